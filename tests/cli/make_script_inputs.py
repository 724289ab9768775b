#!/usr/bin/env python3
"""Small stand-ins for what the Python scripts read, made with sqlite3 alone
(no simulation): for tests/cli/script_outputs.sh.

    make_script_inputs.py sweep DIR VENUE.json [--runs N] [--fall]
        DIR/results.sqlite (the sweep and runs tables of `crowdrecon sweep`),
        DIR/results.csv and DIR/runs/RUN.sqlite: N complete runs (two
        variants, seeds 1 ...) of VENUE, each a run file with the tables the
        scripts read (run, frame_time, census, trajectory_data, person,
        person_state, person_load, shape, event); --fall: their scenario has a
        timeline fall event (the recorded-falls sweeps).
    make_script_inputs.py run FILE VENUE.json
        one such run file.
    make_script_inputs.py nights DIR VENUE.json
        DIR/paths.csv (night-path.py's columns) and DIR/summaries/RUN.json
        (ensemble run summaries) of seven whole nights at inflow scales 1-1.5,
        five of which jam (one of them stopped before its end, without a
        summary): for studies/night-validated-calibration/night-hazard.py.
        DIR/summaries-push/: the same nights, three of them with the entering
        group's back force raised (4.8) at the start; DIR/summaries-late/:
        one raised at 100 s (which night-hazard.py refuses).

The people stand and walk at fixed, seeded places inside the venue's first
measurement area (or at the origin), so that the numbers are not all zero.
"""
import csv
import json
import os
import random
import sqlite3
import sys

COLUMNS = ["run_index", "run_id", "variant", "seed", "population.density_per_m2", "population.counter_flow_fraction",
           "status", "regime", "duration_s", "mean_speed_m_per_s", "stopped_time_fraction", "max_load_n",
           "people_ever_above_load", "longest_above_load_s", "peak_density_per_m2", "wall_s"]


def centre(venue):
    areas = venue.get("measurement_areas", [])
    if not areas:
        return 0.0, 0.0
    ring = areas[0]["polygon"]
    return sum(p[0] for p in ring) / len(ring), sum(p[1] for p in ring) / len(ring)


