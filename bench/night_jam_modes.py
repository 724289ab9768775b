#!/usr/bin/env python3
"""The fixed against the adaptive step on the Madrid night's jam, interleaved (issue 42; bench/README.md).

The night's budget (95 simulated minutes in 15 of wall) is decided by its
jam: about 75 of the 95 minutes, where the crowd barely moves and the
adaptive step gains. A whole night takes about an hour per step and round on
this machine, so this measures the jam as the night itself has it: each step
runs the night once to FROM (default 1,500 s, 02:25, inside the jam) and
keeps that run; then, in each of ROUNDS rounds, both steps continue their
own saved run from FROM for SPAN simulated seconds, in turn (the order
alternating between rounds, on a machine whose speed drifts):

    crowdrecon simulate madrid-night.json(model.time_step_mode = MODE) -o COPY --resume --stop-after FROM+SPAN

under /usr/bin/time, as bench/run_benchmarks.py does. The two steps' nights
differ from the start (a chaotic crowd diverges from any change), so each is
measured on its own jam; the census of both at FROM is printed so that a
reader sees the two jams are alike.

Reports per step the median and range of the wall time per simulated second
of jam, the ratio of the medians (fixed / adaptive), the median of the
per-round ratios, the steps taken, and the whole night this projects (the
first FROM s as measured once, the rest of the night at the jam's median
rate: an estimate, said so); raw results to
results/bench/DATE-night-jam-modes[-LABEL].json and a section of
bench/RESULTS.md (unless --no-results-md).

usage: bench/night_jam_modes.py [--from 1500] [--span 60] [--rounds 3] [--threads 2]
                                [--work DIR] [--exe build/release/cli/crowdrecon] [--label L]
"""
import argparse
import json
import pathlib
import re
import shutil
import sqlite3
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402
import run_benchmarks as rb  # noqa: E402

MODES = ("fixed", "adaptive")
NIGHT = bc.ROOT / "venues/madrid-arena/scenarios/madrid-night.json"
NIGHT_S = 5700.0  # the scenario's duration (checked below)


def run_timed(cmd, folder):
    """Runs cmd under /usr/bin/time -v; the summary and the times, parsed."""
    time_file = pathlib.Path(folder) / "time.txt"
    proc = subprocess.run([rb.TIME, "-v", "-o", str(time_file)] + cmd, capture_output=True, text=True, cwd=bc.ROOT)
    # A run stopped by --stop-after exits as an interrupted run does (130)
    # and says so; any other status is a failure.
    if proc.returncode not in (0, 130):
        bc.fail(f"{' '.join(cmd)} failed with status {proc.returncode}:\n{proc.stdout}{proc.stderr}")
    result = rb.parse_summary(proc.stdout)
    result.update(rb.parse_time_v(time_file.read_text()))
    return result


def census(run_file):
    """People walking and their mean speed at the run file's last frame."""
    with sqlite3.connect(f"file:{run_file}?mode=ro", uri=True) as db:
        frame, t, walking = db.execute("SELECT frame, time_s, walking FROM census ORDER BY frame DESC LIMIT 1").fetchone()
        speed, = db.execute("SELECT AVG(SQRT(vel_x * vel_x + vel_y * vel_y)) FROM person_state WHERE frame = ? "
                            "AND state = 0", (frame,)).fetchone()
    return {"time_s": t, "people": walking, "mean_speed_m_per_s": speed}


def run_files(stem):
    """The run file and what belongs to it (checkpoint; WAL files if left)."""
    return [pathlib.Path(str(stem) + suffix) for suffix in ("", ".checkpoint", "-wal", "-shm")]


def prepare(mode, args):
    """The night with this step run to FROM and kept (reused when present)."""
    folder = args.work / mode
    folder.mkdir(parents=True, exist_ok=True)
    scenario = rb.scenario_copy(NIGHT, NIGHT_S, folder)
    d = json.loads(scenario.read_text())
    d.setdefault("model", {})["time_step_mode"] = mode
    scenario.write_text(json.dumps(d, indent=2))
    saved = folder / "saved.sqlite"
    record = folder / "saved.json"
    if saved.exists() and record.exists() and json.loads(record.read_text()).get("from_s") == args.start:
        print(f"  {mode}: reusing {saved}", file=sys.stderr, flush=True)
        return scenario, saved, json.loads(record.read_text())
    for f in run_files(saved):
        f.unlink(missing_ok=True)
    print(f"  {mode}: the night to {args.start:g} s ...", file=sys.stderr, flush=True)
    r = run_timed([str(args.exe), "simulate", str(scenario), "-o", str(saved), "--stop-after", str(args.start),
                   "--threads", str(args.threads), "-q"] + rb.fixed_threads_option(args.exe), folder)
    if r.get("status") != "interrupted" or abs(r["simulated_s"] - args.start) > 1e-6:
        bc.fail(f"the {mode} night did not stop at {args.start:g} s: {r}")
    info = {"from_s": args.start, "first_part": r, "census": census(saved)}
    record.write_text(json.dumps(info, indent=2))
    return scenario, saved, info


