#!/usr/bin/env python3
"""Falls that happen (issue 39, point 3): the verification scenarios of
venues/verification/scenarios/ under each fall rule, tabulated.

Usage: studies/falls-verification/falls-study.py CROWDRECON OUT_DIR [--force]

For each scenario and rule it runs `crowdrecon simulate` (runs already in
OUT_DIR are reused), then reads the run file: falls (how many, how many of
them tripped over the fallen, the first), and the largest filtered
acceleration anyone reached, |v(t) - v(t - 0.5 s)| / 0.5 s from the frames
(10 per second), the quantity the paper's rule compares with 5 m/s^2.
Writes OUT_DIR/falls.csv and OUT_DIR/falls.md. Standard library only.
Every output is checked before any run (scripts/script_guard.py): OUT_DIR new,
empty or a previous falls study's folder (else --force, which writes into it
and deletes nothing), each run file and table in it new or a previous output
of its kind (a run file is reused only if it is one); the tables are written
whole. A missing program or a bad argument is one line, exit status 2.
"""
import csv
import json
import math
import os
import sqlite3
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # studies/NAME/ is two levels down
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import script_guard as guard  # noqa: E402
SCENARIOS = os.path.join(ROOT, "venues", "verification", "scenarios")
CASES = [
    ("falls-sudden-release.json", "must fall", {}),
    ("falls-surge-down-slope.json", "must fall", {}),
    ("falls-walking-3pm2.json", "must not fall", {}),
    ("falls-walking-3pm2.json", "must not fall", {"counter_flow_fraction": 0.0}),
]
RULES = [
    ("paper", {"criterion": "acceleration"}),
    ("paper + tripping", {"criterion": "acceleration", "trip_over_fallen": True}),
]


def run(crowdrecon, out_dir, name, scenario, population, falls):
    path = os.path.join(out_dir, name + ".sqlite")
    if guard.is_run_file(path):
        return path
    with open(os.path.join(SCENARIOS, scenario)) as f:
        s = json.load(f)
    s["population"].update(population)
    s["timeline"]["falls"] = falls
    # Written into the output folder, never beside the shipped scenarios:
    # their relative paths made absolute.
    s["venue"] = os.path.normpath(os.path.join(SCENARIOS, s["venue"]))
    body = s["population"].get("body", {})
    if isinstance(body, dict) and isinstance(body.get("reference"), str):
        body["reference"] = os.path.normpath(os.path.join(SCENARIOS, body["reference"]))
    tmp = os.path.join(out_dir, ".study-" + name + ".json")
    with open(tmp, "w") as f:
        json.dump(s, f)
    try:
        subprocess.run([crowdrecon, "simulate", tmp, "-o", path + ".part", "--threads", "1"], check=True,
                       stdout=subprocess.DEVNULL)
    finally:
        os.remove(tmp)
    os.replace(path + ".part", path)
    return path


def measure(path):
    db = sqlite3.connect(path)
    falls = db.execute("select time_s, detail from event where kind = 'fall' order by time_s").fetchall()
    times = dict(db.execute("select frame, time_s from frame_time"))
    by_frame = {}
    for frame, pid, vx, vy, state in db.execute("select frame, id, vel_x, vel_y, state from person_state"):
        by_frame.setdefault(frame, {})[pid] = (vx, vy, state)
    frames = sorted(by_frame)
    dt = times[frames[1]] - times[frames[0]]
    lag = round(0.5 / dt)
    peak = 0.0
    for k in range(lag, len(frames)):
        now, then = by_frame[frames[k]], by_frame[frames[k - lag]]
        for pid, (vx, vy, state) in now.items():
            if state != 0 or pid not in then:
                continue
            a = math.hypot(vx - then[pid][0], vy - then[pid][1]) / (lag * dt)
            peak = max(peak, a)
    db.close()
    return {
        "falls": len(falls),
        "tripped": sum(1 for _, d in falls if d.startswith("tripped")),
        "first_fall_s": falls[0][0] if falls else "",
        "peak_filtered_acceleration_m_per_s2": round(peak, 2),
    }


CSV_HEAD = "scenario,expected,rule,falls,"
MD_HEAD = "| scenario | expected | rule | falls |"


def names():
    """(scenario, expected, population, rule, falls, label, run name) of every case and rule."""
    out = []
    for scenario, expected, population in CASES:
        for rule, falls in RULES:
            label = scenario[:-5] + ("-one-way" if population else "")
            out.append((scenario, expected, population, rule, falls, label, label + "-" + rule.replace(" + ", "-")))
    return out


def main():
    p = guard.ArgumentParser(description=__doc__.strip().splitlines()[0])
    p.add_argument("crowdrecon", type=guard.executable)
    p.add_argument("out_dir")
    guard.add_force(p)
    args = p.parse_args()
    crowdrecon, out_dir = args.crowdrecon, args.out_dir
    runs = {"*.sqlite": guard.is_run_file}
    outputs = [guard.Output("OUT_DIR", out_dir, "a folder of falls-study.py", folder=True, is_previous=guard.folder_with(
                   dict(runs, **{"falls.csv": guard.starts_with(CSV_HEAD), "falls.md": guard.starts_with(MD_HEAD)}))),
               guard.Output("", os.path.join(out_dir, "falls.csv"), "a table of falls-study.py", guard.starts_with(CSV_HEAD)),
               guard.Output("", os.path.join(out_dir, "falls.md"), "a table of falls-study.py", guard.starts_with(MD_HEAD))]
    for *_, name in names():
        outputs.append(guard.Output("", os.path.join(out_dir, name + ".sqlite"), "a crowdrecon run file", guard.is_run_file))
        outputs.append(guard.Output("", os.path.join(out_dir, name + ".sqlite.part"), "a partial run file of falls-study.py",
                                    guard.is_run_file))
    guard.check_outputs(outputs, [("the crowdrecon executable", crowdrecon), ("the scenarios", SCENARIOS)], args.force)
    os.makedirs(out_dir, exist_ok=True)
    rows = []
    for scenario, expected, population, rule, falls, label, name in names():
        m = measure(run(crowdrecon, out_dir, name, scenario, population, falls))
        rows.append({"scenario": label, "expected": expected, "rule": rule, **m})
        print(rows[-1], flush=True)
    with guard.whole_file(os.path.join(out_dir, "falls.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with guard.whole_file(os.path.join(out_dir, "falls.md"), "w") as f:
        f.write("| scenario | expected | rule | falls | of them tripped | first fall (s) | peak filtered acceleration (m/s²) |\n")
        f.write("| --- | --- | --- | --- | --- | --- | --- |\n")
        for r in rows:
            f.write(f"| {r['scenario']} | {r['expected']} | {r['rule']} | {r['falls']} | {r['tripped']} | "
                    f"{r['first_fall_s']} | {r['peak_filtered_acceleration_m_per_s2']} |\n")


if __name__ == "__main__":
    guard.run_main(main)
