#!/usr/bin/env python3
"""Two builds side by side on one saved moment of a run (bench/README.md).

A dense moment of a long run (the evacuation's crowd behind its exits, the
night's jam) is the part worth measuring, and it lies minutes into the run.
Save it once, as an interrupted run:

    crowdrecon simulate SCENARIO -o SAVED.sqlite --stop-after 30

then this continues it with each build in every repetition, all at once,
each build on a core of its own (taskset), one thread each, the cores
swapped between repetitions:

    crowdrecon simulate SCENARIO -o COPY.sqlite --resume --stop-after UNTIL --threads 1 --fixed-threads -q

On a VM whose speed drifts by 10-50 % from minute to minute, runs that share
the same seconds of the same machine compare far better than runs taken in
turn; the paired ratio of each repetition is reported with the medians. The
builds must give the same results: each continued run's checkpoint (the
whole state at UNTIL) is compared byte for byte, and a difference stops the
script. Needs as many cores as builds. Raw results to
results/bench/DATE-resumed[-LABEL].json; a section in bench/RESULTS.md
unless --no-results-md.

Example:
  python3 bench/compare_resumed.py --build before=/tmp/old --build after=build/release/cli/crowdrecon \\
      --scenario SCENARIO --saved SAVED.sqlite --until 31 --repeat 8 --label "LABEL"
"""

import argparse
import hashlib
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402
import run_benchmarks as rb  # noqa: E402


def continue_run(exe, scenario, saved, until, core, folder):
    """Starts one continuation of `saved` on `core`; returns (process, run file)."""
    run = pathlib.Path(folder) / "run.sqlite"
    shutil.copyfile(saved, run)
    shutil.copyfile(str(saved) + ".checkpoint", str(run) + ".checkpoint")
    cmd = ["taskset", "-c", str(core), str(exe), "simulate", str(scenario), "-o", str(run), "--resume",
           "--stop-after", str(until), "--threads", "1", "--fixed-threads", "-q"]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=bc.ROOT), run


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    bc.add_comparison_arguments(p, "crowdrecon")
    p.add_argument("--scenario", required=True, help="the scenario of the saved run")
    p.add_argument("--saved", required=True, help="the interrupted run file (its .checkpoint beside it)")
    p.add_argument("--until", type=float, required=True, help="simulated time to continue to (s)")
    args = p.parse_args()

    builds = bc.parse_builds(args)
    cores = sorted(os.sched_getaffinity(0))
    if len(cores) < len(builds):
        bc.fail(f"{len(builds)} builds need as many cores; this process may use {len(cores)}")
    saved = pathlib.Path(args.saved).resolve()
    if not pathlib.Path(str(saved) + ".checkpoint").exists():
        bc.fail(f"{saved}.checkpoint not found (save the run with --stop-after)")
    scenario = pathlib.Path(args.scenario).resolve()

    started = bc.now()
    load_before = bc.warn_if_busy()
    runs = []  # dicts: rep, build, core, result
    with tempfile.TemporaryDirectory(prefix="crowdrecon-resumed-") as work:
        for rep in range(args.repeat):
            started_runs = []
            for b, (name, exe) in enumerate(builds):
                core = cores[(b + rep) % len(builds)]
                folder = pathlib.Path(work) / f"{rep}-{b}"
                folder.mkdir()
                started_runs.append((name, core) + continue_run(exe, scenario, saved, args.until, core, folder))
            states = {}
            for name, core, proc, run in started_runs:
                out, _ = proc.communicate()
                if proc.returncode != 130:  # an interrupted run (--stop-after) exits 130
                    bc.fail(f"{name} exited with status {proc.returncode}:\n{out}")
                result = rb.parse_summary(out)
                states[name] = hashlib.sha256(pathlib.Path(str(run) + ".checkpoint").read_bytes()).hexdigest()
                runs.append({"rep": rep, "build": name, "core": core, "result": result})
                print(f"  {rep + 1}/{args.repeat} {name:>10} (core {core}): engine {result['engine_s']:.2f} s, "
                      f"loop {result['loop_wall_s']:.2f} s", file=sys.stderr)
                run.unlink()
                pathlib.Path(str(run) + ".checkpoint").unlink()
            if len(set(states.values())) != 1:
                bc.fail(f"the builds' states at {args.until} s differ: {states}")
    load_after = bc.load_average()

    reference = builds[0][0]
    engine = {name: [r["result"]["engine_s"] for r in runs if r["build"] == name] for name, _ in builds}
    rows = []
    for name, _ in builds:
        paired = [a / b for a, b in zip(engine[reference], engine[name])]
        rows.append([name, ", ".join(bc.fixed(x) for x in engine[name]), bc.fixed(bc.median(engine[name])),
                     f"{bc.median(engine[reference]) / bc.median(engine[name]):.3f}×",
                     f"{bc.median(paired):.3f}× ({', '.join(f'{x:.2f}' for x in paired)})"])
    table = bc.markdown_table(["build", "engine s per repetition", "median", f"{reference} / this (medians)",
                               "paired (median; each repetition)"], rows)
    notes = [f"saved run {saved.name}, scenario {scenario.name}, continued to {args.until} s; one thread per build, "
             f"builds run at once on cores {', '.join(map(str, cores[:len(builds)]))}, swapped each repetition; "
             f"the states at {args.until} s were identical in every repetition"]
    print(table)
    bc.save_comparison("resumed", "builds side by side on a saved run", args, started, load_before, load_after, notes,
                       table, {"builds": [{"name": n, "exe": str(e)} for n, e in builds], "scenario": str(scenario),
                               "saved": str(saved), "until_s": args.until, "runs": runs})


if __name__ == "__main__":
    main()
