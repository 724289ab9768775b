#!/usr/bin/env python3
"""The whole Madrid night with sleeping against the full integration (issue 66, point 3).

Reads the ensemble summaries (`crowdrecon timeline --summaries`, the sweep's
`ensemble_summaries`) of the nights run with sleeping and of the nights of
studies/night-full-ensemble (the full integration, the same scenario, the
same seeds among them) and the two sweeps' result tables (their wall
times); writes a Markdown table, one row per seed, and per statistic the two
ensembles' mean ± sd and the exact two-sided permutation test of the
difference of their means (scripts/ensemble_stats.py; "same" where p >= 0.05).

usage: compare-nights.py SLEEPING_SUMMARIES_DIR SLEEPING_RESULTS_CSV FULL_SUMMARIES_DIR FULL_RESULTS_CSV -o OUT.md [--force]

OUT.md is written whole (scripts/script_guard.py): never one of the inputs,
never a file that is not a previous output of this script unless --force.
Standard library only.
"""
import argparse
import csv
import json
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "scripts"))
from ensemble_stats import mean_sd, permutation_p  # noqa: E402
import script_guard as guard  # noqa: E402

FIRST_LINE = "The whole Madrid night (02:00-03:35), the paper's model with the adaptive step: with sleeping"


def clock(t, start_h=2):
    if t is None:
        return "never"
    t = int(round(t))
    return f"{start_h + t // 3600:02d}:{t % 3600 // 60:02d}:{t % 60:02d}"


def load(summaries_dir, results_csv):
    """seed -> {clog_s, danger, peak, avalanches, falls, wall_s}."""
    guard.require_csv_columns(results_csv, ["seed", "status", "wall_s"], "a sweep's results.csv")
    walls = {}
    with open(results_csv, newline="") as f:
        for row in csv.DictReader(f):
            if row.get("status") == "complete":
                try:
                    walls[int(row["seed"])] = float(row["wall_s"])
                except ValueError:
                    raise guard.ScriptError(f"{results_csv}: a complete run with seed {row['seed']!r} and wall_s "
                                            f"{row['wall_s']!r}; expected numbers") from None
    runs = {}
    for path in sorted(pathlib.Path(summaries_dir).glob("*.json")):
        d = guard.read_json_file(path, "an ensemble summary of `crowdrecon timeline --summaries`")
        if not isinstance(d, dict):
            raise guard.ScriptError(f"{path}: not a JSON object; expected an ensemble summary of `crowdrecon timeline --summaries`")
        missing = [k for k in ("seed", "clog_for_good_s", "end_s", "danger_peak", "peak_density_per_m2", "avalanche_s",
                               "fall_s") if k not in d]
        if missing:
            raise guard.ScriptError(f"{path}: has no {', '.join(missing)}; expected an ensemble summary of "
                                    "`crowdrecon timeline --summaries`")
        seed = int(d["seed"])
        runs[seed] = {
            "clog_s": d["clog_for_good_s"],
            "end_s": d["end_s"],
            "danger": d["danger_peak"],
            "peak": d["peak_density_per_m2"],
            "avalanches": len(d["avalanche_s"]),
            "falls": len(d["fall_s"]),
            "wall_s": walls.get(seed),
        }
    if not runs:
        raise guard.ScriptError(f"{summaries_dir}: no summaries (*.json); expected a sweep's summaries folder")
    return runs


def main():
    ap = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sleeping_summaries", type=guard.existing_dir)
    ap.add_argument("sleeping_results", type=guard.existing_file)
    ap.add_argument("full_summaries", type=guard.existing_dir)
    ap.add_argument("full_results", type=guard.existing_file)
    ap.add_argument("-o", "--out", required=True)
    guard.add_force(ap)
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    guard.check_outputs([guard.Output("-o", out, "a table of compare-nights.py", guard.first_line_has(FIRST_LINE))],
                        [("a results table", a.sleeping_results), ("a results table", a.full_results)], a.force)
    sleeping = load(a.sleeping_summaries, a.sleeping_results)
    full = load(a.full_summaries, a.full_results)
    lines = [FIRST_LINE + " (2 mm/s over 1 s, wake at 20 N) against the full integration (studies/night-full-ensemble). "
             "A night that never clogs for good counts at its end in the mean.", "",
             "| seed | clog for good: full | sleeping | danger peak: full | sleeping | peak density: full | sleeping "
             "| avalanches: full | sleeping | wall s: full | sleeping |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for seed in sorted(sleeping):
        s, f = sleeping[seed], full.get(seed)
        if f is None:
            continue
        wall = lambda r: "" if r["wall_s"] is None else f"{r['wall_s']:.0f}"  # noqa: E731
        lines.append(f"| {seed} | {clock(f['clog_s'])} | {clock(s['clog_s'])} | {f['danger']} | {s['danger']} "
                     f"| {f['peak']:g} | {s['peak']:g} | {f['avalanches']} | {s['avalanches']} | {wall(f)} | {wall(s)} |")
    lines += ["", f"Ensembles: full {len(full)} nights (seeds {', '.join(map(str, sorted(full)))}), sleeping "
              f"{len(sleeping)} (seeds {', '.join(map(str, sorted(sleeping)))}); exact two-sided permutation test "
              "of the difference of the means.", "",
              "| statistic | full: mean ± sd | sleeping: mean ± sd | p | same? |", "| --- | --- | --- | --- | --- |"]
    stats = [("clog for good (s after 02:00; never: the end)", lambda r: r["clog_s"] if r["clog_s"] is not None else r["end_s"]),
             ("danger peak (people)", lambda r: r["danger"]),
             ("peak density (model /m²)", lambda r: r["peak"]),
             ("avalanches", lambda r: r["avalanches"]),
             ("falls", lambda r: r["falls"])]
    for name, get in stats:
        x = [get(r) for r in full.values()]
        y = [get(r) for r in sleeping.values()]
        (mx, sx), (my, sy) = mean_sd(x), mean_sd(y)
        p = permutation_p(y, x)
        lines.append(f"| {name} | {mx:.4g} ± {sx:.2g} | {my:.4g} ± {sy:.2g} | {p:.3f} | {'yes' if p >= 0.05 else '**no**'} |")
    guard.write_whole(out, "\n".join(lines) + "\n")
    print(f"compare-nights.py: wrote {out}")


if __name__ == "__main__":
    guard.run_main(main)
