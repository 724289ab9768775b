#!/usr/bin/env python3
"""A periodic run's export, measured by a tool that knows nothing of periodic boxes.

`crowdrecon export` cuts each trajectory of a periodic run where it crosses a
seam of the box (runfile/trajectory_export.hpp). This test reads the exported
file as PedPy would (trajectory_data, metadata fps, geometry) and computes,
naively, per-id speeds by finite differences of consecutive frames and the
crossings of the measurement line by consecutive positions of an id. It checks
that they are ours:

  * speeds: equal, within 1e-9 m/s, to the minimum-image differences of the
    run's own positions (the same stored numbers: only rounding in the
    division may differ), and none above 3 m/s;
  * crossings per direction: exactly `crowdrecon analyze --json`'s
    crossings_forward and crossings_backward over the whole run, through the
    line it used (setup.line, setup.forward);
  * every row of the run is in the export, every step of the run is either a
    step within one id or one of the splits, and each split is a step across
    a seam; ids map to people through crowdrecon_track.

The same naive computation on the run file itself must show the seam jumps
(speeds far above 3 m/s and different crossing counts), so that the test
would fail on an export that did not cut them.

A run that is not periodic ("plain") is exported with its ids and no splits;
the same checks hold, and the run file itself measures the same.

usage: test_export_periodic.py CROWDRECON RUN.sqlite periodic|plain
Python's standard library only.
"""
import json
import math
import os
import sqlite3
import subprocess
import sys
import tempfile

SPEED_TOLERANCE_M_PER_S = 1e-9
MAX_SPEED_M_PER_S = 3.0


def fail(message):
    print("FAIL:", message)
    sys.exit(1)


def run_command(args):
    result = subprocess.run(args, capture_output=True, text=True)
    print("$", " ".join(args))
    print(result.stdout + result.stderr, end="")
    if result.returncode != 0:
        fail(f"exit status {result.returncode}")


def trajectories(path):
    """{id: [(frame, x, y), ...] in frame order} and fps, as PedPy reads them."""
    con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    fps = float(dict(con.execute("SELECT key, value FROM metadata"))["fps"])
    tracks = {}
    for frame, i, x, y in con.execute("SELECT frame, id, pos_x AS x, pos_y AS y FROM trajectory_data"):
        tracks.setdefault(i, []).append((frame, x, y))
    for rows in tracks.values():
        rows.sort()
    con.close()
    return tracks, fps


def naive_speeds(tracks, fps):
    """{(id, frame): speed} of each step from the previous row of the id, as a tool unaware of periodicity."""
    speeds = {}
    for i, rows in tracks.items():
        for (f0, x0, y0), (f1, x1, y1) in zip(rows, rows[1:]):
            speeds[(i, f1)] = math.hypot(x1 - x0, y1 - y0) / ((f1 - f0) / fps)
    return speeds


def naive_crossings(tracks, line, forward):
    """Crossings (forward, backward) of the segment `line` by consecutive positions of each id.

    The rule of docs/analysis.md: back side to front side is forward, a step
    ending on the line counts, one starting on it does not, and the crossing
    point must lie on the segment."""
    (ax, ay), (bx, by) = line
    along = (bx - ax, by - ay)
    along2 = along[0] ** 2 + along[1] ** 2
    normal = (-along[1], along[0])
    if normal[0] * forward[0] + normal[1] * forward[1] < 0:
        normal = (-normal[0], -normal[1])
    fwd = bwd = 0
    for rows in tracks.values():
        for (_, x0, y0), (_, x1, y1) in zip(rows, rows[1:]):
            dx, dy = x1 - x0, y1 - y0
            s0 = (x0 - ax) * normal[0] + (y0 - ay) * normal[1]
            s1 = s0 + dx * normal[0] + dy * normal[1]
            if s0 < 0 <= s1:
                direction = 1
            elif s1 < 0 <= s0:
                direction = -1
            else:
                continue
            t = s0 / (s0 - s1)
            u = ((x0 + dx * t - ax) * along[0] + (y0 + dy * t - ay) * along[1]) / along2
            if 0 <= u <= 1:
                if direction > 0:
                    fwd += 1
                else:
                    bwd += 1
    return fwd, bwd


def minimum_image(d, lo, hi, periodic):
    if not periodic:
        return d
    length = hi - lo
    return d - length * round(d / length)


def main(exe, run_path, mode):
    if mode not in ("periodic", "plain"):
        fail(f"mode {mode}, expected periodic or plain")
    with tempfile.TemporaryDirectory(prefix="export-periodic-") as work:
        check(exe, run_path, mode, work)


