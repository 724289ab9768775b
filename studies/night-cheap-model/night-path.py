#!/usr/bin/env python3
"""The Madrid night's path through the phase diagram, read from whole-night runs.

For every run file given, one row per sample (every --every-s simulated
seconds): the people inside the hallway (0 <= x <= 12, 0 <= y <= 3: the open
hallway of venues/madrid-arena/hallway-open.json), per group, the density
(people / 36 m^2, the phase diagrams' measure: model persons per m^2), the
counter-flow share (the smaller group's share of the people inside: the
phase diagrams' counter_flow_fraction, which is symmetric about 0.5) and the
mean speed of the people inside. This is the curve the paper's Figure 5
draws as an arrow ("a dense crowd of people leaving the party. Then a
counter-flow of people joining the event increased the density, and finally
it produced the avalanches and eventually the fatal clogging"), measured on
the model's own nights.

Usage: night-path.py RUN.sqlite [RUN.sqlite ...] -o paths.csv [--every-s 10]

Only the frames sampled are read (the run files' (frame, id) indexes), so a
2-3 GB night takes well under a minute.

Before any work (scripts/script_guard.py): each RUN must be a run file with
the tables read, --every-s a positive number, and -o never a run (also by
another name or link), an existing file that is not a previous paths CSV only
with --force; the CSV is written whole. A bad argument is one line, exit 2.
"""
import argparse
import csv
import json
import math
import os
import sqlite3
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # studies/NAME/ is two levels down
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import script_guard as guard  # noqa: E402

HALLWAY = (0.0, 12.0, 0.0, 3.0)
AREA_M2 = (HALLWAY[1] - HALLWAY[0]) * (HALLWAY[3] - HALLWAY[2])


def read_scenario(path):
    """The scenario a run ran (with a sweep's overrides applied), from its run table."""
    db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    row = db.execute("SELECT value FROM run WHERE key = 'scenario'").fetchone()
    db.close()
    if row is None:
        raise guard.ScriptError(f"{path}: the run file has no scenario; expected a run file of crowdrecon simulate")
    return json.loads(row[0])


def read_run(path, every_s):
    db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    group = dict(db.execute("SELECT id, grp FROM person"))
    frames = db.execute("SELECT frame, time_s FROM frame_time ORDER BY frame").fetchall()
    if not frames:
        raise guard.ScriptError(f"{path}: the run has no frames; expected a run that has begun")
    rows = []
    next_t = 0.0
    for frame, t in frames:
        if t + 1e-9 < next_t:
            continue
        next_t = t + every_s
        inside = {}
        for pid, x, y in db.execute(
                "SELECT id, pos_x, pos_y FROM trajectory_data WHERE frame = ?", (frame,)):
            if HALLWAY[0] <= x <= HALLWAY[1] and HALLWAY[2] <= y <= HALLWAY[3]:
                inside[pid] = group.get(pid, -1)
        speeds = [math.hypot(vx, vy) for pid, vx, vy in db.execute(
            "SELECT id, vel_x, vel_y FROM person_state WHERE frame = ?", (frame,)) if pid in inside]
        n = len(inside)
        n0 = sum(1 for g in inside.values() if g == 0)
        n1 = sum(1 for g in inside.values() if g == 1)
        rows.append({
            "time_s": t,
            "inside": n,
            "main": n0,
            "counter": n1,
            "density_per_m2": n / AREA_M2,
            "counter_flow_share": (min(n0, n1) / n) if n else 0.0,
            "counter_share_raw": (n1 / n) if n else 0.0,
            "mean_speed_m_per_s": (sum(speeds) / len(speeds)) if speeds else 0.0,
        })
    db.close()
    return rows


TABLES = ("person", "frame_time", "trajectory_data", "person_state")
CSV_HEAD = "run,time_s,inside,"


def main():
    ap = guard.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("-o", "--output", required=True)
    ap.add_argument("--every-s", type=guard.positive_float, default=10.0)
    guard.add_force(ap)
    args = ap.parse_args()
    guard.refuse_repeated(args.runs, "run file")
    for run in args.runs:
        guard.check_run_file(run, TABLES)
    guard.check_outputs([guard.Output("-o", args.output, "a paths CSV of night-path.py", guard.starts_with(CSV_HEAD))],
                        [("a run file", r) for r in args.runs], args.force)
    with guard.whole_file(args.output, "w", newline="") as f:
        w = None
        for run in args.runs:
            name = os.path.splitext(os.path.basename(run))[0]
            rows = read_run(run, args.every_s)
            print(f"{name}: {len(rows)} samples", file=sys.stderr, flush=True)
            for r in rows:
                r = {"run": name, **r}
                if w is None:
                    w = csv.DictWriter(f, fieldnames=list(r))
                    w.writeheader()
                w.writerow(r)


if __name__ == "__main__":
    guard.run_main(main)
