#!/usr/bin/env python3
"""studies/itaewon-evening-ensemble/itaewon-densities.py on a run file whose answer is known.

A run file with the tables the script reads (the Itaewon venue in `run`, the
bodies' shapes, the frames, the positions): people placed at the centres of
the alley's measurement areas, their numbers changing from frame to frame
around 22:15 (t = 1800 s), the run's last frame at 22:15:05. The script must
give the mean count over the 10 s around 22:15 per area's m² (and as
real-size people, scaled by the bodies' area over 0.0868 m²), say that 22:20
and 22:25 are not reached, and refuse to write over its input.

    test_itaewon_densities.py SCRIPT VENUE.json SCRATCH_DIR
"""
import csv
import json
import math
import os
import sqlite3
import subprocess
import sys

RADIUS = 0.25  # one-vertex bodies: discs of this radius
REFERENCE_BODY_M2 = 0.0868


def fail(message):
    print("FAIL:", message)
    sys.exit(1)


def polygon_area(ring):
    return abs(sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(ring, ring[1:] + ring[:1]))) / 2.0


def main(script, venue_path, scratch):
    os.makedirs(scratch, exist_ok=True)
    venue = json.load(open(venue_path))
    areas = {a["id"]: a["polygon"] for a in venue["measurement_areas"]}
    region = venue["slope"]["region"]
    # How many stand at each area's centre in each frame: the frames at
    # 1795.0, 1795.5, ... 1805.0 s; a ramp so that the mean is not any one frame's.
    frames = [1795.0 + 0.5 * k for k in range(21)]
    per_frame = {"alley_foot": lambda k: 2 + k % 3, "alley_middle": lambda k: 10 + k,
                 "alley_top": lambda k: 30, "junction": lambda k: 5}
    path = os.path.join(scratch, "run.sqlite")
    if os.path.exists(path):
        os.remove(path)
    db = sqlite3.connect(path)
    db.executescript("""
        create table run(key text primary key, value text);
        create table shape(id integer primary key, radius_m real, vertices text);
        create table person(id integer primary key, shape integer);
        create table frame_time(frame integer primary key, time_s real);
        create table trajectory_data(frame integer, id integer, pos_x real, pos_y real);
    """)
    db.executemany("insert into run values (?, ?)", [("venue", json.dumps(venue)), ("seed", "7")])
    db.execute("insert into shape values (1, ?, '[[0.0, 0.0]]')", (RADIUS,))
    people = 0
    for f, t in enumerate(frames):
        db.execute("insert into frame_time values (?, ?)", (f, t))
        pid = 0
        for name, count in per_frame.items():
            ring = areas[name]
            cx = sum(p[0] for p in ring) / len(ring)
            cy = sum(p[1] for p in ring) / len(ring)
            for i in range(count(f)):
                pid += 1
                db.execute("insert into trajectory_data values (?, ?, ?, ?)", (f, pid, cx + 0.001 * i, cy))
        people = max(people, pid)
    db.executemany("insert into person values (?, 1)", [(i,) for i in range(1, people + 1)])
    db.commit()
    db.close()

    out_md = os.path.join(scratch, "d.md")
    out_csv = os.path.join(scratch, "d.csv")
    r = subprocess.run([sys.executable, script, path, "-o", out_md, "--csv", out_csv, "--also", "22:00,22:15"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"the script failed: {r.stderr}")
    # --also: 22:00 has no frames near it here (the run's frames start at 1795 s) and no recorded range; 22:15,
    # a recorded time given again, is measured once.
    md = open(out_md).read()
    lines_2200 = [l for l in md.splitlines() if "| 22:00 |" in l]
    if len(lines_2200) != 1 or "| – | no frames within the window |" not in lines_2200[0]:
        fail(f"--also 22:00: expected one row without a recorded range:\n{md}")
    if md.count("| 22:15 |") != 1:
        fail(f"--also 22:15 (a recorded time): expected it once:\n{md}")
    for bad, said in [("22:61", "is not a time HH:MM"), ("21:30", "is outside the evening"), ("x", "is not a time HH:MM")]:
        rb = subprocess.run([sys.executable, script, path, "-o", out_md, "--also", bad, "--force"], capture_output=True,
                            text=True)
        if rb.returncode == 0 or said not in rb.stderr:
            fail(f"--also {bad}: expected a refusal saying {said!r}: {rb.returncode} {rb.stderr}")
    rows = {row["area"]: row for row in csv.DictReader(open(out_csv)) if row["clock"] == "22:15"}
    body = math.pi * RADIUS ** 2
    expected = {name: sum(count(k) for k in range(len(frames))) / len(frames) for name, count in per_frame.items()}
    # The whole alley (the slope's region) holds the foot, the middle and the top, not the junction.
    expected["whole alley"] = expected["alley_foot"] + expected["alley_middle"] + expected["alley_top"]
    rings = dict(areas, **{"whole alley": region})
    for name, mean in expected.items():
        if name not in rows:
            fail(f"no row for {name} at 22:15: {sorted(rows)}")
        area = polygon_area(rings[name])
        model = float(rows[name]["model_per_m2"])
        real = float(rows[name]["real_size_per_m2"])
        if abs(model - mean / area) > 1e-3 or abs(real - mean * body / REFERENCE_BODY_M2 / area) > 1e-3:
            fail(f"{name}: {model}, {real} /m², expected {mean / area:.3f}, {mean * body / REFERENCE_BODY_M2 / area:.3f}")
        if int(rows[name]["frames"]) != len(frames):
            fail(f"{name}: {rows[name]['frames']} frames, expected {len(frames)}")
        print(f"{name}: {model:.3f} /m² ({real:.3f} real-size), expected {mean / area:.3f}")
    text = open(out_md).read()
    for clock in ["22:20", "22:25"]:
        if f"| {clock} | " not in text or "not reached (the last frame at 1805.0 s)" not in text:
            fail(f"{clock}: not said to be unreached:\n{text}")
    r = subprocess.run([sys.executable, script, path, "-o", path], capture_output=True, text=True)
    if r.returncode == 0 or "is an input; refusing to overwrite it" not in r.stderr:
        fail(f"writing over the input was not refused: {r.returncode} {r.stderr}")
    print("ok")


if __name__ == "__main__":
    main(*sys.argv[1:])
