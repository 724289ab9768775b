#!/usr/bin/env python3
"""The wall-time cost of the profile validated against the paper's model
(issue 64): the same scenarios run under each profile (`crowdrecon simulate
SCENARIO --profile NAME`), one thread, interleaved rounds.

    bench/profile_cost.py [--exe build/release/cli/crowdrecon] [--before OTHER_EXE] [--repeat 3] [--label L]
        [--scenarios hallway,bottleneck,night-demo,evacuation-2s]

Scenarios, as shipped: the Madrid Arena hallway (periodic, 5 /m², 30 %
counter-flow, 60 s; its own free speeds U(0.8, 1.2) m/s under both
profiles), the Wuppertal bottleneck (75 people, 0.5 m, up to 120 s; its
own speeds), the Madrid night's demo (285 s; the profile's speeds: U(0.8,
1.2) with paper, U(1.0, 1.86) with validated), the evacuation of 6,800
people's first 2 s (its demo cut to 2 s: the crowd packed at the exits,
where a validated step costs most). Per scenario and profile: the
median processor time of the whole run (user + system), its wall time, the
time per step and the ratio to the paper's model, per run and per step. A
whole run's ratio is also what the crowd does (a bottleneck that clogs runs
to its end, one that empties stops early); per step is the model's cost.
With --before, another build runs the same runs, interleaved in the same
rounds, and each row gives the ratio of the two builds (a change that
should make a profile cheaper, measured before/after). Writes
results/bench/ and a section of bench/RESULTS.md (bench_common)."""

import argparse
import pathlib
import random
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402
from keeping_distance_cost import run_once  # noqa: E402

# name: (scenario, simulated seconds: None as shipped)
SCENARIOS = {
    "hallway": ("venues/madrid-arena/scenarios/hallway-5pm2-30cf.json", None),
    "bottleneck": ("venues/juelich/scenarios/wuppertal-bottleneck.json", None),
    "night-demo": ("venues/madrid-arena/scenarios/madrid-night-demo.json", None),
    "evacuation-2s": ("venues/madrid-arena/scenarios/evacuation-6800-demo.json", 2.0),
}


PROFILES = ["paper", "validated"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    bc.add_whole_run_arguments(parser, repeat=3)
    parser.add_argument("--before", help="another build, run interleaved: each row's ratio after / before")
    parser.add_argument("--scenarios", default=",".join(SCENARIOS), help="comma-separated (default: %(default)s)")
    args = parser.parse_args()
    exe = bc.checked_exe_and_repeat(args)
    builds = [("after" if args.before else "this", exe)]
    if args.before:
        before = pathlib.Path(args.before).resolve()
        if not before.exists():
            bc.fail(f"--before {args.before}: not found")
        builds.insert(0, ("before", before))
    chosen = [s for s in args.scenarios.split(",") if s]
    for s in chosen:
        if s not in SCENARIOS:
            bc.fail(f"--scenarios: unknown {s!r}, expected some of {', '.join(SCENARIOS)}")
    started = bc.now()
    load_before = bc.warn_if_busy()
    samples = {}
    rng = random.Random(1)
    copies = []
    try:
        files = {}
        for s in chosen:
            path, duration = SCENARIOS[s]
            files[s] = bc.ROOT / path if duration is None else bc.cut_scenario_copy(bc.ROOT / path, duration, "profile-cost")
            if duration is not None:
                copies.append(files[s])
        with tempfile.TemporaryDirectory() as folder:
            keys = [(s, p, b) for s in chosen for p in PROFILES for b in range(len(builds))]
            for r in range(args.repeat):
                order = list(keys)
                rng.shuffle(order)
                for key in order:
                    sample = run_once(builds[key[2]][1], files[key[0]], folder, ["--profile", key[1]])
                    samples.setdefault(key, []).append(sample)
                    print(f"round {r + 1}/{args.repeat}  {key[0]:13s} {key[1]:10s} {builds[key[2]][0]:6s} " +
                          (f"failed: {sample['failed'][:150]}" if "failed" in sample else
                           f"cpu {sample['cpu_s']:7.2f} s  wall {sample['wall_s']:7.2f} s  steps {sample['steps']:.0f}"),
                          file=sys.stderr)
    finally:
        for c in copies:
            c.unlink(missing_ok=True)
    load_after = bc.load_average()
    rows, data = [], {}
    for s in chosen:
        for b, (build, _) in enumerate(builds):
            ok = {p: [x for x in samples[(s, p, b)] if "failed" not in x] for p in PROFILES}
            cpu = {p: bc.median([x["cpu_s"] for x in ok[p]]) if ok[p] else float("nan") for p in PROFILES}
            step = {p: bc.median([x["cpu_s"] / x["steps"] for x in ok[p]]) if ok[p] else float("nan") for p in PROFILES}
            for p in PROFILES:
                data[f"{s}/{p}/{build}"] = samples[(s, p, b)]
                failed = len(samples[(s, p, b)]) - len(ok[p])
                row = [s, p] + ([build] if len(builds) > 1 else [])
                if not ok[p]:
                    rows.append(row + [f"every run failed ({failed})"] + [""] * (5 + (len(builds) > 1)))
                    continue
                row += [bc.fixed(cpu[p]), bc.fixed(bc.median([x["wall_s"] for x in ok[p]])),
                        f"{bc.median([x['steps'] for x in ok[p]]):.0f}", f"{1e6 * step[p]:.0f}",
                        bc.fixed(cpu[p] / cpu["paper"]) + (f" ({failed} failed)" if failed else ""),
                        bc.fixed(step[p] / step["paper"])]
                if len(builds) > 1:
                    base = [x for x in samples[(s, p, 0)] if "failed" not in x]
                    row.append(bc.fixed(cpu[p] / bc.median([x["cpu_s"] for x in base])) if base and b > 0 else "")
                rows.append(row)
    header_row = ["scenario", "profile"] + (["build"] if len(builds) > 1 else []) + [
        "median cpu s", "median wall s", "steps", "cpu µs / step", "run / paper", "step / paper"] + (
        ["after / before"] if len(builds) > 1 else [])
    table = bc.markdown_table(header_row, rows)
    print(table)
    notes = [f"builds: " + ", ".join(f"{n} = {e}" for n, e in builds),
             f"{args.repeat} interleaved rounds, one thread each (--threads 1 --fixed-threads)",
             "scenarios: " + ", ".join(f"{s} ({SCENARIOS[s][0]}" + (f", cut to {SCENARIOS[s][1]:g} s)" if SCENARIOS[s][1] else ", as shipped)") for s in chosen),
             "the runs differ in what they simulate as well as in cost per step (a bottleneck that empties stops early)"]
    header = bc.header_lines(bc.command_line(), started, load_before, load_after, [f"- {n}" for n in notes])
    bc.write_json(bc.default_json_path("profile-cost", started, args.label), {"samples": data, "notes": notes})
    if not args.no_results_md:
        bc.update_results("profile-cost", args.label, "The cost of the profile validated against the paper's model (issue 64)"
                          + (f": {args.label}" if args.label else ""), header + "\n\n" + table, started)


if __name__ == "__main__":
    main()
