#!/usr/bin/env python3
"""The Itaewon falls the accounts record (issue 43, point 3): what the model
does after several people fall at once, imposed by a timeline event
(`timeline.events[].fall`, docs/scenarios.md), where they fell and where the
model's crowd packs.

Reads a finished sweep of studies/itaewon-recorded-falls/recorded-falls*.json (its
results.csv and the runs it kept) and, with --baseline, the same seeds'
runs without the recorded fall (a sweep of the same scenario and build). Per
run, from the run file:

  - the recorded fall: how many fell of the count asked, and where;
  - the falls after it that the model made (the paper's rule with tripping
    over the fallen): how many, how many "tripped", when and how far from
    the recorded fall's point;
  - the load on the fallen: each one's largest chest load after the fall
    and their longest time above 400 N without a break;
  - the crowd at the fall's place: the head count within 3 m of the point
    at the fall and its peak after it, the people there above 400 N;
  - the whole network: the most people above 400 N at once after the fall,
    and the same for the baseline run of the seed over the same frames;
    the baseline must be identical to the run before the fall (checked:
    positions of every frame before it).

    studies/itaewon-recorded-falls/itaewon-recorded-falls.py SWEEP_DIR -o OUT_DIR [--baseline SWEEP_DIR]

Writes OUT_DIR/recorded-falls.md (the table and the check) and
recorded-falls.csv (one row per run). Plain Python and sqlite3.

Before any work (scripts/script_guard.py): SWEEP_DIR (and --baseline) must be
sweep folders (results.csv) whose runs are complete and kept, and every run's
scenario must hold a timeline fall event (a sweep without one is refused, not
read); OUT_DIR must be new, empty or a previous table's folder (else --force,
which writes into it and deletes nothing), never a sweep's folder; the files
are written whole. A bad argument is one line, exit status 2.
"""
import argparse
import csv
import hashlib
import json
import math
import os
import sqlite3
import statistics
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # studies/NAME/ is two levels down
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import script_guard as guard  # noqa: E402

LOAD_N = 400.0
NEAR_M = 3.0  # "at the fall's place": within this of its point
ALLEY_TOP_Y = 45.0  # the venue: the sidewalk below y = 0, the alley to y = 45, the food street above


def open_run(path):
    return sqlite3.connect(f"file:{path}?mode=ro", uri=True)


def positions_digest(db, before_s):
    """SHA-256 of every position of every frame before `before_s`."""
    h = hashlib.sha256()
    for row in db.execute("select t.frame, t.id, t.pos_x, t.pos_y from trajectory_data t join frame_time f "
                          "on f.frame = t.frame where f.time_s < ? order by t.frame, t.id", (before_s,)):
        h.update(repr(row).encode())
    return h.hexdigest()


def above_at_once(db, after_s):
    """Per frame at or after `after_s`: people above 400 N (frames without any: 0)."""
    frames = [f for (f,) in db.execute("select frame from frame_time where time_s >= ? order by frame", (after_s,))]
    counts = dict(db.execute("select l.frame, count(*) from person_load l join frame_time f on f.frame = l.frame "
                             "where f.time_s >= ? and l.chest_n > ? group by l.frame", (after_s, LOAD_N)))
    return {f: counts.get(f, 0) for f in frames}


def fall_point(scenario_json):
    event = next(e for e in scenario_json["timeline"]["events"] if "fall" in e)
    return event["time_s"], tuple(event["fall"]["at"]), event["fall"]["count"]


