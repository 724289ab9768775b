#!/usr/bin/env python3
"""Before/after whole runs of two crowdrecon builds, interleaved (bench/README.md).

On a machine whose speed drifts (a shared VM: the same run varies by 10-50 %
over minutes), runs of two builds taken one after the other in the same
minute compare far better than two benchmark sessions. For each repetition,
scenario and thread count this runs every build once, in turn:

    crowdrecon simulate SCENARIO -o TMP.sqlite --threads T -q

and reports per build the median engine time (the engine's stage timers),
loop time (steps and writing every frame with its contacts) and real-time
factor, and the ratio of the medians of the first build over the others,
with the median of the per-repetition ratios (paired, so less sensitive to
drift). Raw results to results/bench/DATE-compare[-LABEL].json; a section in
bench/RESULTS.md unless --no-results-md.

Example:
  python3 bench/compare_builds.py --build before=/tmp/old/build/cli/crowdrecon \\
      --build after=build/release/cli/crowdrecon --scenarios box-10000,box-2000 --repeat 8 --label "fast math"
"""

import argparse
import pathlib
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402
import run_benchmarks as rb  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    bc.add_comparison_arguments(p, "crowdrecon")
    p.add_argument("--scenarios", default="box-10000,box-2000", help="comma-separated (default: %(default)s)")
    p.add_argument("--threads", default="1,2", help="comma-separated thread counts (default: %(default)s)")
    p.add_argument("--duration", type=float, default=1.0, help="simulated seconds per run (default: %(default)s)")
    args = p.parse_args()

    builds = bc.parse_builds(args)
    scenarios = [(n, rb.scenario_path(n)) for n in args.scenarios.split(",") if n]
    threads = [int(t) for t in args.threads.split(",") if t]

    started = bc.now()
    load_before = bc.warn_if_busy()
    runs = []  # dicts: rep, scenario, threads, build, result
    with tempfile.TemporaryDirectory(prefix="crowdrecon-compare-") as work:
        copies = {n: rb.scenario_copy(path, args.duration, work) for n, path in scenarios}
        for rep in range(args.repeat):
            for n, _ in scenarios:
                for t in threads:
                    for name, exe in builds:
                        r = rb.run_once(exe, copies[n], t, work)
                        runs.append({"rep": rep, "scenario": n, "threads": t, "build": name, "result": r})
                        print(f"  {rep + 1}/{args.repeat} {n:>12} threads {t} {name:>10}: engine {r['engine_s']:.2f} s, "
                              f"loop {r['loop_wall_s']:.2f} s, real-time factor {r['real_time_factor']:.3f}",
                              file=sys.stderr)
    load_after = bc.load_average()

    reference = builds[0][0]
    rows = []
    for n, _ in scenarios:
        for t in threads:
            def pick(build, key):
                return [x["result"][key] for x in runs if x["scenario"] == n and x["threads"] == t and x["build"] == build]
            for name, _ in builds:
                engine, loop = pick(name, "engine_s"), pick(name, "loop_wall_s")
                row = [n, t, name, f"{bc.median(engine):.2f}", f"{min(engine):.2f}–{max(engine):.2f}",
                       f"{bc.median(loop):.2f}", f"{bc.median(pick(name, 'real_time_factor')):.3f}",
                       bc.si(bc.median(pick(name, "agent_steps_per_s_engine")))]
                if name == reference:
                    row += ["", ""]
                else:
                    ref_engine, ref_loop = pick(reference, "engine_s"), pick(reference, "loop_wall_s")
                    paired = [a / b for a, b in zip(ref_engine, engine)]
                    row += [f"{bc.median(ref_engine) / bc.median(engine):.2f}× (paired {bc.median(paired):.2f}×)",
                            f"{bc.median(ref_loop) / bc.median(loop):.2f}×"]
                rows.append(row)
    header = ["scenario", "threads", "build", "engine s (median)", "engine s range", "loop s (median)",
              "real-time factor", "agent-steps/s engine", f"engine speed-up over {reference}",
              f"loop speed-up over {reference}"]
    table = bc.markdown_table(header, rows)
    print(table)
    notes = [f"- builds: " + ", ".join(f"{name} = `{exe}`" for name, exe in builds),
             f"- {args.repeat} repetitions, each running every build once in turn; {args.duration} s simulated per run",
             "- engine = the engine's stage timers; loop = steps + writing every frame with its contacts; "
             "real-time factor = simulated / loop seconds"]
    bc.save_comparison("compare", "interleaved builds", args, started, load_before, load_after, notes, table,
                       {"builds": [[n, str(e)] for n, e in builds], "runs": runs})

if __name__ == "__main__":
    main()
