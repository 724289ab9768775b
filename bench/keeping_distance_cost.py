#!/usr/bin/env python3
"""The cost of each form of keeping a distance (issue 64): whole runs of the
Wuppertal bottleneck and of the Juelich uni corridor at 2 persons/m2 with
each profile of the keeping-distance study, one thread, interleaved rounds.

    bench/keeping_distance_cost.py [--exe build/release/cli/crowdrecon] [--repeat 3] [--label L]
        [--profile FILE ...]   (default: pilot 2's five, studies/keeping-distance/pilot2/)

Each run is `crowdrecon simulate` of the scenario with the profile's values
(the scenario's own body and speeds removed so that the profile's apply),
--threads 1 --fixed-threads. The table gives per scenario and profile the
median processor time (user + system of the run, less sensitive to a busy
machine than wall time), the median wall time, the time per step and the
share of the engine's time in the neighbour stage and in the drive (the
terms), and the ratio to the profile without a form ("doors"). Writes its
raw data to results/bench/ and a section of bench/RESULTS.md (bench_common)."""

import argparse
import json
import os
import pathlib
import random
import re
import resource
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402

# The door mechanisms alone and with each form of keeping a distance at its
# authors' values (pilot 2).
DEFAULT_PROFILES = ["doors", "doors-anticipation", "doors-centrifugal", "doors-headway", "doors-social-force"]

SCENARIOS = {
    "wuppertal": ("venues/juelich/scenarios/wuppertal-bottleneck.json", 40.0, {}),
    "uni-2pm2": ("venues/juelich/scenarios/uni-corridor.json", 20.0, {"density_per_m2": 2.0}),
}


def scenario_copy(path, duration_s, population, profile, folder):
    """The scenario with its duration, the profile (by absolute path), no body
    or speeds of its own, written next to the original (its relative paths
    stay valid); removed after the runs."""
    data = json.loads(path.read_text())
    data["run"]["duration_s"] = duration_s
    data["run"]["checkpoint_interval_s"] = 0
    data["population"].pop("body", None)
    data["population"].pop("desired_speed_m_per_s", None)
    data["population"].update(population)
    data["profile"] = str(pathlib.Path(profile).resolve())
    data.pop("notes", None)
    copy = path.parent / f".bench-kd-{os.getpid()}-{pathlib.Path(profile).stem}-{path.name}"
    copy.write_text(json.dumps(data))
    return copy


