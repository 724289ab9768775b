#!/usr/bin/env python3
"""The open-decision study of issue 19: a table of point x decision x seed ->
verdict, per-direction verdicts and the avalanche statistics, from the results
of the sweep studies/open-decisions/hallway-decisions.json, and the check
of the early-stop criteria (`crowdrecon analyze RUN --settle-check`) on every
kept run (simulated to its full length).

usage: decision_study.py CROWDRECON SWEEP_DIR OUT_DIR [--force]
  SWEEP_DIR  the sweep's output folder (results.csv, runs/ kept)
  OUT_DIR    where study.md and settle_check.csv are written (settle_check.csv
             is read again: the runs it holds are not checked again)

Before any work (scripts/script_guard.py): CROWDRECON must be a program,
SWEEP_DIR a sweep folder whose results.csv has the columns read and whose
complete runs are kept; OUT_DIR must be new, empty or a folder holding a
previous study.md or settle_check.csv (else --force, which writes into it and
deletes nothing), and its two files new or previous outputs, never the
sweep's own files; both are written whole. A bad argument is one line, exit 2.

Regenerate:
  crowdrecon sweep studies/open-decisions/hallway-decisions.json -o /tmp/dec --jobs 2
  python3 studies/open-decisions/decision_study.py build/release/cli/crowdrecon /tmp/dec studies/open-decisions/results
"""
import csv
import math
import os
import re
import subprocess
import sys
from collections import OrderedDict

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # studies/NAME/ is two levels down
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import script_guard as guard  # noqa: E402

REGIME = {0: "lanes", 1: "avalanches", 2: "clogging", 3: "unclassified"}
SHORT = {"lanes": "L", "avalanches": "A", "clogging": "C", "unclassified": "U"}


def number(row, key):
    v = row.get(key, "")
    return float(v) if v not in ("", None) else math.nan


def settle_check(exe, run_file):
    proc = subprocess.run([exe, "analyze", run_file, "--settle-check"], capture_output=True, text=True)
    if proc.returncode != 0:
        said = (proc.stderr.strip() or proc.stdout.strip() or "nothing").splitlines()[-1]
        raise guard.ScriptError(f"{run_file}: `{exe} analyze --settle-check` exited {proc.returncode} ({said}); "
                                "expected a run file crowdrecon can analyse")
    out = proc.stdout
    lines = [l for l in out.splitlines() if l.startswith("settle check:")]
    if any("does not settle" in l for l in lines):
        return {"settles": "no", "stop_s": "", "kind": "", "verdict_at_stop": "", "same": ""}
    first = lines[0]
    m = re.search(r"settled (frozen|in lanes) at ([0-9.]+) s", first)
    m2 = re.search(r"verdict at the stop (\w+) .* of the whole run (\w+) .*: (same|DIFFERENT)", lines[-1])
    return {"settles": "yes", "stop_s": m.group(2), "kind": "frozen" if m.group(1) == "frozen" else "lanes",
            "verdict_at_stop": m2.group(1), "same": m2.group(3)}


COLUMNS = ("run_id", "variant", "seed", "status", "regime", "population.density_per_m2",
           "population.counter_flow_fraction", "wall_s")
CHECKS_HEAD = "run_id,settles,stop_s,kind,verdict_at_stop,same"
STUDY_HEAD = "# Issue 19: the model's open decisions"


