#!/usr/bin/env python3
"""Two variants of a sweep compared as ensembles over their seeds (issue 42, point 2).

Reads DIR/results.sqlite of `crowdrecon sweep` (variants A and B, the same
seeds), each run's census from its run file (DIR/runs/, the sweep's
`keep_runs`), and optionally the score tables of `crowdrecon timeline
--scores` for each variant; per statistic, the two ensembles' mean ± sd and
the exact two-sided permutation test of the difference of their means
(scripts/ensemble_stats.py). Writes OUT.md (the table) and OUT.csv (one row
per run and statistic).

Statistics: any column of the sweep's `runs` table (--metrics), the run
file's census at the end (`timeline_removed`, `timeline_queued`, people
inside at the end), and from the scores (--scores A.csv B.csv): avalanches,
the clog for good (a run that never clogs for good counts at its end: said
in the table), the peak of people in danger, the peak local density.

usage: sweep-ensembles.py DIR A B -o OUT [--metrics m1,m2,...] [--scores A.csv B.csv] [--force]

DIR must be a sweep folder (results.sqlite) holding both variants and every
metric; OUT.csv and OUT.md are checked before any work and written whole
(scripts/script_guard.py): never one of the sweep's own files (results.csv,
results.sqlite) or a scores table, never a file that is not a previous output
of this script unless --force.
"""
import argparse
import csv
import json
import math
import pathlib
import sqlite3
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from ensemble_stats import mean_sd, permutation_p  # noqa: E402
import script_guard as guard  # noqa: E402

DEFAULT_METRICS = ("mean_speed_g0_m_per_s,mean_speed_g1_m_per_s,stopped_time_fraction,avalanche_count,"
                   "max_load_n,load_p90_n,load_p99_n,people_ever_above_load,people_danger,"
                   "peak_density_per_m2,wall_s")
COST = {"wall_s"}


def runs_of(folder, variant, metrics):
    con = sqlite3.connect(f"file:{folder / 'results.sqlite'}?mode=ro", uri=True)  # never creates one
    cols = ", ".join(f'"{m}"' for m in metrics)
    rows = con.execute(f"SELECT seed, run_id, duration_s, {cols} FROM runs WHERE variant = ? AND status = 'complete' "
                       "ORDER BY seed", (variant,)).fetchall()
    if not rows:
        raise guard.ScriptError(f"{folder}: no complete runs of variant '{variant}'; expected a variant with complete runs")
    out = {}
    for seed, run_id, duration, *values in rows:
        r = {"run_id": run_id, "duration_s": duration}
        r.update({m: (float(v) if v is not None else math.nan) for m, v in zip(metrics, values)})
        run = folder / "runs" / f"{run_id}.sqlite"
        if run.exists():
            meta = dict(sqlite3.connect(f'file:{run}?mode=ro', uri=True).execute("SELECT key, value FROM run"))
            if "timeline_removed" in meta:
                r["timeline_removed"] = float(meta["timeline_removed"])
                r["timeline_queued"] = float(meta["timeline_queued"])
                # (entered counts the people placed at the start too)
                r["inside_at_end"] = float(meta["timeline_entered"]) - float(meta["timeline_removed"])
        out[int(seed)] = r
    return out


def scores_of(path, runs):
    by_file = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            by_file[pathlib.Path(row["run_file"]).stem] = row
    for seed, r in runs.items():
        row = by_file.get(r["run_id"])
        if row is None:
            raise guard.ScriptError(f"{path}: has no row for {r['run_id']}; expected the scores of every run of the variant")
        r["scored_avalanches"] = float(row["avalanches"])
        clog = row["clog_for_good_s"]
        r["clog_for_good_s"] = float(clog) if clog else float(row["end_s"])
        r["clogs_for_good"] = 1.0 if clog else 0.0
        r["danger_peak"] = float(row["danger_peak"])
        r["scored_peak_density"] = float(row["peak_density_per_m2"])


SCORE_COLUMNS = ("run_file", "avalanches", "clog_for_good_s", "end_s", "danger_peak", "peak_density_per_m2")


