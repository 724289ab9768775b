#!/usr/bin/env python3
"""Text phase diagrams and regime boundaries of a sweep (results.sqlite).

usage: phase-table.py DIR [DIR ...] [--x VALUES] [--y VALUES] [--metric COLUMN]

For every variant of every sweep: a grid of the majority regime over seeds
(rows: counter-flow fraction, high to low; columns: density), with one letter
per point: L lanes, A avalanches, C clogging, U unclassified, F failed,
? no majority; a lower-case letter marks a point where the seeds disagree.
Then, per density, the lowest counter-flow fraction whose majority is not
lanes (the lanes boundary) and the lowest whose majority is clogging. Reads
the sweep's `diagram` axes from the stored sweep file. --x/--y keep only the
listed axis values (to compare a fine sweep with a coarse one); --metric adds
a grid of that results column, averaged over seeds. Python standard library only.
Each DIR must be a sweep folder (results.sqlite) with runs and diagram axes;
--x/--y are comma-separated numbers and --metric a column of every sweep's
runs table (scripts/script_guard.py: a bad argument is one line, exit 2).
"""
import argparse
import collections
import json
import os
import sqlite3
import sys

import script_guard as guard  # (this folder: the scripts are run as files, so it is on the path)

LETTER = {"lanes": "L", "avalanches": "A", "clogging": "C", "unclassified": "U"}


def majority(votes):
    count = collections.Counter(votes)
    (top, n), = count.most_common(1)
    if list(count.values()).count(n) > 1:
        return "?", True
    return top, len(count) > 1


METRIC = "NULL"


def load(folder):
    con = sqlite3.connect(f"file:{os.path.join(folder, 'results.sqlite')}?mode=ro", uri=True)  # never creates one
    meta = dict(con.execute("SELECT key, value FROM sweep").fetchall())
    sweep = {"name": meta.get("name", folder)}
    x, y = meta["diagram_x"], meta["diagram_y"]
    rows = con.execute(f'SELECT variant, "{x}", "{y}", status, regime, {METRIC} FROM runs ORDER BY run_index').fetchall()
    wall = con.execute("SELECT SUM(wall_s), COUNT(*) FROM runs").fetchone()
    return sweep, x, y, rows, wall


def regime_of(status, regime):
    if status != "complete" and status.startswith("failed"):
        return "F"
    return LETTER.get(regime, "U")


def check_sweep(folder, metric):
    """The sweep's diagram axes and --metric are columns of its runs table, and it holds runs."""
    db = os.path.join(folder, "results.sqlite")
    con = guard.open_readonly(db)
    try:
        meta = dict(con.execute("SELECT key, value FROM sweep").fetchall())
        runs = con.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
    finally:
        con.close()
    columns = guard.table_columns(db, "runs")
    for key in ("diagram_x", "diagram_y"):
        if key not in meta:
            raise guard.ScriptError(f"{folder}: its sweep has no {key}; expected a sweep with a phase diagram's axes")
        if meta[key] not in columns:
            raise guard.ScriptError(f"{folder}: its {key} {meta[key]!r} is not a column of its runs; "
                                    "expected the results of a crowdrecon sweep")
    for key in ("variant", "status", "regime", "run_index", "wall_s"):
        if key not in columns:
            raise guard.ScriptError(f"{folder}: its runs table has no column {key}; expected the results of a crowdrecon sweep")
    if metric is not None and metric.replace('"', '') not in columns:
        raise guard.ScriptError(f"--metric {metric}: not a column of {folder}'s runs table; "
                                "expected one such as mean_speed_m_per_s")
    if runs == 0:
        raise guard.ScriptError(f"{folder}: its runs table is empty; expected a sweep that has run")


def main():
    p = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dirs", nargs="+", type=guard.sweep_dir, help="sweep output folders (results.sqlite)")
    p.add_argument("--x", type=guard.float_list, help="comma-separated x values to keep")
    p.add_argument("--y", type=guard.float_list, help="comma-separated y values to keep")
    p.add_argument("--metric", help="a results column to tabulate too (mean over seeds)")
    args = p.parse_args()
    for folder in args.dirs:
        check_sweep(folder, args.metric)
    global METRIC
    if args.metric:
        METRIC = '"' + args.metric.replace('"', '') + '"'
    keep_x = set(args.x) if args.x else None
    keep_y = set(args.y) if args.y else None
    for folder in args.dirs:
        sweep, x, y, rows, wall = load(folder)
        print(f"## {sweep.get('name', folder)}\n")
        # (A table whose wall times are all empty sums to NULL: none recorded.)
        print(f"{wall[1]} runs, " + (f"{wall[0] / 3600:.2f} h of run wall time in total (sum over runs)"
                                     if wall[0] is not None else "no run wall time recorded") + "\n")
        variants = list(dict.fromkeys(r[0] for r in rows))
        for variant in variants:
            votes = collections.defaultdict(list)
            values = collections.defaultdict(list)
            for v, xv, yv, status, regime, metric in rows:
                if v != variant or (keep_x and float(xv) not in keep_x) or (keep_y and float(yv) not in keep_y):
                    continue
                votes[(xv, yv)].append(regime_of(status, regime))
                if metric is not None:
                    values[(xv, yv)].append(metric)
            xs = sorted({k[0] for k in votes})
            ys = sorted({k[1] for k in votes}, reverse=True)
            print(f"### variant {variant}\n")
            print("| counter-flow \\ density | " + " | ".join(f"{v:g}" for v in xs) + " |")
            print("| --- |" + " --- |" * len(xs))
            grid = {}
            for yv in ys:
                cells = []
                for xv in xs:
                    if (xv, yv) not in votes:
                        cells.append(" ")
                        continue
                    letter, split = majority(votes[(xv, yv)])
                    grid[(xv, yv)] = letter
                    cells.append(letter.lower() if split and letter != "?" else letter)
                print(f"| {yv:g} | " + " | ".join(cells) + " |")
            print()
            print("| density | lowest counter-flow not lanes | lowest counter-flow clogging |")
            print("| --- | --- | --- |")
            for xv in xs:
                column = sorted((yv, grid[(xv, yv)]) for yv in ys if (xv, yv) in grid)
                not_lanes = next((f"{yv:g}" for yv, g in column if g != "L"), "none")
                clog = next((f"{yv:g}" for yv, g in column if g == "C"), "none")
                print(f"| {xv:g} | {not_lanes} | {clog} |")
            print()
            if args.metric:
                print(f"{args.metric}, mean over seeds:\n")
                print("| counter-flow \\ density | " + " | ".join(f"{v:g}" for v in xs) + " |")
                print("| --- |" + " --- |" * len(xs))
                for yv in ys:
                    cells = [f"{sum(values[(xv, yv)]) / len(values[(xv, yv)]):.3g}" if values.get((xv, yv)) else " "
                             for xv in xs]
                    print(f"| {yv:g} | " + " | ".join(cells) + " |")
                print()
    return 0


if __name__ == "__main__":
    guard.run_main(main)
