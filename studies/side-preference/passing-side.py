#!/usr/bin/env python3
"""Which side two people meeting head on pass each other on (issue 64, side preference).

Reads every run of a sweep of pair-encounter.json (SWEEP_DIR/results.csv and
the kept runs SWEEP_DIR/runs/RUN_ID.sqlite), exports each run's trajectories
with `crowdrecon export` into a scratch folder, and finds the first frame
where the two people's x cross: the one who walks east (it starts at the
smaller x) passes on its right when it is south of the other there (each on
their own right: left shoulder to left shoulder). Writes a Markdown table:
per variant the runs, the share passing on the right with its 95 % Wilson
interval, those on the left, those who never passed each other, and the
median of the closest distance of their centres; and, with --csv, one row
per run.

usage: passing-side.py SWEEP_DIR -o OUT.md [--csv OUT.csv] [--crowdrecon PATH] [--force]

The outputs are written whole (scripts/script_guard.py): never one of the
inputs, never a file that is not a previous output of this script unless
--force. Standard library only.
"""
import argparse
import csv
import io
import math
import os
import pathlib
import sqlite3
import subprocess
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "scripts"))
import script_guard as guard  # noqa: E402

FIRST_LINE = "Two people meeting head on: which side they pass on"
CSV_HEADER = ["variant", "seed", "side", "closest_m"]


def wilson(k, n, z=1.96):
    if n == 0:
        return (float("nan"), float("nan"))
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (c - h, c + h)


def passing(run_file, crowdrecon, scratch):
    out = os.path.join(scratch, os.path.basename(run_file) + ".traj.sqlite")
    r = subprocess.run([crowdrecon, "export", run_file, "-o", out], capture_output=True, text=True)
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise guard.ScriptError(f"{run_file}: crowdrecon export failed: {last}")
    con = guard.open_readonly(out)
    try:
        rows = con.execute("SELECT frame, id, pos_x, pos_y FROM trajectory_data ORDER BY frame, id").fetchall()
    finally:
        con.close()
    frames = {}
    for frame, pid, x, y in rows:
        frames.setdefault(frame, {})[pid] = (x, y)
    both = [f for f in sorted(frames) if len(frames[f]) == 2]
    if not both or any(len(frames[f]) > 2 for f in frames):
        raise guard.ScriptError(f"{run_file}: not two people in the run together; expected a run of pair-encounter.json")
    first = frames[both[0]]
    east = min(first, key=lambda i: first[i][0])  # starts west, walks east
    west = [i for i in first if i != east][0]
    closest = min(math.dist(frames[f][east], frames[f][west]) for f in both if west in frames[f] and east in frames[f])
    for f in both:
        (xe, ye), (xw, yw) = frames[f][east], frames[f][west]
        if xe >= xw:
            return ("right" if ye < yw else "left"), closest
    return "never", closest


def main():
    ap = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sweep_dir", type=guard.sweep_dir_csv)
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--csv")
    ap.add_argument("--crowdrecon", type=guard.executable,
                    help="the crowdrecon executable (default: build/release/cli/crowdrecon of this repository)")
    guard.add_force(ap)
    a = ap.parse_args()
    outputs = [guard.Output("-o", a.out, "a table of passing-side.py", guard.first_line_has(FIRST_LINE))]
    if a.csv:
        outputs.append(guard.Output("--csv", a.csv, "a table of passing-side.py", guard.csv_starting(*CSV_HEADER)))
    guard.check_outputs(outputs, guard.sweep_inputs(a.sweep_dir), a.force)
    if a.crowdrecon is None:  # (checked here, after the outputs: the default is looked for only when needed)
        try:
            a.crowdrecon = guard.executable(str(HERE.parents[1] / "build/release/cli/crowdrecon"))
        except argparse.ArgumentTypeError as e:
            raise guard.ScriptError(f"--crowdrecon not given and {e}") from None
    results = os.path.join(a.sweep_dir, "results.csv")
    with open(results, newline="") as f:
        table = list(csv.DictReader(f))
    if not table:
        raise guard.ScriptError(f"{results}: no runs; expected a sweep of pair-encounter.json")
    per, rows = {}, []
    with tempfile.TemporaryDirectory() as scratch:
        for row in table:
            if row["status"] != "complete":
                raise guard.ScriptError(f"{results}: run {row['run_id']} is {row['status']!r}; expected complete runs")
            run_file = os.path.join(a.sweep_dir, "runs", row["run_id"] + ".sqlite")
            if not os.path.isfile(run_file):
                raise guard.ScriptError(f"{run_file}: no such run file; expected the sweep's kept runs (\"keep_runs\": true)")
            side, closest = passing(run_file, a.crowdrecon, scratch)
            per.setdefault(row["variant"], []).append((side, closest))
            rows.append({"variant": row["variant"], "seed": row["seed"], "side": side, "closest_m": f"{closest:.3f}"})
    lines = [FIRST_LINE + f" ({a.sweep_dir}; the one walking east passes on its right when south of the other "
             "where their x cross).", "",
             "| variant | runs | passed on the right | 95 % interval | on the left | never passed | closest centres, median (m) |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for variant, v in per.items():
        n = len(v)
        right = sum(1 for s, _ in v if s == "right")
        left = sum(1 for s, _ in v if s == "left")
        never = n - right - left
        lo, hi = wilson(right, right + left)
        closest = sorted(c for _, c in v)
        median = (closest[(n - 1) // 2] + closest[n // 2]) / 2
        lines.append(f"| {variant} | {n} | {right} ({100.0 * right / max(1, right + left):.0f} %) | "
                     f"{100 * lo:.0f}-{100 * hi:.0f} % | {left} | {never} | {median:.2f} |")
    if a.csv:
        buffer = io.StringIO()
        w = csv.DictWriter(buffer, fieldnames=CSV_HEADER, lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
        guard.write_whole(a.csv, buffer.getvalue())
    guard.write_whole(a.out, "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    guard.run_main(main)
