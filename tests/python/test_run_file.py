#!/usr/bin/env python3
"""Checks a crowdrecon run file with Python's sqlite3 module, as PedPy would read it.

PedPy's load_trajectory_from_jupedsim_sqlite reads
  SELECT frame, id, pos_x AS x, pos_y AS y FROM trajectory_data
and the frame rate from metadata('fps'); load_walkable_area_from_jupedsim_sqlite
reads metadata('version') and, for version 2, every geometry(wkt). This test
runs exactly those queries and checks the values against the run's own tables.

usage: test_run_file.py RUN.sqlite
"""
import math
import re
import sqlite3
import sys


def fail(message):
    print("FAIL:", message)
    sys.exit(1)


def main(path):
    con = sqlite3.connect(path)
    cur = con.cursor()
    tables = {r[0] for r in cur.execute("SELECT name FROM sqlite_master WHERE type='table'")}
    for t in ("trajectory_data", "metadata", "geometry", "frame_data", "run", "person", "person_state", "contact",
              "frame_time", "event", "shape", "wall"):
        if t not in tables:
            fail(f"missing table {t}")
    cols = [r[1] for r in cur.execute("PRAGMA table_info(trajectory_data)")]
    if cols != ["frame", "id", "pos_x", "pos_y", "ori_x", "ori_y"]:
        fail(f"trajectory_data columns {cols}")

    meta = dict(cur.execute("SELECT key, value FROM metadata"))
    if int(meta["version"]) != 2:
        fail(f"version {meta['version']}")
    fps = float(meta["fps"])
    run = dict(cur.execute("SELECT key, value FROM run"))
    if abs(fps - float(run["output_fps"])) > 1e-12:
        fail("fps differs from the run's output_fps")
    if run["status"] != "complete":
        fail(f"status {run['status']}")

    # PedPy's trajectory query.
    rows = cur.execute("SELECT frame, id, pos_x AS x, pos_y AS y FROM trajectory_data").fetchall()
    if not rows:
        fail("no trajectory rows")
    people = int(run["people"])
    frames = sorted({r[0] for r in rows})
    if frames != list(range(len(frames))):
        fail("frames are not 0..N-1")
    per_frame = {}
    for f, i, x, y in rows:
        per_frame.setdefault(f, set()).add(i)
    if any(ids != set(range(1, people + 1)) for ids in per_frame.values()):
        fail("each frame must hold ids 1..people")
    xs = [r[2] for r in rows]
    ys = [r[3] for r in rows]
    if abs(min(xs) - float(meta["xmin"])) > 1e-9 or abs(max(ys) - float(meta["ymax"])) > 1e-9:
        fail("metadata bounds do not match the trajectories")

    # Orientations are unit vectors consistent with person_state.angle_rad.
    for f, i, ox, oy, a in cur.execute(
            "SELECT t.frame, t.id, t.ori_x, t.ori_y, s.angle_rad FROM trajectory_data t "
            "JOIN person_state s ON s.frame = t.frame AND s.id = t.id"):
        if abs(math.hypot(ox, oy) - 1) > 1e-12 or abs(ox - math.cos(a)) > 1e-12:
            fail(f"orientation of {i} in frame {f}")

    # Frame times are exactly frame / fps.
    for f, t in cur.execute("SELECT frame, time_s FROM frame_time"):
        if abs(t - f / fps) > 1e-9:
            fail(f"frame {f} at t = {t}, expected {f / fps}")
    if {r[0] for r in cur.execute("SELECT frame FROM frame_data")} != set(frames):
        fail("frame_data does not list every frame")

    # PedPy's walkable-area query (version 2: union of geometry rows).
    wkts = [r[0] for r in cur.execute("SELECT wkt FROM geometry")]
    if len(wkts) != 1 or not re.match(r"^(MULTI)?POLYGON \(", wkts[0]):
        fail(f"geometry {wkts}")
    hashes = {r[0] for r in cur.execute("SELECT hash FROM geometry")}
    if {r[0] for r in cur.execute("SELECT geometry_hash FROM frame_data")} != hashes:
        fail("frame_data.geometry_hash does not refer to the geometry")

    # Contacts: unit normals, positive overlaps, valid ids, and the load column
    # equals the sum of the contact force magnitudes on each person.
    last = frames[-1]
    contacts = cur.execute("SELECT a, b, wall, normal_x, normal_y, overlap_m, normal_force_n, tangential_force_n "
                           "FROM contact WHERE frame = ?", (last,)).fetchall()
    if not contacts:
        fail("no contacts in the last frame of a dense run")
    load = {}
    for a, b, wall, nx, ny, ov, fn, ft in contacts:
        if abs(math.hypot(nx, ny) - 1) > 1e-9 or ov <= 0 or not (1 <= a <= people):
            fail("malformed contact row")
        f = math.hypot(fn, ft)
        load[a] = load.get(a, 0) + f
        if not wall:
            load[b] = load.get(b, 0) + f
    for i, l in cur.execute("SELECT id, load_n FROM person_state WHERE frame = ?", (last,)):
        if abs(l - load.get(i, 0.0)) > 1e-6 * max(1.0, l):
            fail(f"load of person {i}: {l} vs {load.get(i, 0.0)}")

    shapes = cur.execute("SELECT COUNT(*) FROM shape").fetchone()[0]
    persons = cur.execute("SELECT COUNT(*), MIN(mass_kg), MAX(mass_kg) FROM person").fetchone()
    if persons[0] != people or shapes < 1 or not (40 <= persons[1] <= persons[2] <= 70):
        fail(f"person table {persons}")
    print(f"run file OK: {people} people, {len(frames)} frames at {fps} fps, {len(contacts)} contacts in the last frame")


if __name__ == "__main__":
    main(sys.argv[1])
