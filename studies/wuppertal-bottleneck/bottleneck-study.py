#!/usr/bin/env python3
"""The empirical anchor of issue 39: the Wuppertal 2018 bottleneck (0.5 m,
run 040_c_56_h-) against the model, each body mode and extension on and off,
over seeds.

Every variant is the shipped scenario (venues/juelich/scenarios/
wuppertal-bottleneck.json) with body.mode and model keys changed, run with
`crowdrecon simulate` (two runs at a time, one thread each); the experiment's
trajectories and the runs' trajectories go through the same code below, so
every statistic has one definition:

  passage     a person's first crossing of the bottleneck's entrance, y = 0
              (time interpolated within the frame interval)
  flow        (N - 1) / (last passage - first passage), persons/s
  span        last passage - first passage (s)
  density     people whose centre is in the measurement area [-0.4, 0.4] x
              [0.5, 1.3] / 0.64 m^2, mean over the frames between the first
              and the last passage
  lapses      times between consecutive passages: median, 90th percentile,
              longest; share of lapses over 1 s; clogs = lapses over 2 s
  stuck       people who never passed (a run that clogged for good)
  KS          two-sample Kolmogorov-Smirnov distance between the variant's
              lapses (all seeds pooled) and the experiment's, with its
              asymptotic p-value

usage: studies/wuppertal-bottleneck/bottleneck-study.py CROWDRECON OUT_DIR [--seeds 10] [--variants a,b,...] [--jobs 2] [--force]
Writes OUT_DIR/runs/VARIANT-sSEED.sqlite (reused when complete), OUT_DIR/results.csv
and OUT_DIR/study.md. Standard library only. Needs the experiment's trajectories
in the data folder ../shared/data beside the repository (../shared/data/README.md)
and says so when they are missing. Every output is checked before any run
(scripts/script_guard.py): OUT_DIR new, empty or a previous study's folder
(else --force, which writes into it and deletes nothing), each file in it new
or a previous output of its kind; results.csv and study.md are written whole.
A bad argument (a variant, a count, a missing program) is one line, exit 2.
"""
import argparse
import collections
import concurrent.futures
import json
import math
import os
import sqlite3
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), 'scripts'))
import petrack  # noqa: E402  (scripts/: the PeTrack reader the studies share)
import script_guard as guard  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))  # studies/NAME/ is two levels down
SCENARIO = os.path.join(ROOT, 'venues', 'juelich', 'scenarios', 'wuppertal-bottleneck.json')
DATA = os.path.join(ROOT, '..', 'shared', 'data', 'juelich-bottleneck', '040_c_56_h-.txt')
AREA = (-0.4, 0.4, 0.5, 1.3)
AREA_M2 = 0.8 * 0.8

# A variant is BODY[+jitter|+jitter=SIGMA][+face-desired][+no-spring|+creep=T][+yield=SHARE][+turn|+turn=DEG][+lag=T]: the
# body mode (paper, anthropometric, circle), then options of the model
# (docs/decisions.md, "Issue 39"): the gait jitter at its measured strength
# and band (the parameter table's defaults) or at SIGMA m/s, the motive
# torque turning people to their desired direction (ERRATA 5's option),
# contacts without the tangential spring (issue 19's option) or with a
# spring that creeps over T seconds, yielding with the given push share,
# a blocked person turning a shoulder into the way (by 90 degrees or DEG),
# a reaction time of the drive (its velocity perceived with a lag of T s).
DEFAULT_VARIANTS = ['paper', 'anthropometric', 'circle', 'paper+jitter', 'anthropometric+jitter', 'circle+jitter']


# The ranges of the model's parameter table (engine/src/parameter_table.cpp) for the numbers of a variant.
RANGES = {'jitter=': (0.0, 5.0, 'm/s'), 'creep=': (1e-3, 1e4, 's'), 'yield=': (0.0, 1.0, ''),
          'turn=': (0.0, 90.0, 'deg'), 'lag=': (0.01, 10.0, 's')}