def make_run(path, venue, seed, fall=False):
    if os.path.exists(path):
        os.remove(path)
    rng = random.Random(seed)
    cx, cy = centre(venue)
    scenario = {"format": "crowdrecon-scenario", "version": 1, "name": f"stand-in, seed {seed}",
                "population": {"seed": seed}, "model": {},
                "timeline": {"events": [{"time_s": 1.0, "fall": {"at": [cx, cy], "count": 2}}] if fall else []}}
    db = sqlite3.connect(path)
    db.executescript("""
        create table run(key text primary key, value text);
        create table frame_time(frame integer primary key, time_s real);
        create table census(frame integer primary key, time_s real, walking integer, fallen integer);
        create table trajectory_data(frame integer, id integer, pos_x real, pos_y real);
        create table person(id integer primary key, grp integer, shape integer, target text);
        create table shape(id integer primary key, radius_m real, vertices text);
        create table person_state(frame integer, id integer, vel_x real, vel_y real, state integer, load_n real);
        create table person_load(frame integer, id integer, chest_n real);
        create table event(frame integer, time_s real, kind text, person integer, detail text);
        create table contact(frame integer, a integer, b integer, wall integer, normal_force_n real);
    """)
    db.executemany("insert into run values (?, ?)", [
        ("format", "crowdrecon-run"), ("status", "complete"), ("seed", str(seed)), ("venue", json.dumps(venue)),
        ("scenario", json.dumps(scenario)), ("wall_s", "1.0")])
    db.execute("insert into shape values (1, 0.2, '[[0.0, 0.0]]')")
    people = 12
    for pid in range(1, people + 1):
        db.execute("insert into person values (?, ?, 1, ?)", (pid, pid % 2, "to_exit" if pid % 2 == 0 else "to_court"))
    for frame in range(40):
        t = 0.1 * frame
        db.execute("insert into frame_time values (?, ?)", (frame, t))
        db.execute("insert into census values (?, ?, ?, ?)", (frame, t, people, 0))
        for pid in range(1, people + 1):
            x = cx + 0.3 * (pid % 4) + 0.01 * frame * (1 if pid % 2 == 0 else -1)
            y = cy + 0.3 * (pid // 4) + rng.uniform(-0.01, 0.01)
            db.execute("insert into trajectory_data values (?, ?, ?, ?)", (frame, pid, x, y))
            db.execute("insert into person_state values (?, ?, ?, ?, 0, ?)",
                       (frame, pid, 0.1 if pid % 2 == 0 else -0.1, 0.0, rng.uniform(0, 600)))
            db.execute("insert into person_load values (?, ?, ?)", (frame, pid, rng.uniform(0, 600)))
    if fall:
        db.execute("insert into event values (10, 1.0, 'fall', 1, 'recorded: stand-in')")
    db.commit()
    db.close()


def make_sweep(folder, venue, runs, fall=False):
    os.makedirs(os.path.join(folder, "runs"), exist_ok=True)
    rows = []
    for k in range(runs):
        variant, seed = ("one-way" if k % 2 else "two-way"), k // 2 + 1
        run_id = f"{k:04d}-{variant}-seed{seed}"
        make_run(os.path.join(folder, "runs", run_id + ".sqlite"), venue, seed, fall)
        rows.append([k, run_id, variant, seed, 3.0, 0.3, "complete", "lanes", 4.0, 0.5 + 0.01 * k, 0.1, 500.0 + k,
                     2, 0.5, 4.5, 1.0 + k])
    db_path = os.path.join(folder, "results.sqlite")
    if os.path.exists(db_path):
        os.remove(db_path)
    db = sqlite3.connect(db_path)
    db.execute("create table sweep(key text primary key, value text)")
    db.executemany("insert into sweep values (?, ?)", [
        ("format", "crowdrecon-sweep-results"), ("version", "1"), ("name", "a stand-in sweep"),
        ("diagram_x", "population.density_per_m2"), ("diagram_y", "population.counter_flow_fraction")])
    db.execute("create table runs (" + ", ".join(f'"{c}"' for c in COLUMNS) + ")")
    db.executemany("insert into runs values (" + ", ".join("?" for _ in COLUMNS) + ")", rows)
    db.commit()
    db.close()
    with open(os.path.join(folder, "results.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        w.writerows(rows)


def make_nights(folder, venue):
    """(run, scale, first jam or None, clog for good or None, finished)."""
    nights = [("n1", 1.0, None, None, True), ("n2", 1.2, None, None, True), ("n3", 1.4, 4790.0, 4790.0, True),
              ("n4", 1.45, 2400.0, 2460.0, True), ("n5", 1.45, 2900.0, 3700.0, True), ("n6", 1.5, 2750.0, None, False),
              ("n7", 1.5, 2600.0, 3300.0, True)]
    pushed = {"n4", "n5", "n7"}
    for sub in ("summaries", "summaries-push", "summaries-late"):
        os.makedirs(os.path.join(folder, sub), exist_ok=True)
    with open(os.path.join(folder, "paths.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", "time_s", "inside", "main", "counter", "density_per_m2", "counter_flow_share",
                    "counter_share_raw", "mean_speed_m_per_s"])
        for run, scale, jam, clog, finished in nights:
            end = 5700 if finished else 3100
            for t in range(0, end + 1, 10):
                moving = jam is None or t < jam or (clog is not None and jam + 200 < t < clog)
                w.writerow([run, t, 60, 40, 20, 1.7, 0.33, 0.33, 1.0 if moving else 0.02])
    for run, scale, jam, clog, finished in nights:
        if not finished:
            continue
        summary = {"format": "crowdrecon-ensemble-run", "version": 1, "label": run, "seed": 1, "end_s": 5700.0,
                   "clog_for_good_s": clog, "avalanche_s": [], "fall_s": [],
                   "scenario": {"venue": venue.get("metadata", {}).get("name", "venue"),
                                "timeline": {"rate_scale": scale}, "model": {}}}
        with open(os.path.join(folder, "summaries", run + ".json"), "w") as f:
            json.dump(summary, f)
        for sub, at in (("summaries-push", 0.0), ("summaries-late", 100.0)):
            if run in pushed:
                summary["scenario"]["timeline"]["events"] = [{"time_s": at, "group": "counter",
                                                              "set": {"back_force_gamma": 4.8}}]
            with open(os.path.join(folder, sub, run + ".json"), "w") as f:
                json.dump(summary, f)
            summary["scenario"]["timeline"].pop("events", None)


def main(argv):
    if len(argv) >= 4 and argv[1] == "nights":
        with open(argv[3]) as f:
            make_nights(argv[2], json.load(f))
        return
    if len(argv) < 4 or argv[1] not in ("sweep", "run"):
        sys.exit(__doc__)
    with open(argv[3]) as f:
        venue = json.load(f)
    if argv[1] == "run":
        make_run(argv[2], venue, 1)
        return
    runs = int(argv[argv.index("--runs") + 1]) if "--runs" in argv else 4
    make_sweep(argv[2], venue, runs, "--fall" in argv)


if __name__ == "__main__":
    main(sys.argv)