def measure(mode, scenario, saved, args):
    """SPAN simulated s of the jam from this step's saved run (a copy)."""
    folder = args.work / mode
    copy = folder / "round.sqlite"
    for f in run_files(copy):
        f.unlink(missing_ok=True)
    for src, dst in zip(run_files(saved), run_files(copy)):
        if src.exists():
            shutil.copyfile(src, dst)
    r = run_timed([str(args.exe), "simulate", str(scenario), "-o", str(copy), "--resume", "--stop-after",
                   str(args.start + args.span), "--threads", str(args.threads), "-q"] +
                  rb.fixed_threads_option(args.exe), folder)
    r["span_s"] = r["simulated_s"] - args.start
    r["wall_per_simulated_s"] = r["loop_wall_s"] / r["span_s"]
    r["census_after"] = census(copy)
    for f in run_files(copy):
        f.unlink(missing_ok=True)
    return r


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--from", dest="start", type=float, default=1500.0, help="simulated s where the jam is measured from")
    p.add_argument("--span", type=float, default=60.0, help="simulated s of jam per round")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--work", default="", help="folder for the saved nights (kept; reused when present)")
    p.add_argument("--exe", default=str(bc.ROOT / "build/release/cli/crowdrecon"))
    p.add_argument("--label", default="")
    p.add_argument("--no-results-md", action="store_true")
    args = p.parse_args()
    if args.rounds < 1 or not (args.span > 0) or not (0 < args.start < NIGHT_S - args.span):
        bc.fail(f"--rounds >= 1, --span > 0 and 0 < --from < {NIGHT_S:g} - span expected")
    if json.loads(NIGHT.read_text())["run"]["duration_s"] != NIGHT_S:
        bc.fail(f"{NIGHT}: run.duration_s is no longer {NIGHT_S:g}; update NIGHT_S")
    args.exe = pathlib.Path(args.exe).resolve()
    temporary = None
    if args.work:
        args.work = pathlib.Path(args.work).resolve()
    else:
        temporary = tempfile.TemporaryDirectory(prefix="crowdrecon-night-jam-")
        args.work = pathlib.Path(temporary.name)
    started = bc.now()
    load_before = bc.warn_if_busy()
    prepared = {mode: prepare(mode, args) for mode in MODES}
    data = {mode: [] for mode in MODES}
    for rnd in range(args.rounds):
        order = MODES if rnd % 2 == 0 else tuple(reversed(MODES))
        for mode in order:
            scenario, saved, _ = prepared[mode]
            m = measure(mode, scenario, saved, args)
            data[mode].append(m)
            print(f"  round {rnd + 1}/{args.rounds} {mode}: {m['wall_per_simulated_s']:.3f} s of wall per simulated s",
                  file=sys.stderr, flush=True)
    load_after = bc.load_average()
    f = {mode: [m["wall_per_simulated_s"] for m in data[mode]] for mode in MODES}
    paired = [a / b for a, b in zip(f["fixed"], f["adaptive"])]
    rows = []
    for mode in MODES:
        info = prepared[mode][2]
        first = info["first_part"]["loop_wall_s"]
        jam = bc.median(f[mode])
        night_min = (first + jam * (NIGHT_S - args.start)) / 60.0
        steps = data[mode][0].get("steps")
        c = info["census"]
        rows.append([mode, f"{c['people']} people, {c['mean_speed_m_per_s']:.3f} m/s",
                     f"{jam:.3f} ({min(f[mode]):.3f}–{max(f[mode]):.3f})",
                     f"{steps / args.span:.0f}" if steps else f"{args.span / data[mode][0]['time_step_s'] / args.span:.0f}",
                     f"{first:.0f} s", f"{night_min:.1f} min (estimate)",
                     f"{bc.median(f['fixed']) / jam:.3f}; paired {bc.median(paired):.3f}" if mode == "adaptive" else ""])
    table = bc.markdown_table(["step", f"census at {args.start:g} s", "wall per simulated s of jam, median (range)",
                               "steps per simulated s", f"the night to {args.start:g} s (once)",
                               "the whole night projected (budget 15 min)", "fixed / adaptive"], rows)
    header = bc.header_lines(bc.command_line(), started, load_before, load_after,
                             [f"- {args.rounds} rounds, the steps in turn (order alternating), {args.threads} thread(s); "
                              f"each round continues the step's own night from {args.start:g} s for {args.span:g} s",
                              "- the projection: the first part as measured once, the rest of the night at the jam's "
                              "median rate (the night is jammed from about 1,140 s to its end)"])
    print(header + "\n\n" + table)
    path = bc.default_json_path("night-jam-modes", started, args.label)
    bc.write_json(path, {"args": {k: str(v) for k, v in vars(args).items()},
                         "prepared": {m: prepared[m][2] for m in MODES}, "data": data})
    if not args.no_results_md:
        bc.update_results("night-jam-modes", args.label, f"{started.strftime('%Y-%m-%d %H:%M UTC')} · the night's jam, "
                          f"fixed against adaptive step · {args.label}", header + "\n\n" + table, started)
    if temporary:
        temporary.cleanup()


if __name__ == "__main__":
    main()
