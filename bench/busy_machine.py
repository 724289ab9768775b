#!/usr/bin/env python3
"""Whole runs on an idle machine and with one core kept busy by another
program: --threads 1 against --threads 2, with the thread governor (the
default) and without it (--fixed-threads, the behaviour before the governor),
and without it under OpenMP's passive waiting policy (for comparison).

    bench/busy_machine.py --exe build/release/cli/crowdrecon [--repeat 5] [--label L]

Every round runs each configuration once, in a shuffled order (interleaved,
so that slow drifts of a noisy machine fall on all alike); the busy core is a
Python loop started before the run and stopped after it. The table gives
median wall seconds per run, their spread, and the ratios that the hardening
issue asks for: busy 2 threads / busy 1 thread (must stay <= 1.5), and idle
2 threads with the governor / without it (must stay ~1). Writes its raw data
to results/bench/ and a section of bench/RESULTS.md (bench_common)."""

import argparse
import os
import pathlib
import random
import re
import subprocess
import sys
import tempfile
import time

import bench_common as bc

SCENARIOS = {
    # name: (scenario file relative to the repository, simulated seconds)
    "hallway-180": ("venues/madrid-arena/scenarios/hallway-5pm2-30cf.json", 30.0),
    "box-2000": ("bench/scenarios/box-2000.json", 3.0),
}
PASSIVE = {"OMP_WAIT_POLICY": "passive"}
CONFIGS = [
    # (name, busy core, --threads, extra options, extra environment)
    ("idle 1T", False, 1, [], {}),
    ("idle 2T fixed", False, 2, ["--fixed-threads"], {}),
    ("idle 2T governor", False, 2, [], {}),
    ("idle 2T fixed passive", False, 2, ["--fixed-threads"], PASSIVE),
    ("busy 1T", True, 1, [], {}),
    ("busy 2T fixed", True, 2, ["--fixed-threads"], {}),
    ("busy 2T governor", True, 2, [], {}),
    ("busy 2T fixed passive", True, 2, ["--fixed-threads"], PASSIVE),
]


def run_once(exe, scenario, threads, extra, env, busy, folder):
    out = bc.fresh_run_file(folder)
    hog = subprocess.Popen([sys.executable, "-c", "while True: pass"]) if busy else None
    if hog:
        time.sleep(0.3)  # the other program is busy before the run starts
    try:
        result = subprocess.run([str(exe), "simulate", str(scenario), "-o", str(out), "-q", "--threads", str(threads)]
                                + extra, capture_output=True, text=True, env=dict(os.environ, **env))
    finally:
        if hog:
            hog.kill()
            hog.wait()
    if result.returncode != 0:
        bc.fail(f"{scenario.name} --threads {threads} {' '.join(extra)}: exit {result.returncode}\n{result.stderr}")
    wall = re.search(r"simulated: (?:from [0-9.]+ to )?[0-9.]+ s in ([0-9.]+) s wall", result.stdout)
    threads_line = re.search(r"threads: (.*)", result.stdout)
    return float(wall.group(1)), threads_line.group(1) if threads_line else ""


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    bc.add_whole_run_arguments(parser, repeat=5)
    parser.add_argument("--scenario", action="append", choices=sorted(SCENARIOS), help="default: all")
    args = parser.parse_args()
    exe = bc.checked_exe_and_repeat(args)
    started = bc.now()
    load_before = bc.warn_if_busy()
    names = args.scenario or sorted(SCENARIOS)
    times = {(s, c[0]): [] for s in names for c in CONFIGS}
    reports = {}
    copies = []
    rng = random.Random(1)
    try:
        with tempfile.TemporaryDirectory() as folder:
            scenarios = {}
            for s in names:
                rel, duration = SCENARIOS[s]
                scenarios[s] = bc.cut_scenario_copy(bc.ROOT / rel, duration, "busy")
                copies.append(scenarios[s])
            for r in range(args.repeat):
                order = [(s, c) for s in names for c in CONFIGS]
                rng.shuffle(order)
                for s, (cname, busy, threads, extra, env) in order:
                    wall, report = run_once(exe, scenarios[s], threads, extra, env, busy, folder)
                    times[(s, cname)].append(wall)
                    if report:
                        reports.setdefault((s, cname), []).append(report)
                    print(f"round {r + 1}/{args.repeat}  {s:12s} {cname:18s} {wall:8.2f} s  {report}", file=sys.stderr)
    finally:
        for c in copies:
            c.unlink(missing_ok=True)
    load_after = bc.load_average()

    rows = []
    for s in names:
        med = {c[0]: bc.median(times[(s, c[0])]) for c in CONFIGS}
        for cname, *_ in CONFIGS:
            rows.append([s, cname, bc.fixed(med[cname]), bc.percent(bc.spread(times[(s, cname)])),
                         (reports.get((s, cname)) or [""])[-1]])
        rows.append([s, "**busy 2T / busy 1T, fixed (before)**", bc.fixed(med["busy 2T fixed"] / med["busy 1T"]), "", ""])
        rows.append([s, "**busy 2T / busy 1T, governor (after)**", bc.fixed(med["busy 2T governor"] / med["busy 1T"]), "", ""])
        rows.append([s, "**idle 2T governor / idle 2T fixed**", bc.fixed(med["idle 2T governor"] / med["idle 2T fixed"]), "", ""])
        rows.append([s, "**busy 2T / busy 1T, fixed, OMP_WAIT_POLICY=passive**",
                     bc.fixed(med["busy 2T fixed passive"] / med["busy 1T"]), "", ""])
        rows.append([s, "**idle 2T fixed passive / idle 2T fixed**",
                     bc.fixed(med["idle 2T fixed passive"] / med["idle 2T fixed"]), "", ""])
        rows.append([s, "**idle 1T / idle 2T governor**", bc.fixed(med["idle 1T"] / med["idle 2T governor"]), "", ""])
    table = bc.markdown_table(["scenario", "configuration", "median wall s", "spread", "governor (last round)"], rows)
    print(table)
    notes = [f"{args.repeat} interleaved rounds; busy = one `python3 -c 'while True: pass'` for the length of the run",
             "scenarios: " + ", ".join(f"{s} ({SCENARIOS[s][1]:g} s simulated)" for s in names)]
    data = {"machine": bc.machine(), "commit": bc.git_commit(), "times": {f"{s}|{c}": v for (s, c), v in times.items()},
            "reports": {f"{s}|{c}": v for (s, c), v in reports.items()}}
    json_path = bc.write_json(bc.default_json_path("busy", started, args.label), dict(data, load_before=load_before,
                                                                                      load_after=load_after))
    print(f"raw results: {json_path}", file=sys.stderr)
    if not args.no_results_md:
        body = bc.header_lines(bc.command_line(), started, load_before, load_after, notes) + "\n\n" + table + "\n"
        title = f"{started.strftime('%Y-%m-%d %H:%M UTC')} · busy machine: threads 1 vs 2" + (
            f" · {args.label}" if args.label else "")
        print(f"updated {bc.update_results('busy', args.label, title, body, started)}", file=sys.stderr)


if __name__ == "__main__":
    main()
