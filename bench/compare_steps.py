#!/usr/bin/env python3
"""Before/after step timings of two or more builds on one saved world, interleaved (bench/README.md).

Like compare_kernels.py, but with crowdrecon_step_world: each round runs every
build's program once, in turn, on the same saved world and state:

    crowdrecon_step_world WORLD STATE --steps=N --warm-up=W --threads=T

A run loads the state, takes W steps, then times N steps; it takes a second
or two at 10,000 people where a developed-crowd kernel benchmark first walks
its crowd 5 simulated seconds, so many more rounds fit in the same time,
which is what this VM's drift needs. Every build must print the same contact
count and positions checksum (the same work); the script stops otherwise.

Reports per build the median wall time per step, its range, and the speed-up
of the reference build (the first --build) over each other: the ratio of the
medians, and the median of the per-round ratios (paired). Raw results to
results/bench/DATE-steps-compare[-LABEL].json; a section in bench/RESULTS.md
unless --no-results-md.

Example (worlds from `crowdrecon_bench_kernels --dump_worlds=build/worlds`):
  python3 bench/compare_steps.py --build before=/tmp/old/build/release/bench/crowdrecon_step_world \\
      --build after=build/release/bench/crowdrecon_step_world \\
      --world build/worlds/box-10000-developed --rounds 14 --steps 100 --threads 1 --label "LABEL"
"""

import argparse
import pathlib
import re
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402

LINE = re.compile(r"^([0-9.]+) ms/step\s+(\d+) steps\s+(\d+) contacts\s+positions ([0-9a-f]+)$")


def run_steps(exe, world, state, steps, warm_up, threads):
    command = [str(exe), str(world), str(state), f"--steps={steps}", f"--warm-up={warm_up}", f"--threads={threads}"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        bc.fail(f"{' '.join(command)} failed with status {done.returncode}:\n{done.stderr[-2000:]}")
    match = LINE.match(done.stdout.strip())
    if not match:
        bc.fail(f"{' '.join(command)}: unexpected output {done.stdout.strip()!r}")
    return {"ms_per_step": float(match.group(1)), "contacts": int(match.group(3)), "positions": match.group(4)}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    bc.add_comparison_arguments(p, "crowdrecon_step_world")
    p.add_argument("--world", required=True,
                   help="saved world without extension: WORLD.world and WORLD.state (crowdrecon_bench_kernels --dump_worlds)")
    p.add_argument("--rounds", type=int, default=None, help="alias of --repeat")
    p.add_argument("--steps", type=int, default=100, help="timed steps per run (default: %(default)s)")
    p.add_argument("--warm-up", type=int, default=20, help="steps before the timed ones (default: %(default)s)")
    p.add_argument("--threads", type=int, default=1, help="engine threads (default: %(default)s)")
    args = p.parse_args()
    if args.rounds is not None:
        args.repeat = args.rounds
    builds = bc.parse_builds(args)
    world = pathlib.Path(args.world)
    world_file, state_file = world.with_name(world.name + ".world"), world.with_name(world.name + ".state")
    for f in (world_file, state_file):
        if not f.exists():
            bc.fail(f"--world {args.world}: {f} not found (write the worlds with crowdrecon_bench_kernels --dump_worlds=DIR)")
    if args.steps < 1 or args.warm_up < 0 or args.threads < 1:
        bc.fail("--steps and --threads must be at least 1, --warm-up at least 0")

    started = bc.now()
    load_before = bc.warn_if_busy()
    runs = []
    for rep in range(args.repeat):
        for name, exe in builds:
            r = run_steps(exe, world_file, state_file, args.steps, args.warm_up, args.threads)
            runs.append({"rep": rep, "build": name, **r})
            print(f"  {rep + 1}/{args.repeat} {name:>10}: {r['ms_per_step']:.4f} ms/step", file=sys.stderr)
    load_after = bc.load_average()
    work = {(r["contacts"], r["positions"]) for r in runs}
    if len(work) != 1:
        bc.fail("the builds did different work (contact counts and positions checksums: "
                + ", ".join(f"{c} {h}" for c, h in sorted(work)) + "); compare builds that give the same results")

    reference = builds[0][0]
    ref = [r["ms_per_step"] for r in runs if r["build"] == reference]
    rows = []
    for name, _ in builds:
        times = [r["ms_per_step"] for r in runs if r["build"] == name]
        row = [name, f"{bc.median(times):.4f} ms", f"{min(times):.4f}–{max(times):.4f}"]
        if name == reference:
            row.append("")
        else:
            paired = [a / b for a, b in zip(ref, times)]
            row.append(f"{bc.median(ref) / bc.median(times):.3f}× (paired {bc.median(paired):.3f}×)")
        rows.append(row)
    table = bc.markdown_table(["build", "time per step (median)", "range", f"speed-up over {reference}"], rows)
    print(table)
    contacts, positions = work.pop()
    notes = ["- builds: " + ", ".join(f"{name} = `{exe}`" for name, exe in builds),
             f"- world `{world.name}`, {args.repeat} rounds, each running every build once in turn; "
             f"{args.warm_up} steps, then {args.steps} timed, {args.threads} thread(s); every run ended with "
             f"{contacts} contacts, positions checksum {positions}"]
    bc.save_comparison("steps-compare", "interleaved step builds", args, started, load_before, load_after, notes,
                       table, {"builds": [[n, str(e)] for n, e in builds], "world": str(world), "steps": args.steps,
                               "warm_up": args.warm_up, "threads": args.threads, "runs": runs})


if __name__ == "__main__":
    main()
