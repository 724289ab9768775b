#!/usr/bin/env python3
"""Simulation-based calibration of `crowdrecon calibrate` (issue 41, point 3).

Are the calibration's intervals right as often as they claim? Draws TRUTHS
parameter sets from a stated prior, makes synthetic recordings at each (runs
of seeds the calibration never runs), calibrates each with a small, fast
problem, and reports per parameter:

  - coverage: the fraction of truths inside the posterior's central 68 % and
    95 % intervals (a flat prior over the bounds, the quadratic over every set
    evaluated with its lack of fit counted; docs/calibration.md, "The
    posterior"), each with its binomial standard error; an interval is right
    when its coverage matches the nominal level within that uncertainty. For
    comparison, the same for the older intervals: value ± sigma and `ci95`
    (Ceres' covariance of the local quadratic) and the bootstrap's 95 %;
  - the rank histogram (Talts et al. 2018, "Validating Bayesian inference
    algorithms with simulation-based calibration"): the rank of the truth
    among the posterior's samples (posterior.csv), u = the share of samples
    below it, uniform on [0, 1] when the posterior is right; a U shape means
    intervals too narrow (too confident), a hump too wide, a slope a bias.

The problem (default): the cheap recovery problem of the tests
(tests/data/calibration/recovery*.json: a periodic hallway at 3 /m², 30 %
counter-flow, 10 s; desired speed and restitution; speeds per direction, the
share standing still, the flow), R recordings per truth (seeds 100001 + ...,
never run by the calibration), K seeds per parameter set (1000 k + 1 ...,
different for each truth: each truth replicates the whole process). The prior
is uniform over the box given in PRIOR (default below). Everything is
deterministic: the truths come from Python's random with --seed.

    studies/calibration-coverage/calibration-coverage.py OUT [--truths 20] [--recordings 3] [--seeds 3]
                                        [--crowdrecon build/release/cli/crowdrecon] [--jobs 2]

Writes OUT/coverage.csv (one row per truth and parameter), OUT/coverage.md
(the table), OUT/ranks.svg (the rank histograms) and keeps each truth's
calibration in OUT/truth-NN/. Resumable: a truth whose calibration.json
exists is read, not run again.

Before any work (scripts/script_guard.py): the counts are checked against the
design (at least one truth, at most 100, so that no truth's calibration seeds
reach the recordings' seeds; recordings from 1 to 100; K from 2 to 1000), the
crowdrecon executable must exist, and OUT must be new, empty or a previous
coverage folder (else --force, which writes into it and deletes nothing);
coverage.csv, coverage.md and ranks.svg are written whole. A truth's folder is
started afresh only when it holds this script's files alone.
"""
import argparse
import csv
import json
import math
import os
import random
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # studies/NAME/ is two levels down
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import script_guard as guard  # noqa: E402
DATA = os.path.join(ROOT, "tests", "data", "calibration")
SPEC = os.path.join(ROOT, "venues", "madrid-arena", "observations", "hallway.json")

# The prior: uniform over these boxes, which are also the calibration's bounds
# (recovery.json's are replaced by them): the posterior's flat prior is then
# the prior the truths are drawn from, as simulation-based calibration asks.
PRIOR = {
    "population.desired_speed_m_per_s": (0.8, 1.6),
    "model.restitution": (0.15, 0.7),
}


def phi(x):
    return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))


def run(cmd, log):
    with open(log, "a") as out:
        r = subprocess.run(cmd, stdout=out, stderr=subprocess.STDOUT)
    if r.returncode != 0:
        sys.exit(f"calibration-coverage: {' '.join(cmd)} exited {r.returncode} (see {log})")


def truth_values(seed, n):
    rng = random.Random(seed)
    return [{path: rng.uniform(lo, hi) for path, (lo, hi) in PRIOR.items()} for _ in range(n)]


# What calibrate_truth writes in a truth's folder: the only entries it deletes when it starts a truth afresh.
TRUTH_ENTRIES = ("truth.json", "truth", "log.txt", "calibration.json", "calibration", "*.observation.json",
                 "*.observation.csv")
