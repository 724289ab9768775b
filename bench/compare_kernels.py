#!/usr/bin/env python3
"""Before/after kernel benchmarks of two or more builds, interleaved (bench/README.md).

The kernel counterpart of compare_builds.py. For each repetition this runs
every build's crowdrecon_bench_kernels once, in turn, with the same filter:

    crowdrecon_bench_kernels --benchmark_filter=FILTER --benchmark_min_time=T --benchmark_format=json

and reports per benchmark and build the median real time per iteration, its
range, and the ratio of the reference build's median (the first --build) over
the others' with the median of the per-repetition ratios (paired, so less
sensitive to the drift of a shared machine). A developed-crowd benchmark
walks its crowd for 5 simulated seconds before it measures, in every run:
the builds compared must give the same results for their timings to measure
the same work (compare the contacts column). Raw results to
results/bench/DATE-kernels-compare[-LABEL].json; a section in
bench/RESULTS.md unless --no-results-md.

Example:
  python3 bench/compare_kernels.py --build before=/tmp/old/build/release/bench/crowdrecon_bench_kernels \\
      --build after=build/release/bench/crowdrecon_bench_kernels \\
      --filter 'Step/box-(2000|10000)/developed/threads:1' --repeat 5 --label "skip pass"
"""

import argparse
import json
import pathlib
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402


def run_kernels(exe, pattern, min_time, stage=None):
    command = [str(exe), f"--benchmark_filter={pattern}", f"--benchmark_min_time={min_time}", "--benchmark_format=json"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        bc.fail(f"{' '.join(command)} failed with status {done.returncode}:\n{done.stderr[-2000:]}")
    if not done.stdout.strip():
        bc.fail(f"{exe}: no benchmark matches the filter {pattern!r} (names end in /real_time)")
    try:
        data = json.loads(done.stdout)
    except json.JSONDecodeError as e:
        bc.fail(f"{exe}: output is not JSON ({e})")
    results = {}
    for b in data.get("benchmarks", []):
        if b.get("run_type", "iteration") != "iteration":
            continue
        results[b["name"]] = {"real_time": b["real_time"], "time_unit": b.get("time_unit", "ns"),
                              "contacts": b.get("contacts")}
        if stage:
            results[b["name"]]["stage_ms"] = b.get(f"{stage}_ms")
    if not results:
        bc.fail(f"{exe}: no benchmark matches the filter {pattern!r}")
    return results


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    bc.add_comparison_arguments(p, "crowdrecon_bench_kernels")
    p.add_argument("--filter", required=True, help="Google Benchmark filter (regular expression)")
    p.add_argument("--min-time", type=float, default=1.0, help="--benchmark_min_time, seconds (default: %(default)s)")
    p.add_argument("--stage", help="also compare one engine stage's time per step (a Step benchmark's counter "
                   "STAGE_ms, e.g. drive), with its own paired ratio")
    args = p.parse_args()

    builds = bc.parse_builds(args)

    started = bc.now()
    load_before = bc.warn_if_busy()
    runs = []  # dicts: rep, build, results
    for rep in range(args.repeat):
        for name, exe in builds:
            results = run_kernels(exe, args.filter, args.min_time, args.stage)
            runs.append({"rep": rep, "build": name, "results": results})
            for bench, r in results.items():
                print(f"  {rep + 1}/{args.repeat} {name:>10} {bench}: {r['real_time']:.4g} {r['time_unit']}", file=sys.stderr)
    load_after = bc.load_average()

    reference = builds[0][0]
    names = sorted({b for run in runs for b in run["results"]})
    rows = []
    for bench in names:
        def pick(build, key="real_time"):
            return [run["results"][bench][key] for run in runs if run["build"] == build and bench in run["results"]]
        for name, _ in builds:
            times = pick(name)
            if not times:
                continue
            unit = next(run["results"][bench]["time_unit"] for run in runs if run["build"] == name and bench in run["results"])
            contacts = [c for c in pick(name, "contacts") if c is not None]
            row = [bench, name, f"{bc.median(times):.4g} {unit}", f"{min(times):.4g}–{max(times):.4g}",
                   f"{bc.median(contacts):.0f}" if contacts else ""]
            ref = pick(reference)
            if name == reference or not ref:
                row.append("")
            else:
                paired = [a / b for a, b in zip(ref, times)]
                row.append(f"{bc.median(ref) / bc.median(times):.2f}× (paired {bc.median(paired):.2f}×)")
            if args.stage:
                stage = [x for x in pick(name, "stage_ms") if x is not None]
                ref_stage = [x for x in pick(reference, "stage_ms") if x is not None]
                row.append(f"{bc.median(stage) * 1e3:.4g} µs" if stage else "")
                if stage and ref_stage and name != reference:
                    paired = [a / b for a, b in zip(ref_stage, stage)]
                    row.append(f"{bc.median(ref_stage) / bc.median(stage):.2f}× (paired {bc.median(paired):.2f}×)")
                else:
                    row.append("")
            rows.append(row)
    header = ["benchmark", "build", "time (median)", "range", "contacts", f"speed-up over {reference}"]
    if args.stage:
        header += [f"{args.stage} per step (median)", f"{args.stage} speed-up over {reference}"]
    table = bc.markdown_table(header, rows)
    print(table)
    notes = [f"- builds: " + ", ".join(f"{name} = `{exe}`" for name, exe in builds),
             f"- {args.repeat} repetitions, each running every build once in turn; filter `{args.filter}`, "
             f"min time {args.min_time} s"]
    bc.save_comparison("kernels-compare", "interleaved kernel builds", args, started, load_before, load_after, notes,
                       table, {"builds": [[n, str(e)] for n, e in builds], "filter": args.filter, "runs": runs})

if __name__ == "__main__":
    main()
