#!/usr/bin/env python3
"""The Itaewon design envelope (issue 43, point 5): what a one-way rule in the
alley, or the station's inflow held back, changes for the same crowd.

Reads a finished sweep of studies/itaewon-design-envelope/design-envelope*.json (or arrival-ranges*.json) (its
results.csv and the runs it kept) and writes, per design (variant x the
station inflow's cap), over its seeds:

  - the alley's own density: each measurement area's head count over its
    area, a 10-s moving mean; its peak and its mean over the run's last 30 s;
  - people through the alley: crossings of the alley's foot (y = 1 m) up and
    down, from the trajectories;
  - loads: the most people above 400 N at once, everyone ever above it, the
    largest chest load and the longest exposure (the sweep's analysis);
  - the peak local density and falls.

    studies/itaewon-design-envelope/itaewon-envelope.py SWEEP_DIR -o OUT_DIR [--venue venues/itaewon/alley.json]

Writes OUT_DIR/envelope.md (the table), envelope.csv (one row per run) and
envelope.svg / envelope.png (the alley's peak density and the people above
400 N per design). Plain Python and sqlite3; the PNG drawn by headless
Chromium where it is installed.

Before any work (scripts/script_guard.py): SWEEP_DIR must be a finished sweep
(results.sqlite, results.csv with the analysis' columns, its kept runs) of the
Itaewon alley: every run's own venue must have the --venue's measurement areas
(a sweep of another venue, such as the hallway, is refused instead of giving an
envelope of zeros); OUT_DIR must be new, empty or a previous envelope's folder
(else --force, which writes into it and deletes nothing), never the sweep
folder; every file is written whole. A bad argument is one line, exit status 2.
"""
import argparse
import csv
import json
import math
import os
import sqlite3
import statistics
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # studies/NAME/ is two levels down
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from svg_png import svg_to_png  # noqa: E402
import script_guard as guard  # noqa: E402

FOOT_Y = 1.0           # the alley's foot line (venue: alley_foot_line)
FOOT_X = (-0.1, 3.3)   # ... across the alley's width there
WINDOW_S = 10.0        # moving mean of the area densities
LOAD_N = 400.0


def inside(x, y, poly):
    c = False
    j = len(poly) - 1
    for i in range(len(poly)):
        xi, yi = poly[i]
        xj, yj = poly[j]
        if (yi > y) != (yj > y) and x < (xj - xi) * (y - yi) / (yj - yi) + xi:
            c = not c
        j = i
    return c


def area(poly):
    return 0.5 * abs(sum(poly[i][0] * poly[i - 1][1] - poly[i - 1][0] * poly[i][1] for i in range(len(poly))))


def run_metrics(path, areas, alley):
    db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    times = dict(db.execute("select frame, time_s from census"))
    frames = sorted(times)
    dt = (times[frames[-1]] - times[frames[0]]) / max(len(frames) - 1, 1)
    counts = {a: {f: 0 for f in frames} for a in areas}
    last = {}
    up = down = 0
    for frame, pid, x, y in db.execute("select frame, id, pos_x, pos_y from trajectory_data order by frame"):
        for a, (poly, _) in areas.items():
            if inside(x, y, poly):
                counts[a][frame] += 1
        if pid in last:
            y0 = last[pid]
            if FOOT_X[0] <= x <= FOOT_X[1]:
                if y0 < FOOT_Y <= y:
                    up += 1
                elif y0 >= FOOT_Y > y:
                    down += 1
        last[pid] = y
    above = dict(db.execute(f"select frame, count(*) from person_load where chest_n > {LOAD_N} group by frame"))
    fallen = max(r[0] for r in db.execute("select fallen from census"))
    out = {"alley_up": up, "alley_down": down, "most_above_400n_at_once": max(above.values(), default=0),
           "fallen": fallen}
    # Where the loaded people are at that worst frame: in the alley, or elsewhere (the junction, the streets).
    in_alley = 0
    if above:
        worst = max(above, key=above.get)
        for x, y in db.execute("select t.pos_x, t.pos_y from person_load l join trajectory_data t "
                               "on t.frame = l.frame and t.id = l.id where l.frame = ? and l.chest_n > ?",
                               (worst, LOAD_N)):
            in_alley += inside(x, y, alley)
    out["above_400n_in_alley_at_worst"] = in_alley
    n = max(1, int(round(WINDOW_S / dt)))
    tail = max(1, int(round(30.0 / dt)))
    for a, (poly, m2) in areas.items():
        series = [counts[a][f] / m2 for f in frames]
        moving = [statistics.mean(series[max(0, k - n + 1):k + 1]) for k in range(len(series))]
        out[f"{a}_peak_per_m2"] = max(moving)
        out[f"{a}_end_per_m2"] = statistics.mean(series[-tail:])
    return out