is_truth_folder = guard.folder_of(*TRUTH_ENTRIES)


def calibrate_truth(args, k, truth):
    d = os.path.join(args.out, f"truth-{k:02d}")
    result = os.path.join(d, "calibration", "calibration.json")
    if os.path.exists(result):
        return json.load(open(result)), 0.0
    t0 = time.time()
    if os.path.exists(d):
        if not os.path.isdir(d) or not is_truth_folder(d):
            raise guard.ScriptError(f"{d}: is {guard.describe_existing(d)}, not an unfinished truth of this script; "
                                    "expected another OUT (nothing in it is deleted)")
        shutil.rmtree(d)
    os.makedirs(d)
    log = os.path.join(d, "log.txt")
    scenario = os.path.join(DATA, "recovery-scenario.json")
    # The recordings: R runs at the truth, of seeds the calibration never runs.
    first = 100001 + 100 * k
    sweep = {
        "format": "crowdrecon-sweep", "version": 1,
        "name": f"coverage truth {k}", "scenario": scenario,
        "variants": [{"name": "truth", "set": {
            "population.desired_speed_m_per_s": [truth["population.desired_speed_m_per_s"] - 0.2,
                                                 truth["population.desired_speed_m_per_s"] + 0.2],
            "model.restitution": truth["model.restitution"]}}],
        "seeds": {"first": first, "count": args.recordings}, "keep_runs": True}
    json.dump(sweep, open(os.path.join(d, "truth.json"), "w"), indent=1)
    run([args.crowdrecon, "sweep", os.path.join(d, "truth.json"), "-o", os.path.join(d, "truth"), "-q",
         "--jobs", str(args.jobs)], log)
    calibration = json.load(open(os.path.join(DATA, "recovery.json")))
    template = calibration["observations"][0]
    calibration["observations"] = []
    runs = sorted(f for f in os.listdir(os.path.join(d, "truth", "runs")) if f.endswith(".sqlite"))
    for r in runs:
        obs = os.path.join(d, r.replace(".sqlite", ".observation.json"))
        run([args.crowdrecon, "observe", "trajectories", os.path.join(d, "truth", "runs", r), "--spec", SPEC,
             "-o", obs, "-q"], log)
        calibration["observations"].append(dict(template, file=obs))
    for par in calibration["parameters"]:
        par["min"], par["max"] = PRIOR[par["path"]]
    calibration["name"] = f"coverage truth {k}"
    calibration["scenario"] = scenario
    # Each truth is a replicate of the whole process: its own recordings and
    # its own calibration seeds. (With the same seeds 1..K for every truth,
    # the error of their mean is one draw shared by all truths, and the 20
    # calibrations are not 20 independent trials of the intervals.)
    calibration["seeds"] = {"first": 1 + 1000 * k, "count": args.seeds}
    calibration["starts"] = []
    calibration["options"] = {"refinements": 1, "bootstrap": 100, "profile_points": 0}
    json.dump(calibration, open(os.path.join(d, "calibration.json"), "w"), indent=1)
    run([args.crowdrecon, "calibrate", os.path.join(d, "calibration.json"), "-o", os.path.join(d, "calibration"),
         "-q", "--jobs", str(args.jobs)], log)
    shutil.rmtree(os.path.join(d, "calibration", "cache"), ignore_errors=True)
    shutil.rmtree(os.path.join(d, "calibration", "batches"), ignore_errors=True)
    shutil.rmtree(os.path.join(d, "truth", "runs"), ignore_errors=True)
    return json.load(open(result)), time.time() - t0


def posterior_rank(d, path, truth):
    """The share of the posterior's samples below the truth (NaN: none)."""
    f = os.path.join(d, "calibration", "posterior.csv")
    if not os.path.exists(f):
        return math.nan
    with open(f) as fh:
        values = [float(r[path]) for r in csv.DictReader(fh)]
    return sum(1 for v in values if v < truth) / len(values) if values else math.nan


