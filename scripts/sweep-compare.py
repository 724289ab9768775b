#!/usr/bin/env python3
"""Paired differences of a metric between two variants of sweeps.

Compares, run by run, the rows of sweep results (results.sqlite written by
`crowdrecon sweep`) that share a seed and the values of the diagram axes:
variant B minus variant A, averaged over the selected points, with the
standard error over the paired differences. Used for the readings in
results/sweeps/madrid-arena/README.md.

usage: sweep-compare.py A_DIR:VARIANT B_DIR:VARIANT [--metric M]
                        [--min-y Y] [--max-y Y] [--min-x X] [--max-x X]

A_DIR and B_DIR may be the same folder (two variants of one sweep) or two
sweeps over grids that share points (a coarse grid inside a fine one); only
points present in both are compared. Exit status 1 if none are. A bad
argument (a folder that is not a sweep, a variant or metric it does not hold,
a minimum above its maximum) is one line and exit status 2
(scripts/script_guard.py).
"""
import argparse
import math
import os
import sqlite3
import sys

import script_guard as guard  # (this folder: the scripts are run as files, so it is on the path)


def sweep_variant(spec):
    """argparse type=: DIR:VARIANT, DIR a sweep folder holding VARIANT."""
    folder, colon, variant = spec.rpartition(":")
    if not colon or not folder or not variant:
        raise argparse.ArgumentTypeError(f"{spec!r} is not DIR:VARIANT; expected a sweep folder and one of its "
                                               "variants, such as results/sweeps/madrid-arena/hallway-gamma:gamma-0.6")
    guard.sweep_dir(folder)
    variants = guard.sweep_variants(folder)
    if variant not in variants:
        raise argparse.ArgumentTypeError(f"{spec}: {folder} has no variant {variant!r}; expected one of "
                                               + ", ".join(variants))
    return spec


def load(spec, metric):
    folder, variant = spec.rsplit(":", 1)
    if metric not in guard.table_columns(os.path.join(folder, "results.sqlite"), "runs"):
        raise guard.ScriptError(f"--metric {metric}: not a column of {folder}'s runs table; "
                                "expected one such as mean_speed_m_per_s")
    con = sqlite3.connect(f"file:{folder}/results.sqlite?mode=ro", uri=True)  # never creates one
    meta = dict(con.execute("SELECT key, value FROM sweep"))
    x, y = meta["diagram_x"], meta["diagram_y"]
    rows = con.execute(
        f'SELECT "{x}", "{y}", seed, "{metric}" FROM runs WHERE variant = ? AND status = \'complete\'', (variant,))
    out = {}
    for vx, vy, seed, value in rows:
        if value is not None:
            out[(round(float(vx), 9), round(float(vy), 9), int(seed))] = float(value)
    if not out:
        sys.exit(f"sweep-compare: no complete runs of variant '{variant}' with {metric} in {folder}")
    return out


def main():
    p = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("a", type=sweep_variant)
    p.add_argument("b", type=sweep_variant)
    p.add_argument("--metric", default="mean_speed_m_per_s")
    p.add_argument("--min-x", type=guard.finite_float, default=-math.inf)
    p.add_argument("--max-x", type=guard.finite_float, default=math.inf)
    p.add_argument("--min-y", type=guard.finite_float, default=-math.inf)
    p.add_argument("--max-y", type=guard.finite_float, default=math.inf)
    args = p.parse_args()
    for axis in ("x", "y"):
        low, high = getattr(args, f"min_{axis}"), getattr(args, f"max_{axis}")
        if low > high:
            raise guard.ScriptError(f"--min-{axis} {low:g} is above --max-{axis} {high:g}; expected a minimum at or "
                                    "below the maximum")
    a, b = load(args.a, args.metric), load(args.b, args.metric)
    keys = sorted(k for k in a if k in b and args.min_x <= k[0] <= args.max_x and args.min_y <= k[1] <= args.max_y)
    if not keys:
        sys.exit("sweep-compare: no common (point, seed) in the selection")
    d = [b[k] - a[k] for k in keys]
    mean = sum(d) / len(d)
    sem = math.sqrt(sum((v - mean) ** 2 for v in d) / (len(d) - 1) / len(d)) if len(d) > 1 else float("nan")
    points = len({(k[0], k[1]) for k in keys})
    print(f"{args.metric}: {args.b} - {args.a} = {mean:+.4f} +- {sem:.4f} "
          f"(paired by seed over {len(d)} runs at {points} points; A mean {sum(a[k] for k in keys) / len(keys):.4f})")


if __name__ == "__main__":
    guard.run_main(main)
