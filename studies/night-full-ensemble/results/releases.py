#!/usr/bin/env python3
"""Each whole night's avalanches and what they released, from its run file alone.

For every run file given: the run's own avalanche events (the timeline's
avalanche system, hallway-wide; docs/scenarios.md), each with the people who
left the hallway in the 60 s after it (by exit, and how many of them left by
the exit behind them: a person of the leaving group pushed back into the
court); the people inside at 60-s marks; and when the hallway was last seen
moving (the last frame whose walking people's mean speed was above 0.1 m/s);
and, at the last frame, the two groups' head counts and mean positions along
the hallway (a frozen night's jam is two blocks face to face).
Reads the tables `event`, `person`, `census`, `person_state` (docs/scenarios.md,
"The run file").

usage: releases.py RUN.sqlite... > releases.md

Each argument must be a run file with those tables (and frame_time,
trajectory_data); anything else is one line, exit status 2
(scripts/script_guard.py).
"""
import os
import sqlite3
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # studies/NAME/results/
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import script_guard as guard  # noqa: E402

TABLES = ("event", "person", "census", "person_state", "frame_time", "trajectory_data")


def clock(t):
    s = int(round(t)) + 2 * 3600  # the night's clock starts at 02:00
    return f"{s // 3600:02d}:{s % 3600 // 60:02d}:{s % 60:02d}"


def main(paths):
    print("| run | avalanche at | stop before it | left in the next 60 s (to the street / into the court / pushed back) | inside before → 60 s after |")
    print("| --- | --- | --- | --- | --- |")
    summary = []
    for path in paths:
        db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        name = path.rsplit("/", 1)[-1].removesuffix(".sqlite")
        status, = db.execute("SELECT value FROM run WHERE key = 'status'").fetchone() or ("?",)
        end, = db.execute("SELECT MAX(time_s) FROM census").fetchone()

        def inside(t):
            row = db.execute("SELECT walking FROM census WHERE time_s <= ? ORDER BY frame DESC LIMIT 1", (t,)).fetchone()
            return row[0] if row else 0

        avalanches = db.execute("SELECT time_s, detail FROM event WHERE kind = 'avalanche' ORDER BY time_s").fetchall()
        crowd = [(t, d) for t, d in avalanches if d.startswith("crowd")]
        for t, detail in avalanches:
            stop = detail.split("after a stop of ")[1].split(",")[0] if "after a stop of " in detail else "?"
            left = dict(db.execute(
                "SELECT e.detail || '/' || p.target, COUNT(*) FROM event e JOIN person p ON p.id = e.person "
                "WHERE e.kind = 'exit' AND e.time_s > ? AND e.time_s <= ? GROUP BY e.detail, p.target",
                (t, t + 60.0)).fetchall())
            street = left.get("exit/to_exit", 0) + left.get("exit/to_court", 0)
            court = left.get("court/to_court", 0)
            back = left.get("court/to_exit", 0)
            who = detail.split(":")[0]
            print(f"| {name} | {clock(t)} ({t:.1f} s), {who} | {stop} | {street} / {court} / {back} | "
                  f"{inside(t)} → {inside(t + 60.0)} |")
        moving = db.execute(
            "SELECT MAX(f.time_s) FROM (SELECT frame, AVG(SQRT(vel_x * vel_x + vel_y * vel_y)) AS speed "
            "FROM person_state WHERE state = 0 GROUP BY frame) m JOIN frame_time f ON f.frame = m.frame "
            "WHERE m.speed > 0.1").fetchone()[0]
        last_frame, = db.execute("SELECT MAX(frame) FROM frame_time").fetchone()
        blocks = dict((g, (n, x)) for g, n, x in db.execute(
            "SELECT p.grp, COUNT(*), AVG(t.pos_x) FROM trajectory_data t JOIN person p ON p.id = t.id "
            "WHERE t.frame = ? GROUP BY p.grp", (last_frame,)).fetchall())
        face = " / ".join(f"{blocks[g][0]} at x {blocks[g][1]:.1f} m" if g in blocks else "0" for g in (0, 1))
        summary.append((name, status, end, len(avalanches), len(crowd), moving, inside(end), face))
    print()
    print("| run | status | end | avalanches (crowd-wide) | last moving (mean speed > 0.1 m/s) | inside at the end | "
          "leaving / entering group at the end (mean x; the court at x 0, the street at 12) |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for name, status, end, n, c, moving, last, face in summary:
        print(f"| {name} | {status} | {clock(end)} | {n} ({c}) | {clock(moving) if moving is not None else '–'} | {last} "
              f"| {face} |")


def arguments():
    p = guard.ArgumentParser(description=__doc__.strip().splitlines()[0])
    p.add_argument("runs", nargs="+", metavar="RUN.sqlite", help="run files of whole nights")
    args = p.parse_args()
    for path in args.runs:
        guard.check_run_file(path, TABLES, "the run file of a whole night (a run with a timeline: its census "
                                           "and events)")
    return args.runs


if __name__ == "__main__":
    guard.run_main(lambda: main(arguments()))