def main():
    p = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dir", type=guard.sweep_dir)
    p.add_argument("a")
    p.add_argument("b")
    p.add_argument("-o", "--out", required=True)
    p.add_argument("--metrics", default=DEFAULT_METRICS)
    p.add_argument("--scores", nargs=2, metavar=("A_CSV", "B_CSV"), type=guard.existing_file)
    guard.add_force(p)
    a = p.parse_args()
    folder = pathlib.Path(a.dir)
    metrics = [m for m in a.metrics.split(",") if m]
    variants = guard.sweep_variants(folder)
    for v in (a.a, a.b):
        if v not in variants:
            raise guard.ScriptError(f"{folder}: has no variant '{v}'; expected one of {', '.join(variants)}")
    columns = guard.table_columns(folder / "results.sqlite", "runs")
    missing = [m for m in metrics if m not in columns]
    if not metrics or missing:
        raise guard.ScriptError(f"--metrics {a.metrics}: " + (f"{', '.join(missing)} not a column of the sweep's runs table"
                                                              if missing else "no metric")
                                + "; expected columns such as mean_speed_m_per_s, max_load_n")
    for path in a.scores or []:
        guard.require_csv_columns(path, SCORE_COLUMNS, "a score table of `crowdrecon timeline --scores`")
    if a.out.endswith(("/", "\\")) or pathlib.Path(a.out).name in ("", ".", ".."):
        raise guard.ScriptError(f"-o {a.out}: names a folder; expected a name for OUT.csv and OUT.md (such as "
                                f"{a.out.rstrip('/')}/compare)")
    out = pathlib.Path(a.out)
    guard.check_outputs([
        guard.Output("-o (OUT.csv)", out.with_suffix(".csv"), "a table of sweep-ensembles.py",
                     guard.csv_starting("statistic", "seed")),
        guard.Output("-o (OUT.md)", out.with_suffix(".md"), "a table of sweep-ensembles.py",
                     guard.first_line_has(" against ", "permutation test")),
    ], guard.sweep_inputs(folder) + [("a scores table", s) for s in a.scores or []], a.force)
    ra, rb = runs_of(folder, a.a, metrics), runs_of(folder, a.b, metrics)
    if a.scores:
        scores_of(a.scores[0], ra)
        scores_of(a.scores[1], rb)
    seeds = sorted(set(ra) & set(rb))
    if len(seeds) < 3:
        raise guard.ScriptError(f"{folder}: {len(seeds)} seed(s) run in both variants; expected at least 3")
    keys = [k for k in ra[seeds[0]] if k not in ("run_id", "duration_s")]
    with guard.whole_file(out.with_suffix(".csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["statistic", "seed", a.a, a.b])
        for k in keys:
            for s in seeds:
                w.writerow([k, s, ra[s].get(k, ""), rb[s].get(k, "")])
    lines = [f"{a.a} against {a.b}, {len(seeds)} seeds each ({folder.resolve().name}); exact two-sided permutation test "
             "of the difference of the means; same when p >= 0.05.", "",
             f"| statistic | {a.a}: mean ± sd | {a.b}: mean ± sd | p | same? |", "| --- | --- | --- | --- | --- |"]
    for k in keys:
        x = [ra[s][k] for s in seeds if not math.isnan(ra[s].get(k, math.nan))]
        y = [rb[s][k] for s in seeds if not math.isnan(rb[s].get(k, math.nan))]
        if len(x) < 2 or len(y) < 2:
            lines.append(f"| {k} | — | — | — | (no values) |")
            continue
        (mx, sx), (my, sy) = mean_sd(x), mean_sd(y)
        pv = permutation_p(x, y)
        verdict = "(cost)" if k in COST else ("yes" if pv >= 0.05 else "**no**")
        note = " (never: the run's end)" if k == "clog_for_good_s" else ""
        lines.append(f"| {k}{note} | {mx:.4g} ± {sx:.2g} | {my:.4g} ± {sy:.2g} | {pv:.3f} | {verdict} |")
    guard.write_whole(out.with_suffix(".md"), "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    guard.run_main(main)