AREAS = ("alley_foot", "alley_middle", "alley_top", "junction")  # the areas the table and the figure name
COLUMNS = ("run_id", "variant", "seed", "status", "max_load_n", "people_ever_above_load", "longest_above_load_s",
           "peak_density_per_m2", "wall_s")
EXPECTED_SWEEP = ("a finished sweep of the Itaewon alley (studies/itaewon-design-envelope/design-envelope*.json or "
                  "arrival-ranges*.json, with keep_runs)")


def check_venue(path):
    """The --venue: a venue with the areas the table names and the slope's region (the alley)."""
    venue = guard.read_json_file(path, "a crowdrecon venue (JSON)")
    areas = {a.get("id"): a.get("polygon") for a in venue.get("measurement_areas", [])} if isinstance(venue, dict) else {}
    missing = [a for a in AREAS if a not in areas]
    if missing or not (venue.get("slope") or {}).get("region"):
        raise guard.ScriptError(f"--venue {path}: has no " + (f"measurement area {', '.join(missing)}" if missing else
                                                               "slope region") +
                                "; expected the Itaewon alley's venue (venues/itaewon/alley.json)")
    return venue


def check_sweep(sweep, rows):
    """Every run complete, kept, with the tables read, and run in a venue with the alley's areas (else its counts
    are zeros: a hallway sweep gave an envelope of zeros)."""
    if not rows:
        raise guard.ScriptError(f"{sweep}: its results.csv holds no runs; expected {EXPECTED_SWEEP}")
    for r in rows:
        if r["status"] != "complete":
            raise guard.ScriptError(f"{sweep}: run {r['run_id']} did not complete ({r['status']}); expected "
                                    f"{EXPECTED_SWEEP}")
        run = os.path.join(sweep, "runs", r["run_id"] + ".sqlite")
        if not os.path.exists(run):
            raise guard.ScriptError(f"{run}: missing; expected {EXPECTED_SWEEP}")
        guard.check_run_file(run, ("census", "trajectory_data", "person_load"))
        db = guard.open_readonly(run)
        try:
            row = db.execute("select value from run where key = 'venue'").fetchone()
        finally:
            db.close()
        try:
            own = json.loads(row[0]) if row else None
        except ValueError:
            own = None
        name = (own or {}).get("metadata", {}).get("name", "unnamed") if isinstance(own, dict) else "unknown"
        own_areas = {a.get("id"): a.get("polygon") for a in own.get("measurement_areas", [])} if isinstance(own, dict) else {}
        if any(a not in own_areas for a in AREAS):
            raise guard.ScriptError(f"{sweep}: run {r['run_id']} is not of the Itaewon alley (its venue "
                                    f"{name[:60]!r} has no measurement areas {', '.join(AREAS)}); "
                                    f"expected {EXPECTED_SWEEP}")


CSV_HEAD = "alley_up,alley_down,"
MD_HEAD = "| design | station inflow held to (persons/s) |"


