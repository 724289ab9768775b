#!/usr/bin/env python3
"""The Itaewon runs' densities in the alley against the published ones (issue 43).

For each run file (the evening, t = 0 at 21:45), the people in each of the
venue's measurement areas and in the whole alley (the slope's region) over a
10-s window around 22:15, 22:20 and 22:25 (the times of the National Forensic
Service's densities, docs/itaewon.md "The recorded times"), as persons/m² of
the model's bodies and as real-size people (the same floor covered by ANSUR II
median bodies, 0.0868 m², the runs' validity statements' measure).

    studies/itaewon-evening-ensemble/itaewon-densities.py RUN.sqlite... -o DENSITIES.md [--csv DENSITIES.csv]
        [--also 22:00,22:10]

--also adds evening times without a recorded density (HH:MM between 21:45 and
22:30), measured the same way, to compare runs before the recorded times.

A run that ended before a time (or, still running, has not reached it) gives no
figure for it (said in the table). The outputs are checked before any work and
written whole (scripts/script_guard.py): never a run file given, never a file
that is not a previous table of this script unless --force; --scale is a
positive number.
"""
import csv
import json
import math
import os
import sqlite3
import statistics
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # studies/NAME/ is two levels down
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import script_guard as guard  # noqa: E402

# The National Forensic Service's densities in the alley (CCTV and simulation
# analysis in the police special investigation, as reported; docs/itaewon.md).
RECORDED = [("22:15", 1800.0, 7.72, 8.39), ("22:20", 2100.0, 8.06, 9.40), ("22:25", 2400.0, 9.07, 10.74)]
WINDOW_S = 10.0
REFERENCE_BODY_M2 = 0.0868  # ANSUR II median body (analysis/plausibility: the validity statements' reference)


def ring_area(ring):
    return abs(sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(ring, ring[1:] + ring[:1]))) / 2.0


def inside(ring, x, y):
    hit = False
    for (x1, y1), (x2, y2) in zip(ring, ring[1:] + ring[:1]):
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            hit = not hit
    return hit


def body_area(radius, vertices):
    ring = [tuple(v) for v in vertices]
    perimeter = sum(math.dist(a, b) for a, b in zip(ring, ring[1:] + ring[:1]))
    return ring_area(ring) + perimeter * radius + math.pi * radius * radius


EVENING_START_MIN = 21 * 60 + 45  # t = 0 of the evening's runs


def evening_time(text):
    """HH:MM of the evening (21:45-22:30) as (text, run seconds); ScriptError otherwise."""
    try:
        h, m = text.split(":")
        minutes = int(h) * 60 + int(m)
        if len(m) != 2 or not 0 <= int(m) < 60:
            raise ValueError
    except ValueError:
        raise guard.ScriptError(f"--also: {text!r} is not a time HH:MM; expected times such as 22:00") from None
    if not EVENING_START_MIN <= minutes <= EVENING_START_MIN + 45:
        raise guard.ScriptError(f"--also: {text} is outside the evening; expected a time from 21:45 to 22:30")
    return f"{minutes // 60}:{minutes % 60:02d}", 60.0 * (minutes - EVENING_START_MIN)


def read_run(path, scale, times=RECORDED):
    db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    run = dict(db.execute("select key, value from run"))
    venue = json.loads(run["venue"])
    areas = [(a["id"], a["polygon"]) for a in venue.get("measurement_areas", [])]
    region = venue.get("slope", {}).get("region")
    if region:
        areas.append(("whole alley", region))
    shapes = {i: body_area(r, json.loads(v)) for i, r, v in db.execute("select id, radius_m, vertices from shape")}
    person_area = {i: shapes[s] for i, s in db.execute("select id, shape from person")}
    end_s = db.execute("select max(time_s) from frame_time").fetchone()[0]
    rows = []
    for clock, t, low, high in times:
        t *= scale
        frames = [f for (f,) in db.execute("select frame from frame_time where time_s >= ? and time_s <= ? order by frame",
                                          (t - WINDOW_S / 2, t + WINDOW_S / 2))]
        if end_s is None or end_s < t + WINDOW_S / 2 or not frames:
            rows.append({"clock": clock, "recorded": (low, high), "ended": end_s, "areas": None,
                         "reached": end_s is not None and end_s >= t + WINDOW_S / 2})
            continue
        counts = {name: [] for name, _ in areas}
        covered = {name: [] for name, _ in areas}
        for f in frames:
            people = db.execute("select id, pos_x, pos_y from trajectory_data where frame = ?", (f,)).fetchall()
            for name, ring in areas:
                ids = [i for i, x, y in people if inside(ring, x, y)]
                counts[name].append(len(ids))
                covered[name].append(sum(person_area.get(i, REFERENCE_BODY_M2) for i in ids))
        result = {}
        for name, ring in areas:
            a = ring_area(ring)
            result[name] = (statistics.fmean(counts[name]) / a, statistics.fmean(covered[name]) / REFERENCE_BODY_M2 / a, a)
        rows.append({"clock": clock, "recorded": (low, high), "ended": end_s, "areas": result, "frames": len(frames)})
    return run.get("seed", "?"), rows, [name for name, _ in areas]


