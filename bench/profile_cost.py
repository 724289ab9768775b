#!/usr/bin/env python3
"""The wall-time cost of the profile validated against the paper's model
(issue 64): the same scenarios run under each profile (`crowdrecon simulate
SCENARIO --profile NAME`), one thread, interleaved rounds.

    bench/profile_cost.py [--exe build/release/cli/crowdrecon] [--repeat 3] [--label L]

Scenarios, as shipped: the Madrid Arena hallway (periodic, 5 /m², 30 %
counter-flow, 60 s; its own free speeds U(0.8, 1.2) m/s under both
profiles), the Wuppertal bottleneck (75 people, 0.5 m, up to 120 s; its
own speeds), the Madrid night's demo (285 s; the profile's speeds: U(0.8,
1.2) with paper, U(1.0, 1.86) with validated). Per scenario and profile: the
median processor time of the whole run (user + system), its wall time, the
time per step and the ratio to the paper's model, per run and per step. A
whole run's ratio is also what the crowd does (a bottleneck that clogs runs
to its end, one that empties stops early); per step is the model's cost.
Writes results/bench/ and a section of bench/RESULTS.md (bench_common)."""

import argparse
import pathlib
import random
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402
from keeping_distance_cost import run_once  # noqa: E402

SCENARIOS = {
    "hallway": "venues/madrid-arena/scenarios/hallway-5pm2-30cf.json",
    "bottleneck": "venues/juelich/scenarios/wuppertal-bottleneck.json",
    "night-demo": "venues/madrid-arena/scenarios/madrid-night-demo.json",
}
PROFILES = ["paper", "validated"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    bc.add_whole_run_arguments(parser, repeat=3)
    args = parser.parse_args()
    exe = bc.checked_exe_and_repeat(args)
    started = bc.now()
    load_before = bc.warn_if_busy()
    samples = {}
    rng = random.Random(1)
    with tempfile.TemporaryDirectory() as folder:
        keys = [(s, p) for s in SCENARIOS for p in PROFILES]
        for r in range(args.repeat):
            order = list(keys)
            rng.shuffle(order)
            for key in order:
                sample = run_once(exe, bc.ROOT / SCENARIOS[key[0]], folder, ["--profile", key[1]])
                samples.setdefault(key, []).append(sample)
                print(f"round {r + 1}/{args.repeat}  {key[0]:10s} {key[1]:10s} " +
                      (f"failed: {sample['failed'][:150]}" if "failed" in sample else
                       f"cpu {sample['cpu_s']:7.2f} s  wall {sample['wall_s']:7.2f} s  steps {sample['steps']:.0f}"),
                      file=sys.stderr)
    load_after = bc.load_average()
    rows, data = [], {}
    for s in SCENARIOS:
        ok = {p: [x for x in samples[(s, p)] if "failed" not in x] for p in PROFILES}
        cpu = {p: bc.median([x["cpu_s"] for x in ok[p]]) if ok[p] else float("nan") for p in PROFILES}
        step = {p: bc.median([x["cpu_s"] / x["steps"] for x in ok[p]]) if ok[p] else float("nan") for p in PROFILES}
        for p in PROFILES:
            data[f"{s}/{p}"] = samples[(s, p)]
            failed = len(samples[(s, p)]) - len(ok[p])
            if not ok[p]:
                rows.append([s, p, f"every run failed ({failed})", "", "", "", "", ""])
                continue
            rows.append([s, p, bc.fixed(cpu[p]), bc.fixed(bc.median([x["wall_s"] for x in ok[p]])),
                         f"{bc.median([x['steps'] for x in ok[p]]):.0f}", f"{1e6 * step[p]:.0f}",
                         bc.fixed(cpu[p] / cpu["paper"]) + (f" ({failed} failed)" if failed else ""),
                         bc.fixed(step[p] / step["paper"])])
    table = bc.markdown_table(["scenario", "profile", "median cpu s", "median wall s", "steps", "cpu µs / step",
                               "run / paper", "step / paper"], rows)
    print(table)
    notes = [f"{args.repeat} interleaved rounds, one thread each (--threads 1 --fixed-threads)",
             "scenarios as shipped: " + ", ".join(f"{s} ({f})" for s, f in SCENARIOS.items()),
             "the runs differ in what they simulate as well as in cost per step (a bottleneck that empties stops early)"]
    header = bc.header_lines(bc.command_line(), started, load_before, load_after, [f"- {n}" for n in notes])
    bc.write_json(bc.default_json_path("profile-cost", started, args.label), {"samples": data, "notes": notes})
    if not args.no_results_md:
        bc.update_results("profile-cost", args.label, "The cost of the profile validated against the paper's model (issue 64)"
                          + (f": {args.label}" if args.label else ""), header + "\n\n" + table, started)


if __name__ == "__main__":
    main()