def main():
    p = guard.ArgumentParser(description=__doc__.strip().splitlines()[0])
    p.add_argument("crowdrecon", type=guard.executable)
    p.add_argument("sweep_dir", type=guard.sweep_dir_csv)
    p.add_argument("out_dir")
    guard.add_force(p)
    args = p.parse_args()
    exe, sweep_dir, out_dir = args.crowdrecon, args.sweep_dir, args.out_dir
    expected = "the sweep of studies/open-decisions/hallway-decisions.json (results.csv and its kept runs)"
    guard.require_csv_columns(os.path.join(sweep_dir, "results.csv"), COLUMNS, expected)
    rows = list(csv.DictReader(open(os.path.join(sweep_dir, "results.csv"))))
    if not rows:
        raise guard.ScriptError(f"{sweep_dir}: its results.csv holds no runs; expected {expected}")
    files = {"study.md": guard.starts_with(STUDY_HEAD), "settle_check.csv": guard.starts_with(CHECKS_HEAD)}
    guard.check_outputs(
        [guard.Output("OUT_DIR", out_dir, "a folder of decision_study.py", folder=True, is_previous=guard.folder_with(files))]
        + [guard.Output("", os.path.join(out_dir, name), f"a {name} of decision_study.py", check)
           for name, check in files.items()],
        guard.sweep_inputs(sweep_dir) + [("the crowdrecon executable", exe)], args.force)
    checks_file = os.path.join(out_dir, "settle_check.csv")
    if os.path.exists(checks_file) and os.path.getsize(checks_file) > 0:
        guard.require_csv_columns(checks_file, CHECKS_HEAD.split(","), "a settle_check.csv of decision_study.py")
    done = set()
    if os.path.exists(checks_file):
        done = {c["run_id"] for c in csv.DictReader(open(checks_file))}
    for r in rows:
        run_file = os.path.join(sweep_dir, "runs", r["run_id"] + ".sqlite")
        if r["status"] == "complete" and r["run_id"] not in done and not os.path.exists(run_file):
            raise guard.ScriptError(f"{run_file}: missing; expected {expected}")
    os.makedirs(out_dir, exist_ok=True)
    checks = {}
    if os.path.exists(checks_file):
        for c in csv.DictReader(open(checks_file)):
            checks[c["run_id"]] = c
    fields = ["run_id", "settles", "stop_s", "kind", "verdict_at_stop", "same"]

    def save():
        with guard.whole_file(checks_file, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            for r in rows:
                if r["run_id"] in checks:
                    w.writerow({k: checks[r["run_id"]][k] for k in fields})

    for r in rows:
        if r["run_id"] in checks:
            continue
        if r["status"] != "complete":  # no run file: e.g. a crowd that cannot be placed
            checks[r["run_id"]] = {"run_id": r["run_id"], "settles": "failed", "stop_s": "", "kind": "",
                                   "verdict_at_stop": "", "same": ""}
            continue
        run_file = os.path.join(sweep_dir, "runs", r["run_id"] + ".sqlite")
        c = settle_check(exe, run_file)
        c["run_id"] = r["run_id"]
        checks[r["run_id"]] = c
        save()
        print(r["run_id"], c, flush=True)
    save()

    variants = list(OrderedDict.fromkeys(r["variant"] for r in rows))
    points = sorted({(float(r["population.density_per_m2"]), float(r["population.counter_flow_fraction"])) for r in rows})
    md = ["# Issue 19: the model's open decisions at three points of the hallway diagram", "",
          "Generated by `studies/open-decisions/decision_study.py` from the sweep "
          "`studies/open-decisions/hallway-decisions.json` (240 s runs, full length, 10 frames/s; "
          "classifier version 2). Each cell: the verdicts of seeds 1, 2, 3 "
          "(L lanes, A avalanches, C clogging, U unclassified, F failed: the crowd could not be placed), then per seed the verdicts of the main flow / "
          "counter-flow, the avalanches of the whole run (crowd's series), the stationary avalanches per "
          "direction, the mean rise time of the crowd's avalanches, and the lapse-tail exponent of each "
          "direction's passages (n/a: fewer than 10 lapses of 1 s or more).", ""]
    md.append("| decision | " + " | ".join(f"{d:g} /m², {cf:.0%}" for d, cf in points) + " |")
    md.append("|---|" + "---|" * len(points))
    detail = ["", "## Per run", "",
              "| decision | density | seed | verdict | main / counter | avalanches (run) | stationary avalanches main / counter | "
              "rise time (s) | tail α main | tail α counter | clogged fraction main / counter | "
              "end speed main / counter (m/s) | would settle at | verdict then = whole run |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for v in variants:
        cells = []
        for d, cf in points:
            sel = sorted([r for r in rows if r["variant"] == v and float(r["population.density_per_m2"]) == d
                          and float(r["population.counter_flow_fraction"]) == cf], key=lambda r: int(r["seed"]))
            cells.append(" ".join(SHORT.get(r["regime"], "F") for r in sel))
            for r in sel:
                c = checks[r["run_id"]]
                if r["status"] != "complete":
                    detail.append(f"| {v} | {d:g} | {r['seed']} | failed: {r['status'][8:].split(': ', 2)[-1]} |" + " |" * 10)
                    continue
                g = [REGIME.get(int(number(r, f"regime_code_g{k}")), "-") if not math.isnan(number(r, f"regime_code_g{k}")) else "-"
                     for k in (0, 1)]
                tail = []
                for k in (0, 1):
                    a, e = number(r, f"lapse_tail_exponent_g{k}"), number(r, f"lapse_tail_exponent_error_g{k}")
                    tail.append("n/a" if math.isnan(a) else f"{a:.2f} ± {e:.2f}")
                rise = number(r, "avalanche_mean_rise_time_s")
                detail.append(
                    f"| {v} | {d:g} | {r['seed']} | {r['regime']} | {SHORT.get(g[0], '-')} / {SHORT.get(g[1], '-')} | "
                    f"{int(number(r, 'avalanche_count_all'))} | {number(r, 'avalanche_count_g0'):.0f} / {number(r, 'avalanche_count_g1'):.0f} | "
                    f"{'' if number(r, 'avalanche_count') == 0 else f'{rise:.2f}'} | {tail[0]} | {tail[1]} | "
                    f"{number(r, 'clogged_fraction_g0'):.2f} / {number(r, 'clogged_fraction_g1'):.2f} | "
                    f"{number(r, 'end_mean_speed_g0_m_per_s'):.3f} / {number(r, 'end_mean_speed_g1_m_per_s'):.3f} | "
                    f"{(c['stop_s'] + ' s (' + c['kind'] + ')') if c['settles'] == 'yes' else 'no'} | "
                    f"{c['same'] if c['settles'] == 'yes' else ''} |")
        md.append(f"| {v} | " + " | ".join(cells) + " |")
    settled = [c for c in checks.values() if c["settles"] == "yes"]
    same = [c for c in settled if c["same"] == "same"]
    complete = [r for r in rows if r["status"] == "complete"]
    unsettled = [r for r in complete if checks[r["run_id"]]["settles"] == "no"]
    md += ["", f"Early-stop check (`analyze --settle-check`, default options) on the {len(complete)} complete "
           f"full-length runs (of {len(rows)}): "
           f"{len(settled)} would have stopped early ({sum(1 for c in settled if c['kind'] == 'frozen')} frozen, "
           f"{sum(1 for c in settled if c['kind'] == 'lanes')} in lanes), and the verdict at the stop equals the "
           f"240 s verdict in {len(same)} of them. The {len(unsettled)} that run to 240 s: " +
           ", ".join(f"{r['variant']} {float(r['population.density_per_m2']):g} /m² seed {r['seed']} ({r['regime']})"
                     for r in unsettled) + "."]
    if settled:
        stops = sorted(float(c["stop_s"]) for c in settled)
        md.append(f"Stop times: median {stops[len(stops) // 2]:.1f} s, range {stops[0]:.1f}–{stops[-1]:.1f} s.")
    walls = [number(r, "wall_s") for r in rows if r["status"] == "complete"]
    md.append(f"Wall time of the sweep's runs: {sum(walls) / 60:.1f} min of run time in all "
              f"(one thread per run, two runs at a time).")
    guard.write_whole(os.path.join(out_dir, "study.md"), "\n".join(md + detail) + "\n")
    print("\n".join(md))


if __name__ == "__main__":
    guard.run_main(main)