def main():
    p = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("sweep", type=guard.sweep_dir)
    p.add_argument("-o", "--out", required=True)
    p.add_argument("--venue", default=os.path.join(ROOT, "venues", "itaewon", "alley.json"), type=guard.existing_file)
    guard.add_force(p)
    args = p.parse_args()
    guard.check_sweep_dir(args.sweep, sqlite=True, csv_table=True)
    guard.require_csv_columns(os.path.join(args.sweep, "results.csv"), COLUMNS, EXPECTED_SWEEP)
    venue = check_venue(args.venue)
    rows = list(csv.DictReader(open(os.path.join(args.sweep, "results.csv"))))
    check_sweep(args.sweep, rows)
    files = {"envelope.md": guard.starts_with(MD_HEAD), "envelope.csv": guard.starts_with(CSV_HEAD),
             "envelope.svg": guard.is_svg, "envelope.png": guard.is_png}
    guard.check_outputs(
        [guard.Output("-o", args.out, "a folder of itaewon-envelope.py", folder=True, is_previous=guard.folder_with(files))]
        + [guard.Output("", os.path.join(args.out, name), f"an {name} of itaewon-envelope.py", check)
           for name, check in files.items()],
        guard.sweep_inputs(args.sweep) + [("the sweep", args.sweep), ("--venue", args.venue)], args.force)
    venue = json.load(open(args.venue))
    areas = {a["id"]: (a["polygon"], area(a["polygon"])) for a in venue["measurement_areas"]}
    cap = "timeline.inflows.0.max_rate_per_s"
    table = []
    for r in rows:
        if r["status"] != "complete":
            sys.exit(f"itaewon-envelope: run {r['run_id']} did not complete: {r['status']}")
        run = os.path.join(args.sweep, "runs", r["run_id"] + ".sqlite")
        m = run_metrics(run, areas, venue["slope"]["region"])
        m.update({"run_id": r["run_id"], "variant": r["variant"], "station_cap_per_s": float(r.get(cap) or "nan"),
                  "seed": int(r["seed"]), "max_load_n": float(r["max_load_n"]),
                  "people_ever_above_400n": int(float(r["people_ever_above_load"])),
                  "longest_above_400n_s": float(r["longest_above_load_s"] or 0),
                  "peak_local_density_per_m2": float(r["peak_density_per_m2"]), "wall_s": float(r["wall_s"])})
        table.append(m)
        print(f"{r['run_id']}: alley top peak {m['alley_top_peak_per_m2']:.2f} /m2, "
              f"{m['most_above_400n_at_once']} above 400 N at once", file=sys.stderr)
    os.makedirs(args.out, exist_ok=True)
    keys = list(table[0].keys())
    with guard.whole_file(os.path.join(args.out, "envelope.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(table)
    # (A sweep without the cap axis, e.g. the arrival ranges: one design per variant, cap "-".)
    designs = []
    for t in table:
        if not any(d[0] == t["variant"] and same(d[1], t["station_cap_per_s"]) for d in designs):
            designs.append((t["variant"], t["station_cap_per_s"]))
    designs.sort(key=lambda d: (d[0] != "two-way", -d[1] if d[1] == d[1] else 0))

    def cell(ts, key, digits=1):
        v = [t[key] for t in ts]
        med = statistics.median(v)
        fmt = f"{{:.{digits}f}}"
        return f"{fmt.format(med)} ({', '.join(fmt.format(x) for x in v)})"

    lines = ["| design | station inflow held to (persons/s) | alley foot / middle / top: peak density, /m² (10-s mean) | "
             "junction peak, /m² | up / down through the alley's foot | most people above 400 N at once | "
             "of them in the alley | people ever above 400 N | largest chest load, N | longest above 400 N, s | "
             "peak local density, /m² | fallen |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for v, c in designs:
        ts = [t for t in table if t["variant"] == v and same(t["station_cap_per_s"], c)]
        lines.append(f"| {v} | {'-' if c != c else f'{c:g}'} | {cell(ts, 'alley_foot_peak_per_m2')} / {cell(ts, 'alley_middle_peak_per_m2')} / "
                     f"{cell(ts, 'alley_top_peak_per_m2')} | {cell(ts, 'junction_peak_per_m2')} | "
                     f"{cell(ts, 'alley_up', 0)} / {cell(ts, 'alley_down', 0)} | {cell(ts, 'most_above_400n_at_once', 0)} | "
                     f"{cell(ts, 'above_400n_in_alley_at_worst', 0)} | "
                     f"{cell(ts, 'people_ever_above_400n', 0)} | {cell(ts, 'max_load_n', 0)} | "
                     f"{cell(ts, 'longest_above_400n_s', 0)} | {cell(ts, 'peak_local_density_per_m2')} | {cell(ts, 'fallen', 0)} |")
    lines += ["", "Each cell: the median over the seeds, then every seed's value in brackets.",
              f"Wall time of the sweep's runs: {sum(t['wall_s'] for t in table):.0f} s of run time "
              f"({len(table)} runs, {statistics.mean(t['wall_s'] for t in table):.0f} s each on average)."]
    guard.write_whole(os.path.join(args.out, "envelope.md"), "\n".join(lines) + "\n")
    print("\n".join(lines))
    name = sqlite3.connect(f"file:{os.path.join(args.sweep, 'results.sqlite')}?mode=ro", uri=True).execute(
        "select value from sweep where key = 'name'").fetchone()[0]
    draw(table, designs, os.path.join(args.out, "envelope.svg"), name)
    svg_to_png(os.path.join(args.out, "envelope.svg"), os.path.join(args.out, "envelope.png"), 980, 560)


def same(a, b):
    """Equal caps, NaN (no cap axis) equal to NaN."""
    return a == b or (a != a and b != b)


def nice_ceiling(v):
    """The smallest of 1, 1.2, 1.6, 2, 3, 4, 5, 6, 8 x 10^k at or above v (its quarters are short numbers)."""
    if v <= 0:
        return 1.0
    k = 10 ** math.floor(math.log10(v))
    return next(m * k for m in (1, 1.2, 1.6, 2, 3, 4, 5, 6, 8, 10) if m * k >= v)


def draw(table, designs, file, name):
    """Two bar panels: the alley's peak density (top area) and the most people above 400 N at once, per design,
    one dot per seed on a bar at the median."""
    palette = ["#3a6ea5", "#d9822b", "#5a9e4b", "#8e5ea2", "#c44e52"]
    variants = []
    for v, _ in designs:
        if v not in variants:
            variants.append(v)
    colours = {v: palette[i % len(palette)] for i, v in enumerate(variants)}
    title = name if len(name) <= 118 else name[:115] + "..."
    w, h, left, top, pw, ph, gap = 980, 560, 90, 70, 380, 380, 110
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="DejaVu Sans, sans-serif">',
           '<rect width="100%" height="100%" fill="white"/>',
           f'<text x="20" y="30" font-size="14" font-weight="bold">{title}</text>',
           '<text x="20" y="52" font-size="13" fill="#555">bars: median over seeds; dots: each seed; '
           'under each bar its variant and, where the sweep holds it back, the station inflow\'s cap.</text>']
    panels = [("alley_top_peak_per_m2", "the alley's top: peak density, /m²"),
              ("most_above_400n_at_once", "people above 400 N at once (most)")]
    for k, (key, label) in enumerate(panels):
        x0 = left + k * (pw + gap)
        vmax = nice_ceiling(max(t[key] for t in table) * 1.05)
        out.append(f'<rect x="{x0}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="#333"/>')
        out.append(f'<text x="{x0 + pw / 2}" y="{top + ph + 70}" font-size="14" text-anchor="middle">{label}</text>')
        for g in range(5):
            v = vmax * g / 4
            y = top + ph - ph * g / 4
            out.append(f'<line x1="{x0}" x2="{x0 + pw}" y1="{y}" y2="{y}" stroke="#ddd"/>')
            out.append(f'<text x="{x0 - 6}" y="{y + 4}" font-size="11" text-anchor="end">{round(v, 6):g}</text>')
        bw = pw / (len(designs) + 1)
        for i, (v, c) in enumerate(designs):
            ts = [t[key] for t in table if t["variant"] == v and same(t["station_cap_per_s"], c)]
            med = statistics.median(ts)
            cx = x0 + bw * (i + 1)
            out.append(f'<rect x="{cx - bw * 0.35}" y="{top + ph - ph * med / vmax}" width="{bw * 0.7}" '
                       f'height="{ph * med / vmax}" fill="{colours.get(v, "#888")}" opacity="0.75"/>')
            for t in ts:
                out.append(f'<circle cx="{cx}" cy="{top + ph - ph * t / vmax}" r="3.5" fill="black"/>')
            out.append(f'<text x="{cx}" y="{top + ph + 18}" font-size="11" text-anchor="middle">'
                       f'{"" if c != c else f"{c:g}/s"}</text>')
            out.append(f'<text x="{cx}" y="{top + ph + 34}" font-size="8.5" text-anchor="middle" fill="#555">'
                       f'{v}</text>')
    out.append("</svg>")
    guard.write_whole(file, "\n".join(out) + "\n")


if __name__ == "__main__":
    guard.run_main(main)