def check(exe, run_path, mode, work):
    out = os.path.join(work, "export.sqlite")
    analysis = os.path.join(work, "analysis.json")
    run_command([exe, "export", run_path, "-o", out])
    run_command([exe, "analyze", run_path, "--json", analysis])
    with open(analysis) as f:
        summary = json.load(f)
    setup = summary["setup"]

    run = sqlite3.connect(f"file:{run_path}?mode=ro", uri=True)
    run_values = dict(run.execute("SELECT key, value FROM run"))
    box = json.loads(run_values.get("periodic_box", "null") or "null")
    periodic = bool(box and (box["x"] or box["y"]))
    if periodic != (mode == "periodic"):
        fail(f"{run_path}: run value periodic_box {box}; expected a {mode} run")
    if not periodic:
        box = {"x": False, "y": False, "min_m": [0, 0], "max_m": [0, 0]}
    run_rows = run.execute("SELECT COUNT(*) FROM trajectory_data").fetchone()[0]
    run_ori = {(f, i): (ox, oy) for f, i, ox, oy in run.execute("SELECT frame, id, ori_x, ori_y FROM trajectory_data")}
    run_wkt = [r[0] for r in run.execute("SELECT wkt FROM geometry")]
    run_frames = [r[0] for r in run.execute("SELECT frame FROM frame_time ORDER BY frame")]
    run_people = {i: (g, t) for i, g, t in run.execute("SELECT id, grp, target FROM person")}
    run.close()

    exp = sqlite3.connect(f"file:{out}?mode=ro", uri=True)
    meta = dict(exp.execute("SELECT key, value FROM metadata"))
    tables = {r[0] for r in exp.execute("SELECT name FROM sqlite_master WHERE type='table'")}
    if tables != {"trajectory_data", "metadata", "geometry", "frame_data", "crowdrecon_track"}:
        fail(f"export tables {sorted(tables)}")
    if meta["version"] != "2":
        fail(f"metadata version {meta['version']}, expected 2 (PedPy rejects the walkable area of version 3)")
    if meta["crowdrecon_source"] != os.path.basename(run_path):
        fail(f"crowdrecon_source {meta['crowdrecon_source']}")
    if periodic and json.loads(meta["crowdrecon_periodic"]) != box:
        fail(f"crowdrecon_periodic {meta['crowdrecon_periodic']} is not the run's box {box}")
    if not periodic and "crowdrecon_periodic" in meta:
        fail(f"crowdrecon_periodic {meta['crowdrecon_periodic']} in the export of a run that is not periodic")
    if [r[0] for r in exp.execute("SELECT wkt FROM geometry")] != run_wkt:
        fail("the export's walkable area is not the run's")
    hashes = {r[0] for r in exp.execute("SELECT hash FROM geometry")}
    frame_data = exp.execute("SELECT frame, geometry_hash FROM frame_data ORDER BY frame").fetchall()
    if [f for f, _ in frame_data] != run_frames or {h for _, h in frame_data} != hashes:
        fail("frame_data does not list every frame of the run with the geometry's hash")
    exp_rows = exp.execute("SELECT COUNT(*) FROM trajectory_data").fetchone()[0]
    if exp_rows != run_rows:
        fail(f"{exp_rows} rows in the export, {run_rows} in the run")
    track = {i: (p, part, f0, f1) for i, p, part, f0, f1 in exp.execute(
        "SELECT id, person, part, first_frame, last_frame FROM crowdrecon_track")}
    # Each piece carries its person's group and target, as the run's person table has them.
    for i, p, g, t in exp.execute("SELECT id, person, grp, target FROM crowdrecon_track"):
        if run_people.get(p) != (g, t):
            fail(f"id {i}: group and target {(g, t)}, the run's person {p} has {run_people.get(p)}")
    exp_ori = {}
    for f, i, ox, oy in exp.execute("SELECT frame, id, ori_x, ori_y FROM trajectory_data"):
        exp_ori[(f, track[i][0] if i in track else -1)] = (ox, oy)
    if exp_ori != run_ori:
        fail("orientations (ori_x, ori_y) differ from the run's")
    exp.close()

    exp_tracks, fps = trajectories(out)
    run_tracks, run_fps = trajectories(run_path)
    if fps != run_fps:
        fail(f"fps {fps} in the export, {run_fps} in the run")

    # ids and crowdrecon_track: each id one piece of one person, pieces in order.
    if set(track) != set(exp_tracks):
        fail("crowdrecon_track does not list exactly the ids of trajectory_data")
    pieces = {}
    for i, (person, part, f0, f1) in track.items():
        rows = exp_tracks[i]
        if (rows[0][0], rows[-1][0]) != (f0, f1):
            fail(f"id {i}: frames {rows[0][0]}..{rows[-1][0]}, crowdrecon_track says {f0}..{f1}")
        if part == 0 and i != person:
            fail(f"id {i}: the first piece of person {person} does not keep the person's id")
        pieces.setdefault(person, []).append((part, f0, f1))
    for person, parts in pieces.items():
        parts.sort()
        if [p for p, _, _ in parts] != list(range(len(parts))):
            fail(f"person {person}: parts {parts}")
        if any(parts[k][2] >= parts[k + 1][1] for k in range(len(parts) - 1)):
            fail(f"person {person}: pieces overlap or are out of order: {parts}")
    splits = len(track) - len(pieces)
    if int(meta["crowdrecon_split_at_seams"]) != splits:
        fail(f"crowdrecon_split_at_seams {meta['crowdrecon_split_at_seams']}, the tracks show {splits}")

    # (a) Speeds: each step within an id is the run's minimum-image step.
    axes = [(box["x"], box["min_m"][0], box["max_m"][0]), (box["y"], box["min_m"][1], box["max_m"][1])]
    ours = {}  # (person, frame): speed from the run's positions, minimum image
    seam_steps = 0
    for person, rows in run_tracks.items():
        for (f0, x0, y0), (f1, x1, y1) in zip(rows, rows[1:]):
            raw = (x1 - x0, y1 - y0)
            image = tuple(minimum_image(d, lo, hi, p) for d, (p, lo, hi) in zip(raw, axes))
            if image != raw:
                seam_steps += 1
            ours[(person, f1)] = math.hypot(*image) / ((f1 - f0) / fps)
    exported = naive_speeds(exp_tracks, fps)
    if len(exported) + splits != len(ours):
        fail(f"{len(exported)} steps within ids + {splits} splits, expected the run's {len(ours)} steps")
    if splits != seam_steps:
        fail(f"{splits} splits, but the run has {seam_steps} steps across a seam")
    worst = 0.0
    for (i, frame), v in exported.items():
        worst = max(worst, abs(v - ours[(track[i][0], frame)]))
    if worst > SPEED_TOLERANCE_M_PER_S:
        fail(f"exported speeds differ from the run's minimum-image speeds by up to {worst} m/s")
    max_after = max(exported.values())
    if max_after > MAX_SPEED_M_PER_S:
        fail(f"naive speed {max_after:.3f} m/s in the export, expected at most {MAX_SPEED_M_PER_S}")
    before = naive_speeds(run_tracks, fps)
    max_before = max(before.values())
    jumps = sum(1 for v in before.values() if v > MAX_SPEED_M_PER_S)
    if not periodic and (splits != 0 or any(i != person for i, (person, _, _, _) in track.items())):
        fail("the export of a run that is not periodic must keep every id, with no splits")
    if periodic and (max_before <= MAX_SPEED_M_PER_S or jumps != seam_steps):
        fail(f"the run file itself should show its {seam_steps} seam steps as jumps to a naive tool; "
             f"found {jumps}, max speed {max_before:.3f} m/s")

    # (b) Crossings of the analysis's measurement line.
    line = setup["line"]
    fwd, bwd = naive_crossings(exp_tracks, line, setup["forward"])
    want = (int(summary["summary"]["crossings_forward"]), int(summary["summary"]["crossings_backward"]))
    if (fwd, bwd) != want:
        fail(f"naive crossings of the export {fwd} forward / {bwd} backward, analyze says {want[0]} / {want[1]}")
    raw_fwd, raw_bwd = naive_crossings(run_tracks, line, setup["forward"])
    if periodic and fwd + bwd == 0:
        fail("no crossing of the measurement line: the comparison says nothing")
    if periodic and (raw_fwd, raw_bwd) == want:
        fail("naive crossings of the run file itself match analyze: the seam jumps should have added some")
    if not periodic and (raw_fwd, raw_bwd) != want:
        fail(f"naive crossings of a run that is not periodic {raw_fwd} / {raw_bwd}, analyze {want[0]} / {want[1]}")

    print(f"export OK ({mode}): {exp_rows} rows (run: {run_rows}), {len(pieces)} people, {len(track)} ids, {splits} splits "
          f"at seams; naive max speed {max_before:.2f} m/s in the run ({jumps} jumps), {max_after:.3f} m/s in the "
          f"export (speeds within {worst:.1e} m/s of ours); crossings of {setup['line_source']} {line}: analyze "
          f"{want[0]} / {want[1]}, export {fwd} / {bwd}, run file naively {raw_fwd} / {raw_bwd}")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        print(__doc__)
        sys.exit(2)
    main(sys.argv[1], sys.argv[2], sys.argv[3])