def rank_svg(rows, paths, bins, file):
    """Rank (PIT) histograms, one panel per parameter, with the band a uniform
    histogram keeps to in 95 % of cases (binomial, per bin)."""
    n = len(rows) // len(paths)
    w, h, pad = 380, 260, 45
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w * len(paths)}" height="{h + 40}" '
           f'font-family="DejaVu Sans, Arial" font-size="12">', '<rect width="100%" height="100%" fill="white"/>']
    expected = n / bins
    sd = math.sqrt(n * (1 / bins) * (1 - 1 / bins))
    top = max(expected + 2.5 * sd, max([sum(1 for r in rows if r["path"] == p and r["bin"] == b)
                                          for p in paths for b in range(bins)] + [1]))
    for i, path in enumerate(paths):
        x0 = i * w + pad
        y = lambda v: 34 + (h - pad - 14) * (1 - v / top)
        bw = (w - 2 * pad) / bins
        svg.append(f'<rect x="{x0}" y="{y(expected + 1.96 * sd):.1f}" width="{w - 2 * pad}" '
                   f'height="{y(max(0, expected - 1.96 * sd)) - y(expected + 1.96 * sd):.1f}" fill="#dde6f0"/>')
        for b in range(bins):
            c = sum(1 for r in rows if r["path"] == path and r["bin"] == b)
            svg.append(f'<rect x="{x0 + b * bw + 2:.1f}" y="{y(c):.1f}" width="{bw - 4:.1f}" '
                       f'height="{y(0) - y(c):.1f}" fill="#4a6fa5"/>')
        svg.append(f'<line x1="{x0}" x2="{x0 + w - 2 * pad}" y1="{y(expected):.1f}" y2="{y(expected):.1f}" '
                   f'stroke="#333" stroke-dasharray="4 3"/>')
        svg.append(f'<line x1="{x0}" x2="{x0 + w - 2 * pad}" y1="{y(0):.1f}" y2="{y(0):.1f}" stroke="#333"/>')
        for t in range(0, int(top) + 1, max(1, int(top) // 5)):
            svg.append(f'<text x="{x0 - 6}" y="{y(t) + 4:.1f}" text-anchor="end">{t}</text>')
        for b in range(bins + 1):
            svg.append(f'<text x="{x0 + b * bw:.1f}" y="{y(0) + 15:.1f}" text-anchor="middle">{b / bins:g}</text>')
        svg.append(f'<text x="{x0 + (w - 2 * pad) / 2}" y="{h + 12}" text-anchor="middle">'
                   f'rank u: the share of posterior samples below the truth</text>')
        svg.append(f'<text x="{x0 + (w - 2 * pad) / 2}" y="18" text-anchor="middle" font-weight="bold">'
                   f'{path} ({n} truths)</text>')
    svg.append(f'<text x="8" y="{h + 34}" fill="#555">bars: truths per bin; dashed: the uniform expectation; '
               f'band: where a uniform bin count falls 95 % of the time</text>')
    svg.append("</svg>")
    guard.write_whole(file, "\n".join(svg) + "\n")


CSV_HEAD = "truth,path,true,"
MD_HEAD = "# Coverage of the calibration's intervals"
FOOTAGE_HEAD = "# The footage design against actual calibrations"


def out_folder(option, path, force, files):
    """Checks a coverage-style OUT folder and its truth folders before any work (also for
    calibration-footage-check.py). files: {name: predicate} of the files written in it."""
    truth = {"truth-*": lambda d: os.path.isdir(d) and is_truth_folder(d)}
    outputs = [guard.Output(option, path, "a folder of the calibration coverage scripts", folder=True,
                            is_previous=guard.folder_with(dict(files, **truth)))]
    outputs += [guard.Output("", os.path.join(path, name), f"a {name} of the calibration coverage scripts", check)
                for name, check in files.items()]
    guard.check_outputs(outputs, [], force)


def check_truth_folders(out, indices, force):
    """Each truth folder that will be run: new, complete (reused), or an unfinished one of ours."""
    outputs = []
    for k in indices:
        d = os.path.join(out, f"truth-{k:02d}")
        if os.path.exists(os.path.join(d, "calibration", "calibration.json")):
            continue
        outputs.append(guard.Output("", d, "an unfinished truth of this script (which it starts afresh)", folder=True,
                                    is_previous=is_truth_folder))
    for o in outputs:
        if os.path.isdir(o.path) and os.listdir(o.path) and not is_truth_folder(o.path):
            raise guard.ScriptError(f"{o.path}: exists and is {guard.describe_existing(o.path)}, not {o.kind}; "
                                    "expected another OUT (a truth's folder is started afresh, and nothing else is "
                                    "deleted, not even with --force)")
    guard.check_outputs(outputs, [], force)


def add_common_arguments(p):
    p.add_argument("--jobs", type=guard.positive_int, default=2)
    p.add_argument("--crowdrecon", type=guard.executable,
                   default=os.path.join(ROOT, "build", "release", "cli", "crowdrecon"))
    guard.add_force(p)


def main():
    p = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out")
    p.add_argument("--truths", type=guard.int_between(1, 100, "each truth's calibration seeds stay below the "
                                                       "recordings' seeds 100001 ..."), default=20)
    p.add_argument("--recordings", type=guard.int_between(1, 100, "a truth's recording seeds stay its own"), default=3)
    p.add_argument("--seeds", type=guard.int_between(2, 1000, "K: a calibration needs two seeds at least, and a "
                                                     "truth's seeds stay its own"), default=3)
    p.add_argument("--seed", type=guard.int_between(), default=41, help="of the prior's draws")
    p.add_argument("--bins", type=guard.int_between(1, 1000), default=5)
    p.add_argument("--check", action="store_true",
                   help="exit 1 unless every parameter's posterior intervals (68 %% and 95 %%) cover their nominal "
                        "share within two binomial standard errors of it")
    add_common_arguments(p)
    args = p.parse_args()
    out_folder("OUT", args.out, args.force, {"coverage.csv": guard.starts_with(CSV_HEAD),
                                             "coverage.md": guard.starts_with(MD_HEAD), "ranks.svg": guard.is_svg})
    check_truth_folders(args.out, range(args.truths), args.force)
    args.crowdrecon = os.path.abspath(args.crowdrecon)
    args.out = os.path.abspath(args.out)
    os.makedirs(args.out, exist_ok=True)
    truths = truth_values(args.seed, args.truths)
    rows, wall = [], 0.0
    for k, truth in enumerate(truths):
        c, seconds = calibrate_truth(args, k, truth)
        wall += seconds
        for par in c["parameters"]:
            t, v, s = truth[par["path"]], par["value"], par["sigma"]
            lo95, hi95 = par["ci95"] if par.get("ci95") else (math.nan, math.nan)
            blo, bhi = par["bootstrap_ci95"] if par.get("bootstrap_ci95") else (math.nan, math.nan)
            s = s if s is not None else math.nan
            post = par.get("posterior") or {}
            plo68, phi68 = [math.nan if x is None else x for x in (post.get("ci68") or [None, None])]
            plo95, phi95 = [math.nan if x is None else x for x in (post.get("ci95") or [None, None])]
            u = posterior_rank(os.path.join(args.out, f"truth-{k:02d}"), par["path"], t)
            rows.append({"truth": k, "path": par["path"], "true": t, "value": v, "sigma": s,
                         "ci95_low": lo95, "ci95_high": hi95, "bootstrap95_low": blo, "bootstrap95_high": bhi,
                         "posterior_median": post.get("median"), "posterior68_low": plo68, "posterior68_high": phi68,
                         "posterior95_low": plo95, "posterior95_high": phi95,
                         "determination": par["determination"],
                         "inside_posterior68": int(plo68 <= t <= phi68) if math.isfinite(plo68) else "",
                         "inside_posterior95": int(plo95 <= t <= phi95) if math.isfinite(plo95) else "",
                         "inside68": int(abs(t - v) <= s) if math.isfinite(s) else "",
                         "inside95": int(lo95 <= t <= hi95) if lo95 is not None and math.isfinite(s) else "",
                         "inside_bootstrap95": int(blo <= t <= bhi) if blo is not None else "",
                         "rank_u": u, "bin": min(args.bins - 1, int(u * args.bins)) if math.isfinite(u) else -1})
        print(f"truth {k:2d}: " + ", ".join(f"{r['path'].split('.')[-1]} {r['true']:.3f} -> posterior 68 % "
                                            f"[{r['posterior68_low']:.3f}, {r['posterior68_high']:.3f}], 95 % "
                                            f"[{r['posterior95_low']:.3f}, {r['posterior95_high']:.3f}], u {r['rank_u']:.2f}"
                                            for r in rows if r["truth"] == k), flush=True)
    with guard.whole_file(os.path.join(args.out, "coverage.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    paths = list(PRIOR)
    lines = [f"# Coverage of the calibration's intervals ({args.truths} truths)", "",
             f"Problem: tests/data/calibration/recovery*.json (periodic hallway, 3 /m², 30 % counter-flow, 10 s); "
             f"{args.recordings} recordings per truth (seeds never run by the calibration), K = {args.seeds} seeds "
             f"per parameter set (their own for each truth), surrogate approach, bootstrap 100, no profiles, posterior 4 × 20000 steps. Prior: uniform, "
             + "; ".join(f"{p} in [{lo}, {hi}]" for p, (lo, hi) in PRIOR.items())
             + f" (Python random, seed {args.seed}). Wall time of the calibrations run now: {wall:.0f} s.", "",
             "| parameter | inside the posterior's 68 % (nominal 0.68) | inside its 95 % (0.95) | "
             "rank u: mean (uniform 0.5), χ² of the histogram (dof " + str(args.bins - 1) + ") | "
             "for comparison: inside value ± σ (0.68) | inside ci95 (0.95) | inside bootstrap 95 % (0.95) |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for path in paths:
        rs = [r for r in rows if r["path"] == path]
        n = len(rs)
        def frac(key):
            k = sum(r[key] for r in rs if r[key] != "")
            m = sum(1 for r in rs if r[key] != "")
            q = k / m if m else math.nan
            return f"{k}/{m} = {q:.2f} ± {math.sqrt(q * (1 - q) / m) if m else math.nan:.2f}"
        us = [r["rank_u"] for r in rs if math.isfinite(r["rank_u"])]
        counts = [sum(1 for r in rs if r["bin"] == b) for b in range(args.bins)]
        e = len(us) / args.bins
        chi2 = sum((c - e) ** 2 / e for c in counts) if e > 0 else math.nan
        mean_u = sum(us) / len(us) if us else math.nan
        lines.append(f"| {path} | {frac('inside_posterior68')} | {frac('inside_posterior95')} | "
                     f"{mean_u:.2f}; {chi2:.1f} (bins {counts}) | "
                     f"{frac('inside68')} | {frac('inside95')} | {frac('inside_bootstrap95')} |")
    lines += ["", "Each fraction's ± is its binomial standard error. Rank u: the share of the truth's posterior "
              "samples below it: uniform when the posterior is right; piled at 0 and 1 when it is too narrow.", ""]
    guard.write_whole(os.path.join(args.out, "coverage.md"), "\n".join(lines))
    rank_svg(rows, paths, args.bins, os.path.join(args.out, "ranks.svg"))
    print("\n".join(lines))
    if args.check:
        failures = []
        for path in paths:
            rs = [r for r in rows if r["path"] == path]
            for key, nominal in (("inside_posterior68", 0.68), ("inside_posterior95", 0.95)):
                m = sum(1 for r in rs if r[key] != "")
                q = sum(r[key] for r in rs if r[key] != "") / m
                se = math.sqrt(nominal * (1 - nominal) / m)
                if abs(q - nominal) > 2 * se:
                    failures.append(f"{path}: {key} {q:.2f}, nominal {nominal} ± {2 * se:.2f} (two standard errors)")
        if failures:
            print("coverage check FAILED:\n  " + "\n  ".join(failures))
            sys.exit(1)
        print("coverage check: every interval covers its nominal share within two standard errors")


if __name__ == "__main__":
    guard.run_main(main)