def run_metrics(path):
    db = open_run(path)
    scenario = json.loads(db.execute("select value from run where key = 'scenario'").fetchone()[0])
    t0, (px, py), asked = fall_point(scenario)
    times = dict(db.execute("select frame, time_s from frame_time"))
    dt = (max(times.values()) - min(times.values())) / max(len(times) - 1, 1)
    falls = list(db.execute("select frame, time_s, person, detail from event where kind = 'fall' order by time_s, person"))
    recorded = [f for f in falls if f[3].startswith("recorded:")]
    later = [f for f in falls if not f[3].startswith("recorded:")]
    early = [f for f in later if f[1] < t0 - 1e-9]

    def where(frame, person):
        row = db.execute("select pos_x, pos_y from trajectory_data where frame = ? and id = ?", (frame, person)).fetchone()
        return row if row else (float("nan"), float("nan"))

    fallen_ids = [f[2] for f in recorded]
    # Each recorded fallen's loads after the fall: the largest, the longest run above 400 N.
    most, longest = [], []
    for pid in fallen_ids:
        series = [c for (c,) in db.execute("select l.chest_n from person_load l join frame_time f on f.frame = l.frame "
                                           "where l.id = ? and f.time_s >= ? order by l.frame", (pid, t0))]
        most.append(max(series, default=0.0))
        run = best = 0
        for c in series:
            run = run + 1 if c > LOAD_N else 0
            best = max(best, run)
        longest.append(best * dt)
    # The force pressing on each recorded fallen (their contacts' normal
    # forces summed): the floor holds a fallen body, so a push from one side
    # is carried without compressing the chest across (the chest load above).
    pressed = {}
    if fallen_ids:
        ids = ",".join(str(int(p)) for p in fallen_ids)
        for frame, a, b, fn in db.execute(
                f"select c.frame, c.a, c.b, c.normal_force_n from contact c join frame_time f on f.frame = c.frame "
                f"where f.time_s >= ? and (c.a in ({ids}) or (c.wall = 0 and c.b in ({ids})))", (t0,)):
            for pid in (a, b):
                if pid in fallen_ids:
                    pressed[(frame, pid)] = pressed.get((frame, pid), 0.0) + fn
    # The crowd at the fall's place, per frame from the fall on.
    near = {}
    near_loaded = {}
    for frame, x, y, chest in db.execute(
            "select t.frame, t.pos_x, t.pos_y, coalesce(l.chest_n, 0) from trajectory_data t join frame_time f "
            "on f.frame = t.frame left join person_load l on l.frame = t.frame and l.id = t.id "
            "where f.time_s >= ? - 1e-9", (t0,)):
        if math.hypot(x - px, y - py) <= NEAR_M:
            near[frame] = near.get(frame, 0) + 1
            near_loaded[frame] = near_loaded.get(frame, 0) + (chest > LOAD_N)
    first = min(near) if near else None
    later_dist = []
    places = {"sidewalk": 0, "alley": 0, "food street": 0}
    for f in later:
        x, y = where(f[0], f[2])
        later_dist.append(math.hypot(x - px, y - py))
        places["sidewalk" if y < 0 else "alley" if y < ALLEY_TOP_Y else "food street"] += 1
    groups = dict(db.execute("select id, grp from person"))
    later_counter = sum(1 for f in later if groups.get(f[2]) == 1)  # (ids 1-based in every table)
    above = above_at_once(db, t0)
    return {
        "scenario_t0": t0, "point": (px, py), "asked": asked,
        "recorded": len(recorded), "before_fall_falls": len(early),
        "later_falls": len(later) - len(early),
        "later_tripped": sum(1 for f in later if f[3].startswith("tripped")),
        "later_first_after_s": (min(f[1] for f in later if f[1] >= t0) - t0) if len(later) > len(early) else None,
        "later_within_3m": sum(1 for d in later_dist if d <= NEAR_M),
        "later_on_sidewalk": places["sidewalk"], "later_in_alley": places["alley"],
        "later_on_food_street": places["food street"], "later_counter_flow": later_counter,
        "fallen_max_load_n": max(most, default=0.0),
        "fallen_median_max_load_n": statistics.median(most) if most else 0.0,
        "fallen_longest_above_400n_s": max(longest, default=0.0),
        "fallen_most_pressed_n": max(pressed.values(), default=0.0),
        "near_at_fall": near.get(first, 0) if first is not None else 0,
        "near_peak_after": max(near.values(), default=0),
        "near_above_400n_peak": max(near_loaded.values(), default=0),
        "above_400n_most_after": max(above.values(), default=0),
        "above_frames": above,
        "digest_before": positions_digest(db, t0),
        "end_s": max(times.values()),
    }