def run_once(exe, scenario, folder, extra=()):
    """One `crowdrecon simulate` on one thread (extra: more options, e.g.
    --profile): its processor and wall time, steps and the engine's shares."""
    out = bc.fresh_run_file(folder)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    result = subprocess.run([str(exe), "simulate", str(scenario), "-o", str(out), "-q", "--threads", "1",
                             "--fixed-threads", *extra], capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if result.returncode != 0:  # (a run that goes numerically wrong is a result too: counted, not timed)
        return {"failed": result.stderr.strip().splitlines()[-1] if result.stderr.strip() else f"exit {result.returncode}"}
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    wall = float(re.search(r"simulated: [0-9.]+ s in ([0-9.]+) s wall", result.stdout).group(1))
    simulated = float(re.search(r"simulated: ([0-9.]+) s in", result.stdout).group(1))
    step = float(re.search(r"time step ([0-9.eE+-]+) s", result.stdout).group(1))
    shares = dict((k, float(v)) for k, v in re.findall(r"(\w+) ([0-9.]+) %", result.stdout.split("engine time")[1]))
    return {"cpu_s": cpu, "wall_s": wall, "steps": simulated / step, "neighbours_share": shares.get("neighbours", 0.0),
            "drive_share": shares.get("drive", 0.0)}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    bc.add_whole_run_arguments(parser, repeat=3)
    parser.add_argument("--profile", action="append", help="a profile file (may be repeated)")
    args = parser.parse_args()
    exe = bc.checked_exe_and_repeat(args)
    folder_of_study = bc.ROOT / "studies/keeping-distance/pilot2"
    profiles = [pathlib.Path(p) for p in args.profile] if args.profile else [
        folder_of_study / f"{name}.profile.json" for name in DEFAULT_PROFILES]
    for p in profiles:
        if not p.exists():
            bc.fail(f"{p}: no such profile")
    names = {p: p.name.replace(".profile.json", "") for p in profiles}
    started = bc.now()
    load_before = bc.warn_if_busy()
    samples = {}
    copies = []
    rng = random.Random(1)
    try:
        with tempfile.TemporaryDirectory() as folder:
            files = {}
            for s, (rel, duration, population) in SCENARIOS.items():
                for p in profiles:
                    files[(s, p)] = scenario_copy(bc.ROOT / rel, duration, population, p, folder)
                    copies.append(files[(s, p)])
            for r in range(args.repeat):
                order = list(files)
                rng.shuffle(order)
                for key in order:
                    sample = run_once(exe, files[key], folder)
                    samples.setdefault(key, []).append(sample)
                    print(f"round {r + 1}/{args.repeat}  {key[0]:10s} {names[key[1]]:24s} " +
                          (f"failed: {sample['failed'][:150]}" if "failed" in sample else
                           f"cpu {sample['cpu_s']:7.2f} s  wall {sample['wall_s']:7.2f} s"), file=sys.stderr)
    finally:
        for c in copies:
            c.unlink(missing_ok=True)
    load_after = bc.load_average()

    rows = []
    data = {}
    for s in SCENARIOS:
        base = next((p for p in profiles if names[p] == "doors"), profiles[0])
        base_cpu = bc.median([x["cpu_s"] for x in samples[(s, base)] if "failed" not in x] or [float("nan")])
        for p in profiles:
            data[f"{s}/{names[p]}"] = samples[(s, p)]
            failed = [x for x in samples[(s, p)] if "failed" in x]
            xs = [x for x in samples[(s, p)] if "failed" not in x]
            if not xs:
                rows.append([s, names[p], f"every run failed ({len(failed)}): {failed[0]['failed'][:120]}", "", "", "", "", ""])
                continue
            cpu = bc.median([x["cpu_s"] for x in xs])
            per_step = bc.median([x["cpu_s"] / x["steps"] for x in xs])
            rows.append([s, names[p], bc.fixed(cpu), bc.fixed(bc.median([x["wall_s"] for x in xs])),
                         f"{1e6 * per_step:.0f}", f"{bc.median([x['neighbours_share'] for x in xs]):.0f} %",
                         f"{bc.median([x['drive_share'] for x in xs]):.0f} %", bc.fixed(cpu / base_cpu)
                         + (f" ({len(failed)} failed)" if failed else "")])
    table = bc.markdown_table(["scenario", "profile", "median cpu s", "median wall s", "cpu µs / step",
                               "neighbours", "drive", f"cpu / {names[base]}"], rows)
    print(table)
    notes = [f"{args.repeat} interleaved rounds, one thread each (--threads 1 --fixed-threads)",
             "scenarios: " + ", ".join(f"{s} ({d:g} s simulated)" for s, (_, d, _) in SCENARIOS.items()),
             "the runs differ in what they simulate as well as in cost per step: a profile whose crowd leaves the "
             "bottleneck sooner has fewer people in it for the rest of the run; µs / step is per step of the whole crowd"]
    header = bc.header_lines(bc.command_line(), started, load_before, load_after, [f"- {n}" for n in notes])
    json_path = bc.default_json_path("keeping-distance-cost", started, args.label)
    bc.write_json(json_path, {"samples": data, "notes": notes})
    if not args.no_results_md:
        bc.update_results("keeping-distance-cost", args.label, "The cost of keeping a distance (issue 64)"
                          + (f": {args.label}" if args.label else ""), header + "\n\n" + table, started)


if __name__ == "__main__":
    main()