MD_HEAD = "| run (seed) | time | recorded /m² (NFS) |"
CSV_HEAD = ("run", "seed", "clock", "area", "area_m2")


def venue_areas(path):
    """The areas read_run measures in a run file (ScriptError if the run is not of a venue with any)."""
    guard.check_run_file(path, ("shape", "person", "frame_time", "trajectory_data"))
    db = guard.open_readonly(path)
    try:
        row = db.execute("select value from run where key = 'venue'").fetchone()
    finally:
        db.close()
    expected = "a run of the Itaewon alley (venues/itaewon/alley.json: measurement areas and the slope's region)"
    if row is None:
        raise guard.ScriptError(f"{path}: its run table holds no venue; expected {expected}")
    try:
        venue = json.loads(row[0])
    except ValueError:
        raise guard.ScriptError(f"{path}: its venue is not JSON; expected {expected}") from None
    names = [a.get("id") for a in venue.get("measurement_areas", [])] if isinstance(venue, dict) else []
    if isinstance(venue, dict) and venue.get("slope", {}).get("region"):
        names.append("whole alley")
    if not names:
        raise guard.ScriptError(f"{path}: its venue has no measurement areas and no slope region; expected {expected}")
    return names


def main():
    p = guard.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", nargs="+", type=guard.run_file, help="run files of the evening")
    p.add_argument("-o", "--output", required=True, help="Markdown table")
    p.add_argument("--csv", help="one row per run, time and area")
    p.add_argument("--scale", type=guard.float_between(0.0, low_open=True, what="run time per evening time, "
                                                                              "such as 0.1 for the shortened evening"),
                   default=1.0, help="run time per evening time (the shortened evening's clock: 0.1)")
    p.add_argument("--also", default="", help="more evening times, comma-separated HH:MM (no recorded density)")
    guard.add_force(p)
    args = p.parse_args()
    guard.refuse_repeated(args.runs, "run file")
    also = [evening_time(t.strip()) for t in args.also.split(",") if t.strip()]
    recorded_s = {r[1] for r in RECORDED}
    times = sorted([(c, t, None, None) for c, t in also if t not in recorded_s] + RECORDED, key=lambda r: r[1])
    first = None
    for path in args.runs:
        names = venue_areas(path)
        if first is None:
            first = (path, names)
        elif names != first[1]:
            raise guard.ScriptError(f"{path}: its venue's areas ({', '.join(names)}) are not those of {first[0]} "
                                    f"({', '.join(first[1])}); expected runs of one venue")
    guard.check_outputs([
        guard.Output("-o", args.output, "a Markdown table of itaewon-densities.py", guard.starts_with(MD_HEAD)),
        guard.Output("--csv", args.csv, "a CSV table of itaewon-densities.py", guard.csv_starting(*CSV_HEAD)),
    ], [("a run file", r) for r in args.runs], args.force)
    table = []
    names = None
    for path in args.runs:
        seed, rows, area_names = read_run(path, args.scale, times)
        names = names or area_names
        for r in rows:
            table.append((path, seed, r))
    head = "| run (seed) | time | recorded /m² (NFS) | " + " | ".join(f"{n}: model (real-size)" for n in names) + " |"
    lines = [head, "|" + " --- |" * (3 + len(names))]
    csv_rows = []
    for path, seed, r in table:
        low, high = r["recorded"]
        recorded = "–" if low is None else f"{low}–{high}"
        stem = path.rsplit("/", 1)[-1].removesuffix(".sqlite")
        if r["areas"] is None:
            ended = ("no frames" if r["ended"] is None else "no frames within the window" if r["reached"]
                     else f"not reached (the last frame at {r['ended']:.1f} s)")
            lines.append(f"| {stem} ({seed}) | {r['clock']} | {recorded} | " + " | ".join(ended for _ in names) + " |")
            continue
        cells = []
        for n in names:
            model, real, area = r["areas"][n]
            cells.append(f"{model:.1f} ({real:.1f})")
            csv_rows.append([stem, seed, r["clock"], n, f"{area:.2f}", f"{model:.3f}", f"{real:.3f}",
                             "" if low is None else low, "" if high is None else high, r["frames"]])
        lines.append(f"| {stem} ({seed}) | {r['clock']} | {recorded} | " + " | ".join(cells) + " |")
    note = (f"\nMeans over the {WINDOW_S:.0f} s around each time; persons/m² of the model's bodies and, in brackets, "
            f"the same floor covered by real-size people ({REFERENCE_BODY_M2} m² each). 'whole alley' is the slope's region "
            "(the alley from the sidewalk to the food street). Recorded: the National Forensic Service's densities in the "
            "alley (docs/itaewon.md).\n")
    guard.write_whole(args.output, "\n".join(lines) + "\n" + note)
    if args.csv:
        with guard.whole_file(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["run", "seed", "clock", "area", "area_m2", "model_per_m2", "real_size_per_m2", "recorded_low_per_m2",
                        "recorded_high_per_m2", "frames"])
            w.writerows(csv_rows)


if __name__ == "__main__":
    guard.run_main(main)