EXPECTED_SWEEP = ("a finished sweep of studies/itaewon-recorded-falls/recorded-falls*.json (results.csv and its kept "
                  "runs)")
RUN_TABLES = ("frame_time", "event", "trajectory_data", "person_load", "person", "contact")


def check_runs(sweep, rows, fall):
    """Every complete run kept, a run file with the tables read; with `fall`, its scenario has a fall event."""
    for r in rows:
        if r["status"] != "complete":
            if fall:
                raise guard.ScriptError(f"{sweep}: run {r['run_id']} did not complete ({r['status']}); expected "
                                        f"{EXPECTED_SWEEP}")
            continue
        run = os.path.join(sweep, "runs", r["run_id"] + ".sqlite")
        if not os.path.exists(run):
            raise guard.ScriptError(f"{run}: missing; expected {EXPECTED_SWEEP}")
        guard.check_run_file(run, RUN_TABLES)
        if not fall:
            continue
        db = open_run(run)
        try:
            row = db.execute("select value from run where key = 'scenario'").fetchone()
        finally:
            db.close()
        try:
            scenario = json.loads(row[0]) if row else None
            fall_point(scenario)
        except (ValueError, TypeError, KeyError, AttributeError, StopIteration):
            raise guard.ScriptError(f"{sweep}: run {r['run_id']}'s scenario has no timeline fall event; expected "
                                    f"{EXPECTED_SWEEP}") from None


CSV_HEAD = "run_id,variant,asked,seed,"
MD_HEAD = "# Itaewon: the falls the accounts record"


