#!/usr/bin/env python3
"""The fixed against the adaptive step on the issue's budgets, interleaved (issue 42; bench/README.md).

For each scenario, ROUNDS rounds; in each round both steps run once, in turn
(the order alternating between rounds, on a machine whose speed drifts):

    crowdrecon simulate SCENARIO(model.time_step_mode = MODE) -o TMP --threads T -q

under /usr/bin/time, as bench/run_benchmarks.py does (its run_once and
steady_difference). Scenarios:

  evacuation   venues/madrid-arena/scenarios/evacuation-6800-demo.json, its
               first DURATION s (default 20) with every contact written at
               10 frames/s: minutes of wall per simulated minute (budget 4)
  box-10000    bench/scenarios/box-10000.json, the 2 s after 4 s of walking
               (a developed crowd, the difference of a 6-s and a 4-s run):
               the real-time factor (budget 1)

Reports per scenario and step the median and range over the rounds, the
ratio of the medians (fixed / adaptive) and the median of the per-round
ratios; raw results to results/bench/DATE-step-modes[-LABEL].json and a
section of bench/RESULTS.md (unless --no-results-md).

usage: bench/step_modes.py [--scenarios evacuation,box-10000] [--threads 2] [--rounds 3]
                           [--duration 20] [--exe build/release/cli/crowdrecon] [--label L]
"""
import argparse
import json
import pathlib
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402
import run_benchmarks as rb  # noqa: E402

MODES = ("fixed", "adaptive")


def with_mode(copy, mode):
    """The scenario copy (rb.scenario_copy's, in this run's folder) with its step's mode set, in place."""
    d = json.loads(copy.read_text())
    d.setdefault("model", {})["time_step_mode"] = mode
    copy.write_text(json.dumps(d, indent=2))
    return copy


def measure(name, mode, work, args):
    folder = pathlib.Path(work) / f"{name}-{mode}"
    folder.mkdir(exist_ok=True)
    if name == "evacuation":
        source = bc.ROOT / "venues/madrid-arena/scenarios/evacuation-6800-demo.json"
        scenario = with_mode(rb.scenario_copy(source, args.duration, folder), mode)
        r = rb.run_once(args.exe, scenario, args.threads, folder)
        return {"figure": r["loop_wall_s"] / r["simulated_s"], "unit": "min of wall per simulated min",
                "budget": 4.0, "better": "lower", "run": r}
    if name == "box-10000":
        source = bc.ROOT / "bench/scenarios/box-10000.json"
        first = with_mode(rb.scenario_copy(source, 4.0, folder), mode)
        whole_folder = folder / "whole"
        whole_folder.mkdir(exist_ok=True)
        whole = with_mode(rb.scenario_copy(source, 6.0, whole_folder), mode)
        r = rb.steady_difference(rb.run_once(args.exe, first, args.threads, folder),
                                 rb.run_once(args.exe, whole, args.threads, folder))
        return {"figure": r["real_time_factor"], "unit": "real-time factor", "budget": 1.0, "better": "higher",
                "run": r}
    bc.fail(f"unknown scenario {name}: evacuation or box-10000")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenarios", default="evacuation,box-10000")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--duration", type=float, default=20.0, help="simulated seconds of the evacuation")
    p.add_argument("--exe", default=str(bc.ROOT / "build/release/cli/crowdrecon"))
    p.add_argument("--label", default="")
    p.add_argument("--no-results-md", action="store_true")
    args = p.parse_args()
    if args.rounds < 1:
        bc.fail("--rounds must be at least 1")
    args.exe = pathlib.Path(args.exe).resolve()
    started = bc.now()
    load_before = bc.warn_if_busy()
    names = [s for s in args.scenarios.split(",") if s]
    data = {name: {m: [] for m in MODES} for name in names}
    with tempfile.TemporaryDirectory(prefix="crowdrecon-step-modes-") as work:
        for rnd in range(args.rounds):
            for name in names:
                order = MODES if rnd % 2 == 0 else tuple(reversed(MODES))
                for mode in order:
                    m = measure(name, mode, work, args)
                    data[name][mode].append(m)
                    print(f"  round {rnd + 1}/{args.rounds} {name} {mode}: {m['figure']:.3f} {m['unit']}",
                          file=sys.stderr, flush=True)
    load_after = bc.load_average()
    rows = []
    for name in names:
        f = {mode: [m["figure"] for m in data[name][mode]] for mode in MODES}
        first = data[name]["fixed"][0]
        paired = [a / b for a, b in zip(f["fixed"], f["adaptive"]) if b]
        for mode in MODES:
            met = (bc.median(f[mode]) <= first["budget"]) if first["better"] == "lower" else (
                bc.median(f[mode]) >= first["budget"])
            rows.append([name, mode, f"{bc.median(f[mode]):.3f} ({min(f[mode]):.3f}–{max(f[mode]):.3f})",
                         first["unit"], f"{first['budget']:g}", "met" if met else "**not met**",
                         f"{bc.median(f['fixed']) / bc.median(f['adaptive']):.3f}; paired {bc.median(paired):.3f}"
                         if mode == "adaptive" else ""])
    table = bc.markdown_table(["scenario", "step", "median (range)", "unit", "budget", "", "fixed / adaptive"], rows)
    header = bc.header_lines(bc.command_line(), started, load_before, load_after,
                             [f"- {args.rounds} rounds, the steps in turn (order alternating), {args.threads} thread(s)",
                              f"- evacuation: its first {args.duration:g} s only, a slice of the budget's run (the crowd "
                              "at the exits densifies later); \"met\" says this slice is inside the budget, not the run",
                              "- box-10000: a difference of two runs (6 s and 4 s), so its spread is wide"])
    print(header + "\n\n" + table)
    stamp = started
    path = bc.default_json_path("step-modes", stamp, args.label)
    bc.write_json(path, {"args": {k: str(v) for k, v in vars(args).items()}, "data": data})
    if not args.no_results_md:
        bc.update_results("step-modes", args.label, f"{stamp.strftime('%Y-%m-%d %H:%M UTC')} · fixed against adaptive "
                          f"step on the budgets · {args.label}", header + "\n\n" + table, stamp)


if __name__ == "__main__":
    main()