def variant_number(name, part):
    """The number of a variant's part such as jitter=0.3, checked against its range (ValueError)."""
    prefix = part[:part.index('=') + 1]
    low, high, unit = RANGES[prefix]
    text = part[len(prefix):]
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (low <= value <= high):
        raise ValueError(f'variant {name!r}: {part!r}; expected {prefix}NUMBER from {low:g} to {high:g}'
                         + (f' {unit}' if unit else ''))
    return value


def parse_variant(name):
    parts = name.split('+')
    body, model = parts[0], {}
    if body not in ('paper', 'anthropometric', 'circle'):
        raise ValueError(f'variant {name!r}: body {body!r}; expected paper, anthropometric or circle')
    for part in parts[1:]:
        if part == 'jitter':
            model['gait_jitter'] = 'isotropic'
        elif part.startswith('jitter='):
            model['gait_jitter'] = 'isotropic'
            model['gait_jitter_velocity_m_per_s'] = variant_number(name, part)
        elif part == 'no-spring':
            model['tangential_spring'] = 'none'
        elif part.startswith('creep='):
            model['tangential_spring'] = 'creeping'
            model['tangential_spring_relaxation_time_s'] = variant_number(name, part)
        elif part == 'face-desired':
            model['facing_target'] = 'desired_direction'
        elif part.startswith('yield='):
            model['yielding'] = 'when_blocked'
            model['yielding_push_share'] = variant_number(name, part)
        elif part == 'turn' or part.startswith('turn='):
            model['shoulder_turn'] = 'when_blocked'
            if part.startswith('turn='):
                model['shoulder_turn_angle_deg'] = variant_number(name, part)
        elif part.startswith('lag='):
            model['drive_reaction'] = 'lagged'
            model['drive_reaction_time_s'] = variant_number(name, part)
        else:
            raise ValueError(f'variant {name!r}: {part!r}; expected jitter, jitter=SIGMA, face-desired, no-spring, '
                             'creep=T, yield=SHARE, turn, turn=DEG or lag=T')
    return body, model