def main():
    p = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("sweep", type=guard.sweep_dir_csv)
    p.add_argument("-o", "--out", required=True)
    p.add_argument("--baseline", type=guard.sweep_dir_csv,
                   help="a sweep of the same scenario without the recorded fall (same seeds, same build)")
    guard.add_force(p)
    args = p.parse_args()
    rows = list(csv.DictReader(open(os.path.join(args.sweep, "results.csv"))))
    if not rows:
        raise guard.ScriptError(f"{args.sweep}: its results.csv holds no runs; expected {EXPECTED_SWEEP}")
    check_runs(args.sweep, rows, True)
    if args.baseline:
        check_runs(args.baseline, list(csv.DictReader(open(os.path.join(args.baseline, "results.csv")))), False)
    files = {"recorded-falls.md": guard.starts_with(MD_HEAD), "recorded-falls.csv": guard.starts_with(CSV_HEAD)}
    inputs = guard.sweep_inputs(args.sweep) + [("the sweep", args.sweep)]
    if args.baseline:
        inputs += guard.sweep_inputs(args.baseline) + [("the baseline sweep", args.baseline)]
    guard.check_outputs(
        [guard.Output("-o", args.out, "a folder of itaewon-recorded-falls.py", folder=True,
                      is_previous=guard.folder_with(files))]
        + [guard.Output("", os.path.join(args.out, name), f"a {name} of itaewon-recorded-falls.py", check)
           for name, check in files.items()], inputs, args.force)
    base = {}
    if args.baseline:
        for r in csv.DictReader(open(os.path.join(args.baseline, "results.csv"))):
            if r["status"] == "complete":
                base[int(r["seed"])] = os.path.join(args.baseline, "runs", r["run_id"] + ".sqlite")
    table = []
    for r in rows:
        if r["status"] != "complete":
            sys.exit(f"itaewon-recorded-falls: run {r['run_id']} did not complete: {r['status']}")
        m = run_metrics(os.path.join(args.sweep, "runs", r["run_id"] + ".sqlite"))
        m.update({"run_id": r["run_id"], "variant": r["variant"], "seed": int(r["seed"]), "wall_s": float(r["wall_s"])})
        b = base.get(m["seed"])
        m["baseline_same_before_fall"] = None
        m["baseline_above_400n_most_after"] = None
        if b:
            bdb = open_run(b)
            m["baseline_same_before_fall"] = positions_digest(bdb, m["scenario_t0"]) == m["digest_before"]
            babove = above_at_once(bdb, m["scenario_t0"])
            m["baseline_above_400n_most_after"] = max(babove.values(), default=0)
        table.append(m)
        print(f"{r['run_id']}: {m['recorded']} of {m['asked']} fell, then {m['later_falls']} more "
              f"({m['later_tripped']} tripped); fallen's largest load {m['fallen_max_load_n']:.0f} N", file=sys.stderr)
    os.makedirs(args.out, exist_ok=True)
    keys = ["run_id", "variant", "asked", "seed", "recorded", "before_fall_falls", "later_falls", "later_tripped",
            "later_first_after_s", "later_within_3m", "later_on_sidewalk", "later_in_alley", "later_on_food_street",
            "later_counter_flow", "fallen_max_load_n", "fallen_median_max_load_n",
            "fallen_longest_above_400n_s", "fallen_most_pressed_n", "near_at_fall", "near_peak_after", "near_above_400n_peak",
            "above_400n_most_after", "baseline_above_400n_most_after", "baseline_same_before_fall", "wall_s"]
    with guard.whole_file(os.path.join(args.out, "recorded-falls.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(table)

    def fmt(v, digits=0):
        if v is None:
            return "–"
        if isinstance(v, bool):
            return "yes" if v else "**no**"
        return f"{v:.{digits}f}" if isinstance(v, float) else str(v)

    lines = [
        "# Itaewon: the falls the accounts record, imposed (issue 43, point 3)",
        "",
        f"Sweep `{os.path.relpath(args.sweep)}`" + (f", baseline `{os.path.relpath(args.baseline)}`" if args.baseline else "")
        + f"; written by `studies/itaewon-recorded-falls/itaewon-recorded-falls.py`. At {table[0]['scenario_t0']:g} s (22:15 on the shortened"
        " evening's clock) the walking people nearest the point fall at once (`timeline.events[].fall`); every later"
        " fall is the model's own (the paper's acceleration rule, and tripping over the fallen where the run has it:"
        " `timeline.falls.trip_over_fallen`). Loads are chest loads (`person_load`); 'most pressed' is the sum of a"
        f" fallen person's contact forces; 'near' is within {NEAR_M:g} m of the point; the sweep's paths are where it"
        " ran (its run files are not kept in the repository).",
        "",
        "| run | place | asked | fell | later falls (tripped) | first after | within 3 m | sidewalk / alley / food street | of them coming down | fallen: largest load | fallen: median of largest | fallen: longest above 400 N | fallen: most pressed (contacts' sum) | near at the fall | near, peak after | near above 400 N, peak | network above 400 N, most after | baseline, same frames | baseline identical before |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for m in table:
        first = "–" if m["later_first_after_s"] is None else f"{m['later_first_after_s']:.1f} s"
        lines.append(
            f"| {m['run_id']} | {m['variant']} ({m['point'][0]:g}, {m['point'][1]:g}) | {m['asked']} | {m['recorded']} | "
            f"{m['later_falls']} ({m['later_tripped']}) | {first} | {m['later_within_3m']} | "
            f"{m['later_on_sidewalk']} / {m['later_in_alley']} / {m['later_on_food_street']} | {m['later_counter_flow']} | "
            f"{m['fallen_max_load_n']:.0f} N | {m['fallen_median_max_load_n']:.0f} N | {m['fallen_longest_above_400n_s']:.1f} s | {m['fallen_most_pressed_n']:.0f} N | "
            f"{m['near_at_fall']} | {m['near_peak_after']} | {m['near_above_400n_peak']} | {m['above_400n_most_after']} | "
            f"{fmt(m['baseline_above_400n_most_after'])} | {fmt(m['baseline_same_before_fall'])} |")
    if any(m["before_fall_falls"] for m in table):
        lines += ["", "Falls before the recorded one (the model's own): " +
                  ", ".join(f"{m['run_id']} {m['before_fall_falls']}" for m in table if m["before_fall_falls"])]
    guard.write_whole(os.path.join(args.out, "recorded-falls.md"), "\n".join(lines) + "\n")


if __name__ == "__main__":
    guard.run_main(main)
