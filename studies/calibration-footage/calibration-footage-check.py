#!/usr/bin/env python3
"""The footage design checked against actual calibrations (issue 41, point 4).

`crowdrecon calibrate` predicts, from the seeds' covariance of the statistics
and the surrogate's Jacobian at its best fit, how precisely N recordings of T
seconds determine each parameter (report.txt "How much footage", footage.csv;
docs/calibration.md). This script checks that prediction where it can be
checked: at one truth, it repeats the whole process REPLICATES times for two
designs (R1 and R2 recordings of the cheap recovery problem, each replicate
with recordings of its own seeds and calibration seeds of its own; the
coverage script's machinery, studies/calibration-coverage/calibration-coverage.py) and compares

  - the scatter of the fitted values over the replicates (their sample
    standard deviation, with its own uncertainty sd / sqrt(2 (R - 1))),
  - with the design's prediction for that calibration (footage.this_calibration:
    its recordings and its K seeds; the median over the replicates).

A parameter whose predicted 95 % interval is wider than its bounds is held by
the bounds, not by the footage: its fitted values cannot scatter as predicted
and it is reported, not compared.

    studies/calibration-footage/calibration-footage-check.py OUT [--replicates 8] [--designs 1,4] [--seeds 3]

Before any work (scripts/script_guard.py, as the coverage script): at least
two replicates (a scatter needs two), designs of 1 to 100 recordings whose
replicates share no truth, K from 2 to 1000, the crowdrecon executable, and OUT
new, empty or a previous footage check's folder (else --force, which writes
into it and deletes nothing); footage-check.md is written whole.
"""
import argparse
import importlib.util
import json
import math
import os
import statistics
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # studies/NAME/ is two levels down
spec = importlib.util.spec_from_file_location(
    "coverage", os.path.join(ROOT, "studies", "calibration-coverage", "calibration-coverage.py"))
coverage = importlib.util.module_from_spec(spec)
spec.loader.exec_module(coverage)
guard = coverage.guard  # scripts/script_guard.py, put on the path by the coverage script

TRUTH = {"population.desired_speed_m_per_s": 1.2, "model.restitution": 0.4}


def design_list(text):
    """argparse type=: recordings per calibration, comma-separated whole numbers from 1 to 100, none twice."""
    values = guard.float_list(text, guard.int_between(1, 100, "recordings per calibration"))
    for k, v in enumerate(values):
        if v in values[:k]:
            raise argparse.ArgumentTypeError(f"{v} is given twice; expected each design once")
    return values


def truth_index(design, k):
    """Replicate k of design R: recordings and seeds of its own (offset so that designs share none)."""
    return 50 + 10 * design + k


def main():
    p = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out")
    p.add_argument("--replicates", type=guard.int_between(2, 100, "the scatter of the fitted values needs two"),
                   default=8)
    p.add_argument("--designs", default="1,4", type=design_list, help="recordings per calibration, one design each")
    p.add_argument("--seeds", type=guard.int_between(2, 1000, "K: a calibration needs two seeds at least"), default=3)
    coverage.add_common_arguments(p)
    args = p.parse_args()
    used = {}
    for design in args.designs:
        for k in range(args.replicates):
            i = truth_index(design, k)
            if i in used:
                raise guard.ScriptError(f"--designs {','.join(map(str, args.designs))} with --replicates "
                                        f"{args.replicates}: designs {used[i]} and {design} would share truth {i} "
                                        "(their recordings' seeds); expected fewer replicates or designs further "
                                        "apart (replicate k of design R is truth 50 + 10 R + k)")
            used[i] = design
    outputs = [guard.Output("OUT", args.out, "a folder of calibration-footage-check.py", folder=True,
                            is_previous=guard.folder_with({"footage-check.md": guard.starts_with(coverage.FOOTAGE_HEAD),
                                                           "recordings-*": os.path.isdir})),
               guard.Output("", os.path.join(args.out, "footage-check.md"), "a report of calibration-footage-check.py",
                            guard.starts_with(coverage.FOOTAGE_HEAD))]
    guard.check_outputs(outputs, [], args.force)
    for design in args.designs:
        sub_out = os.path.join(args.out, f"recordings-{design}")
        coverage.out_folder("", sub_out, args.force, {})
        coverage.check_truth_folders(sub_out, [truth_index(design, k) for k in range(args.replicates)], args.force)
    os.makedirs(args.out, exist_ok=True)
    t0 = time.time()
    lines = ["# The footage design against actual calibrations", "",
             f"Truth {json.dumps(TRUTH)}; {args.replicates} replicates per design, K = {args.seeds} seeds; "
             "the cheap recovery problem (tests/data/calibration/recovery*.json, bounds = the coverage check's prior).", "",
             "| design | parameter | fitted values: mean; sd (± its uncertainty) | predicted sd (median over replicates) | "
             "ratio observed / predicted | the calibrations' own posterior sd (median) |",
             "| --- | --- | --- | --- | --- | --- |"]
    for design in args.designs:
        sub = argparse.Namespace(**vars(args))
        sub.out = os.path.join(args.out, f"recordings-{design}")
        sub.recordings = design
        os.makedirs(sub.out, exist_ok=True)
        results = []
        for k in range(args.replicates):
            # replicate k of design R: recordings and seeds of its own (offset so that designs share none)
            r, _ = coverage.calibrate_truth(sub, truth_index(design, k), TRUTH)
            results.append(r)
            print(f"design {design} recordings, replicate {k + 1}/{args.replicates} done "
                  f"({time.time() - t0:.0f} s)", file=sys.stderr)
        for i, path in enumerate(TRUTH):
            fitted = [r["parameters"][i]["value"] for r in results]
            predicted = [r["footage"]["this_calibration"]["sd"][path] for r in results]
            posterior = [r["parameters"][i].get("posterior", {}).get("sd") for r in results]
            predicted = [x for x in predicted if x is not None and math.isfinite(x)]
            sd = statistics.stdev(fitted)
            err = sd / math.sqrt(2 * (len(fitted) - 1))
            pred = statistics.median(predicted) if predicted else float("nan")
            lo, hi = [b for b in coverage.PRIOR[path]]
            held = 1.96 * pred > 0.5 * (hi - lo)
            post = statistics.median([x for x in posterior if x is not None]) if any(posterior) else float("nan")
            ratio = "held by the bounds (predicted 95 % wider than the range)" if held else f"{sd / pred:.2f} ± {err / pred:.2f}"
            lines.append(f"| {design} recording(s) | {path} | {statistics.mean(fitted):.3f}; {sd:.3f} ± {err:.3f} | "
                         f"{pred:.3f} | {ratio} | {post:.3f} |")
    lines += ["", f"Wall time: {time.time() - t0:.0f} s."]
    guard.write_whole(os.path.join(args.out, "footage-check.md"), "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    guard.run_main(main)
