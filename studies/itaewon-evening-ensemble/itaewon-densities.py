#!/usr/bin/env python3
"""The Itaewon runs' densities in the alley against the published ones (issue 43).

For each run file (the evening, t = 0 at 21:45), the people in each of the
venue's measurement areas and in the whole alley (the slope's region) over a
10-s window around 22:15, 22:20 and 22:25 (the times of the National Forensic
Service's densities, docs/itaewon.md "The recorded times"), as persons/m² of
the model's bodies and as real-size people (the same floor covered by ANSUR II
median bodies, 0.0868 m², the runs' validity statements' measure).

    studies/itaewon-evening-ensemble/itaewon-densities.py RUN.sqlite... -o DENSITIES.md [--csv DENSITIES.csv]

A run that ended before a time (or, still running, has not reached it) gives no
figure for it (said in the table).
"""
import argparse
import csv
import json
import math
import sqlite3
import statistics
import sys

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


def read_run(path, scale):
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
    for clock, t, low, high in RECORDED:
        t *= scale
        frames = [f for (f,) in db.execute("select frame from frame_time where time_s >= ? and time_s <= ? order by frame",
                                          (t - WINDOW_S / 2, t + WINDOW_S / 2))]
        if end_s is None or end_s < t + WINDOW_S / 2:
            rows.append({"clock": clock, "recorded": (low, high), "ended": end_s, "areas": None})
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


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", nargs="+")
    p.add_argument("-o", "--output", required=True, help="Markdown table")
    p.add_argument("--csv", help="one row per run, time and area")
    p.add_argument("--scale", type=float, default=1.0,
                   help="run time per evening time (the shortened evening's clock: 0.1)")
    args = p.parse_args()
    for out in [args.output, args.csv]:
        if out and any(out == r for r in args.runs):
            sys.exit(f"itaewon-densities: {out} is an input; refusing to overwrite it")
    table = []
    names = None
    for path in args.runs:
        seed, rows, area_names = read_run(path, args.scale)
        names = names or area_names
        for r in rows:
            table.append((path, seed, r))
    head = "| run (seed) | time | recorded /m² (NFS) | " + " | ".join(f"{n}: model (real-size)" for n in names) + " |"
    lines = [head, "|" + " --- |" * (3 + len(names))]
    csv_rows = []
    for path, seed, r in table:
        low, high = r["recorded"]
        stem = path.rsplit("/", 1)[-1].removesuffix(".sqlite")
        if r["areas"] is None:
            ended = "no frames" if r["ended"] is None else f"not reached (the last frame at {r['ended']:.1f} s)"
            lines.append(f"| {stem} ({seed}) | {r['clock']} | {low}–{high} | " + " | ".join(ended for _ in names) + " |")
            continue
        cells = []
        for n in names:
            model, real, area = r["areas"][n]
            cells.append(f"{model:.1f} ({real:.1f})")
            csv_rows.append([stem, seed, r["clock"], n, f"{area:.2f}", f"{model:.3f}", f"{real:.3f}", low, high, r["frames"]])
        lines.append(f"| {stem} ({seed}) | {r['clock']} | {low}–{high} | " + " | ".join(cells) + " |")
    note = (f"\nMeans over the {WINDOW_S:.0f} s around each time; persons/m² of the model's bodies and, in brackets, "
            f"the same floor covered by real-size people ({REFERENCE_BODY_M2} m² each). 'whole alley' is the slope's region "
            "(the alley from the sidewalk to the food street). Recorded: the National Forensic Service's densities in the "
            "alley (docs/itaewon.md).\n")
    with open(args.output, "w") as f:
        f.write("\n".join(lines) + "\n" + note)
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["run", "seed", "clock", "area", "area_m2", "model_per_m2", "real_size_per_m2", "recorded_low_per_m2",
                        "recorded_high_per_m2", "frames"])
            w.writerows(csv_rows)


if __name__ == "__main__":
    main()