def statistics(tracks, frame_s, first_frame=0):
    """tracks: id -> sorted [(frame, x, y)]. Returns a dict of the statistics above."""
    passages = []
    for track in tracks.values():
        for (f0, x0, y0), (f1, x1, y1) in zip(track, track[1:]):
            if y0 > 0.0 >= y1:
                passages.append((f0 + (f1 - f0) * y0 / (y0 - y1) - first_frame) * frame_s)
                break
    passages.sort()
    out = {'people': len(tracks), 'passed': len(passages), 'stuck': len(tracks) - len(passages)}
    if len(passages) < 2:
        return out, []
    lapses = [b - a for a, b in zip(passages, passages[1:])]
    ordered = sorted(lapses)
    counts = collections.Counter()
    lo, hi = int(passages[0] / frame_s) + first_frame, int(passages[-1] / frame_s) + first_frame
    for track in tracks.values():
        for f, x, y in track:
            if lo <= f <= hi and AREA[0] <= x <= AREA[1] and AREA[2] <= y <= AREA[3]:
                counts[f] += 1
    frames = hi - lo + 1
    out.update({
        'first_s': passages[0], 'last_s': passages[-1], 'span_s': passages[-1] - passages[0],
        'flow_per_s': (len(passages) - 1) / (passages[-1] - passages[0]),
        'density_per_m2': sum(counts.values()) / frames / AREA_M2,
        'lapse_median_s': ordered[len(ordered) // 2],
        'lapse_p90_s': ordered[min(len(ordered) - 1, int(0.9 * len(ordered)))],
        'lapse_max_s': ordered[-1],
        'share_over_1s': sum(1 for v in lapses if v > 1.0) / len(lapses),
        'clogs_over_2s': sum(1 for v in lapses if v > 2.0),
    })
    return out, lapses


def read_petrack(path):
    """The experiment's tracks (id -> sorted [(frame, x, y)] in metres) and its frame interval (s)."""
    tracks, fps, _, _ = petrack.read_petrack(path)
    return tracks, 1.0 / fps


def read_run(path):
    db = sqlite3.connect(f'file:{path}?mode=ro', uri=True)
    times = db.execute('SELECT frame, time_s FROM frame_time ORDER BY frame').fetchall()
    frame_s = (times[-1][1] - times[0][1]) / (times[-1][0] - times[0][0])
    tracks = collections.defaultdict(list)
    for frame, pid, x, y in db.execute('SELECT frame, id, pos_x, pos_y FROM trajectory_data ORDER BY id, frame'):
        tracks[pid].append((frame, x, y))
    status = dict(db.execute("SELECT key, value FROM run WHERE key IN ('status', 'wall_time_s')").fetchall())
    db.close()
    return tracks, frame_s, status


def ks(a, b):
    """Two-sample Kolmogorov-Smirnov distance and its asymptotic p-value."""
    a, b = sorted(a), sorted(b)
    i = j = 0
    d = 0.0
    while i < len(a) and j < len(b):
        x = min(a[i], b[j])
        while i < len(a) and a[i] <= x:
            i += 1
        while j < len(b) and b[j] <= x:
            j += 1
        d = max(d, abs(i / len(a) - j / len(b)))
    n = len(a) * len(b) / (len(a) + len(b))
    lam = (math.sqrt(n) + 0.12 + 0.11 / math.sqrt(n)) * d
    p = 2 * sum((-1) ** (k - 1) * math.exp(-2 * k * k * lam * lam) for k in range(1, 101))
    return d, min(1.0, max(0.0, p))


def scenario_for(variant, seed, work):
    body, model = parse_variant(variant)
    with open(SCENARIO) as f:
        s = json.load(f)
    s['venue'] = os.path.join(os.path.dirname(SCENARIO), s['venue'])
    s['population']['body']['reference'] = os.path.join(os.path.dirname(SCENARIO), s['population']['body']['reference'])
    s['population']['body']['mode'] = body
    s['population']['seed'] = seed
    s['name'] = f'{s["name"]} [{variant}, seed {seed}]'
    if model:
        s['model'] = dict(model)
    path = os.path.join(work, f'{variant}-s{seed}.json')
    guard.write_whole(path, json.dumps(s, indent=1))
    return path


def run_one(crowdrecon, variant, seed, out):
    runs = os.path.join(out, 'runs')
    run = os.path.join(runs, f'{variant}-s{seed}.sqlite')
    if os.path.exists(run) and not os.path.exists(run + '-wal'):
        try:
            if read_run(run)[2].get('status') == 'complete':
                return variant, seed, run, 0.0
        except sqlite3.Error:
            pass
    scenario = scenario_for(variant, seed, runs)
    start = time.monotonic()
    proc = subprocess.run([crowdrecon, 'simulate', scenario, '-o', run, '--threads', '1', '--force'],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f'{variant} seed {seed}: crowdrecon simulate exited {proc.returncode}:\n{proc.stdout[-2000:]}')
    return variant, seed, run, time.monotonic() - start


def fmt(values, digits=2):
    values = [v for v in values if v is not None]
    if not values:
        return 'n/a'
    mean = sum(values) / len(values)
    if len(values) == 1:
        return f'{mean:.{digits}f}'
    sd = math.sqrt(sum((v - mean) ** 2 for v in values) / (len(values) - 1))
    return f'{mean:.{digits}f} ± {sd:.{digits}f}'


RESULTS_HEAD = 'variant,seed,passed,stuck,'
STUDY_HEAD = '# The Wuppertal bottleneck against the model'


def check_outputs(args, variants):
    """Every path the study writes, checked before any run (scripts/script_guard.py)."""
    runs = os.path.join(args.out, 'runs')
    names = [f'{v}-s{s}' for v in variants for s in range(1, args.seeds + 1)]
    runs_previous = guard.folder_with({'*.sqlite': guard.is_run_file,
                                       '*.json': guard.is_json_with('format', 'crowdrecon-scenario')})
    outputs = [
        guard.Output('OUT_DIR', args.out, 'a folder of bottleneck-study.py', folder=True, is_previous=guard.folder_with(
            {'results.csv': guard.starts_with(RESULTS_HEAD), 'study.md': guard.starts_with(STUDY_HEAD),
             'runs': runs_previous})),
        guard.Output('', runs, 'a folder of run files of bottleneck-study.py', folder=True, is_previous=runs_previous),
        guard.Output('', os.path.join(args.out, 'results.csv'), 'a table of bottleneck-study.py',
                     guard.starts_with(RESULTS_HEAD)),
        guard.Output('', os.path.join(args.out, 'study.md'), 'a report of bottleneck-study.py',
                     guard.starts_with(STUDY_HEAD))]
    for n in names:
        outputs.append(guard.Output('', os.path.join(runs, n + '.sqlite'), 'a crowdrecon run file',
                                    guard.is_run_file))
        outputs.append(guard.Output('', os.path.join(runs, n + '.json'), 'a crowdrecon scenario',
                                    guard.is_json_with('format', 'crowdrecon-scenario')))
    guard.check_outputs(outputs, [('the crowdrecon executable', args.crowdrecon), ('the experiment\'s trajectories', DATA),
                                  ('the shipped scenario', SCENARIO)], args.force)


def main():
    ap = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('crowdrecon', type=guard.executable)
    ap.add_argument('out')
    ap.add_argument('--seeds', type=guard.positive_int, default=10)
    ap.add_argument('--variants', default=','.join(DEFAULT_VARIANTS), type=guard.nonempty_list,
                    help='comma-separated BODY[+jitter|+jitter=SIGMA][+face-desired][+no-spring|+creep=T][+yield=SHARE] (default: %(default)s)')
    ap.add_argument('--jobs', type=guard.positive_int, default=2)
    guard.add_force(ap)
    args = ap.parse_args()
    variants = args.variants
    for v in variants:
        try:
            parse_variant(v)
        except ValueError as e:
            raise guard.ScriptError(f'--variants: {e}') from None
    if not os.path.isfile(DATA):
        data = os.path.normpath(os.path.join(ROOT, '..', 'shared', 'data'))
        raise guard.ScriptError(f'{os.path.normpath(DATA)}: no such file: the data folder ../shared/data beside the '
                                f'repository ({data}) is missing or incomplete; expected the Wuppertal bottleneck '
                                'trajectories there (../shared/data/README.md)')
    check_outputs(args, variants)
    os.makedirs(os.path.join(args.out, 'runs'), exist_ok=True)

    data_tracks, data_frame_s = read_petrack(DATA)
    data_stats, data_lapses = statistics(data_tracks, data_frame_s)

    results = collections.defaultdict(list)  # variant -> [(seed, stats, lapses, wall)]
    jobs = [(v, s) for v in variants for s in range(1, args.seeds + 1)]
    started = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(run_one, args.crowdrecon, v, s, args.out) for v, s in jobs]
        for k, fut in enumerate(concurrent.futures.as_completed(futures), 1):
            variant, seed, run, wall = fut.result()
            tracks, frame_s, _ = read_run(run)
            st, lapses = statistics(tracks, frame_s)
            results[variant].append((seed, st, lapses, wall))
            print(f'[{k}/{len(jobs)}] {variant} seed {seed}: passed {st["passed"]}/{st["people"]}, '
                  f'flow {st.get("flow_per_s", float("nan")):.2f}/s, longest lapse {st.get("lapse_max_s", float("nan")):.1f} s '
                  f'({wall:.0f} s)', flush=True)
    total_wall = time.monotonic() - started

    keys = ['passed', 'stuck', 'flow_per_s', 'span_s', 'density_per_m2', 'lapse_median_s', 'lapse_p90_s', 'lapse_max_s',
            'share_over_1s', 'clogs_over_2s']
    with guard.whole_file(os.path.join(args.out, 'results.csv'), 'w') as f:
        f.write('variant,seed,' + ','.join(keys) + ',wall_s\n')
        f.write('experiment,,' + ','.join(str(data_stats.get(k, '')) for k in keys) + ',\n')
        for v in variants:
            for seed, st, _, wall in sorted(results[v], key=lambda r: r[0]):
                f.write(f'{v},{seed},' + ','.join(str(st.get(k, '')) for k in keys) + f',{wall:.1f}\n')

    lines = ['# The Wuppertal bottleneck against the model (issue 39)', '',
             f'Generated by `studies/wuppertal-bottleneck/bottleneck-study.py` ({args.seeds} seeds per variant; the statistics are defined '
             'in the script, the same code reads the experiment and the runs). Mean ± standard deviation over seeds; '
             'the lapse quantiles of a seed are over its own lapses; KS: the variant\'s lapses of all seeds pooled '
             'against the experiment\'s.', '',
             '| variant | passed (of 75) | stuck for good | flow (1/s) | first to last passage (s) | density in front (1/m²) '
             '| lapse median (s) | lapse p90 (s) | longest lapse (s) | lapses > 1 s | clogs > 2 s | KS distance (p) |',
             '|---|---|---|---|---|---|---|---|---|---|---|---|']
    d = data_stats
    lines.append(f'| experiment | {d["passed"]} | {d["stuck"]} | {d["flow_per_s"]:.2f} | {d["span_s"]:.1f} | '
                 f'{d["density_per_m2"]:.2f} | {d["lapse_median_s"]:.2f} | {d["lapse_p90_s"]:.2f} | '
                 f'{d["lapse_max_s"]:.2f} | {d["share_over_1s"]:.2f} | {d["clogs_over_2s"]} | – |')
    for v in variants:
        rows = results[v]
        col = lambda k: [r[1].get(k) for r in rows]
        pooled = [x for r in rows for x in r[2]]
        dist, p = ks(pooled, data_lapses) if pooled else (float('nan'), float('nan'))
        lines.append(f'| {v} | {fmt(col("passed"), 1)} | {fmt(col("stuck"), 1)} | {fmt(col("flow_per_s"))} | '
                     f'{fmt(col("span_s"), 1)} | {fmt(col("density_per_m2"))} | {fmt(col("lapse_median_s"))} | '
                     f'{fmt(col("lapse_p90_s"))} | {fmt(col("lapse_max_s"), 1)} | {fmt(col("share_over_1s"))} | '
                     f'{fmt(col("clogs_over_2s"), 1)} | {dist:.2f} ({p:.1g}) |')
    lines += ['', f'Runs: {len(jobs)}, wall time {total_wall / 60:.1f} min ({args.jobs} at a time, one thread each; '
              'runs already complete are reused and count 0).', '',
              '## Per run', '', '| variant | seed | passed | flow (1/s) | longest lapse (s) | clogs > 2 s | wall (s) |',
              '|---|---|---|---|---|---|---|']
    for v in variants:
        for seed, st, _, wall in sorted(results[v], key=lambda r: r[0]):
            lines.append(f'| {v} | {seed} | {st["passed"]} | {st.get("flow_per_s", float("nan")):.2f} | '
                         f'{st.get("lapse_max_s", float("nan")):.1f} | {st.get("clogs_over_2s", "")} | {wall:.0f} |')
    guard.write_whole(os.path.join(args.out, 'study.md'), '\n'.join(lines) + '\n')
    print('\n'.join(lines[:6 + len(variants) + 3]))


if __name__ == '__main__':
    guard.run_main(main)
