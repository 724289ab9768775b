#!/usr/bin/env python3
"""Fixed against adaptive step as ensembles (issue 42, point 2).

A chaotic crowd diverges from any change, so the adaptive step is compared
with the fixed one as distributions over seeds, not run by run: for each
point of the hallway's phase diagram (density, counter-flow) and each seed,
the periodic Madrid Arena hallway is run with either step, and each run's
statistics are computed from its run file:

  speed_forward, speed_counter   mean velocity along each group's direction
                                 over the second half of the run (m/s)
  stopped_share                  share of person-frames below 0.1 m/s (second half)
  load_mean, load_p99            mean and 99th percentile of the chest loads (N)
  steps_per_s                    engine steps per simulated second

Per statistic, the two ensembles are compared by an exact two-sided
permutation test of the difference of their means (every split of the
2K runs into two groups of K); "same" when p >= 0.05. Writes OUT/ensembles.csv
(one row per run) and OUT/ensembles.md (the table).

usage: adaptive-step-ensembles.py CROWDRECON OUT [--seeds K] [--duration S]
       [--points 3:0.3,5:0.3,6.5:0.4] [--threads T] [--force]

Every output (OUT, OUT/runs and each file in them) is checked before any run
(scripts/script_guard.py): new, empty or a previous output of this script,
else --force (a folder is then written into, nothing in it deleted);
ensembles.csv and .md are written whole. A bad argument (a point that is not
DENSITY:COUNTER-FLOW, a count below 1) is one line, exit status 2.
"""
import argparse
import json
import math
import pathlib
import re
import sqlite3
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]  # studies/NAME/ is two levels down
sys.path.insert(0, str(ROOT / "scripts"))
from ensemble_stats import mean_sd, permutation_p  # noqa: E402
import script_guard as guard  # noqa: E402

BASE = ROOT / "venues/madrid-arena/scenarios/hallway-5pm2-30cf.json"


def scenario(density, counter, seed, mode, duration, path):
    d = json.loads(BASE.read_text())
    d["venue"] = str((BASE.parent / d["venue"]).resolve())
    d["population"]["body"]["reference"] = str((BASE.parent / d["population"]["body"]["reference"]).resolve())
    d["population"]["density_per_m2"] = density
    d["population"]["counter_flow_fraction"] = counter
    d["population"]["seed"] = seed
    d["model"]["time_step_mode"] = mode
    d["run"]["duration_s"] = duration
    d["run"]["checkpoint_interval_s"] = 0
    d["name"] = f"hallway {density}/m2 {counter} counter-flow, seed {seed}, {mode} step"
    guard.write_whole(path, json.dumps(d, indent=1))


def statistics(run, duration):
    c = sqlite3.connect(f"file:{run}?mode=ro", uri=True)
    frames = c.execute("SELECT MAX(frame) FROM frame_time").fetchone()[0]
    first = frames // 2
    groups = dict(c.execute("SELECT id, grp FROM person").fetchall())
    along = {}
    stopped = n = 0
    loads = []
    for pid, vx, vy, load in c.execute(
            "SELECT id, vel_x, vel_y, load_n FROM person_state WHERE frame >= ? AND state = 0", (first,)):
        g = groups.get(pid, 0)
        along.setdefault(g, []).append(vx)
        speed = math.hypot(vx, vy)
        stopped += speed < 0.1
        n += 1
        loads.append(load)
    loads.sort()
    keys = sorted(along)
    # The group walking towards +x is "forward" (to_exit), the other "counter".
    means = {g: sum(v) / len(v) for g, v in along.items()}
    forward = max(keys, key=lambda g: means[g])
    counter = [g for g in keys if g != forward]
    return {
        "speed_forward": means[forward],
        "speed_counter": -means[counter[0]] if counter else float("nan"),
        "stopped_share": stopped / n,
        "load_mean": sum(loads) / len(loads),
        "load_p99": loads[int(0.99 * (len(loads) - 1))],
    }


def point_list(text):
    """argparse type=: DENSITY:COUNTER-FLOW,... (density > 0 /m², counter-flow fraction 0 ... 1), none twice."""
    points = []
    for item in text.split(","):
        density, colon, counter = item.partition(":")
        try:
            point = (float(density), float(counter))
        except ValueError:
            point = None
        if not colon or point is None or not (0 < point[0] < 1e3) or not (0 <= point[1] <= 1):
            raise argparse.ArgumentTypeError(f"{item!r} is not DENSITY:COUNTER-FLOW; expected a density above 0 /m² "
                                             "and a counter-flow fraction from 0 to 1, such as 5:0.3")
        if point in points:
            raise argparse.ArgumentTypeError(f"{item!r} is given twice; expected each point once")
        points.append(point)
    return points


CSV_HEAD = "density,counter,seed,mode,"
MD_HEAD = "Fixed against adaptive step"


def main():
    p = guard.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("crowdrecon", type=guard.executable)
    p.add_argument("out")
    p.add_argument("--seeds", type=guard.positive_int, default=6)
    p.add_argument("--duration", type=guard.positive_float, default=60.0)
    p.add_argument("--points", default="3:0.3,5:0.3,6.5:0.4", type=point_list)
    p.add_argument("--threads", type=guard.positive_int, default=1)
    guard.add_force(p)
    a = p.parse_args()
    out = pathlib.Path(a.out)
    work = out / "runs"
    points = a.points
    names = [f"d{density}-c{counter}-s{seed}-{mode}" for density, counter in points
             for seed in range(1, a.seeds + 1) for mode in ("fixed", "adaptive")]
    runs_previous = guard.folder_with({"*.json": guard.is_json_with("format", "crowdrecon-scenario"),
                                       "*.sqlite": guard.is_run_file})
    outputs = [
        guard.Output("OUT", out, "a folder of adaptive-step-ensembles.py", folder=True, is_previous=guard.folder_with(
            {"ensembles.csv": guard.starts_with(CSV_HEAD), "ensembles.md": guard.starts_with(MD_HEAD),
             "runs": runs_previous})),
        guard.Output("", work, "a folder of runs of adaptive-step-ensembles.py", folder=True, is_previous=runs_previous),
        guard.Output("", out / "ensembles.csv", "a table of adaptive-step-ensembles.py", guard.starts_with(CSV_HEAD)),
        guard.Output("", out / "ensembles.md", "a table of adaptive-step-ensembles.py", guard.starts_with(MD_HEAD))]
    for name in names:
        outputs.append(guard.Output("", work / f"{name}.json", "a crowdrecon scenario",
                                    guard.is_json_with("format", "crowdrecon-scenario")))
        outputs.append(guard.Output("", work / f"{name}.sqlite", "a crowdrecon run file", guard.is_run_file))
    guard.check_outputs(outputs, [("the crowdrecon executable", a.crowdrecon), ("the scenario", BASE)], a.force)
    out.mkdir(parents=True, exist_ok=True)
    work.mkdir(exist_ok=True)
    rows = []
    started = time.time()
    for density, counter in points:
        for seed in range(1, a.seeds + 1):
            for mode in ("fixed", "adaptive"):  # interleaved
                name = f"d{density}-c{counter}-s{seed}-{mode}"
                sc = work / f"{name}.json"
                run = work / f"{name}.sqlite"
                scenario(density, counter, seed, mode, a.duration, sc)
                t0 = time.time()
                r = subprocess.run([a.crowdrecon, "simulate", str(sc), "-o", str(run), "--force",
                                    "--threads", str(a.threads)], capture_output=True, text=True)
                wall = time.time() - t0
                if r.returncode != 0:
                    sys.exit(f"{name}: exit {r.returncode}\n{r.stderr}")  # (the run's own message, several lines)
                text = r.stdout + r.stderr
                st = statistics(run, a.duration)
                m = re.search(r"adaptive step: (.*?); mean step ([0-9.]+) h", text)
                step_mean_h = float(m.group(2)) if m else 1.0
                row = {"density": density, "counter": counter, "seed": seed, "mode": mode, "wall_s": wall,
                       "mean_step_h": step_mean_h, **st}
                rows.append(row)
                print(json.dumps(row), flush=True)
                run.unlink()
    keys = ["speed_forward", "speed_counter", "stopped_share", "load_mean", "load_p99", "mean_step_h", "wall_s"]
    with guard.whole_file(out / "ensembles.csv", "w") as f:
        cols = ["density", "counter", "seed", "mode"] + keys
        f.write(",".join(cols) + "\n")
        for r in rows:
            f.write(",".join(str(r[c]) for c in cols) + "\n")
    lines = [f"Fixed against adaptive step, {a.seeds} seeds per point and step, {a.duration:g} s runs, "
             f"statistics over the second half; exact two-sided permutation test of the difference of means. "
             f"Wall time of the whole check: {time.time() - started:.0f} s.", "",
             "| point | statistic | fixed: mean ± sd | adaptive: mean ± sd | p | same? |",
             "| --- | --- | --- | --- | --- | --- |"]
    for density, counter in points:
        for key in keys:
            fx = [r[key] for r in rows if r["density"] == density and r["counter"] == counter and r["mode"] == "fixed"]
            ad = [r[key] for r in rows if r["density"] == density and r["counter"] == counter and r["mode"] == "adaptive"]
            (mf, sf), (ma, sa) = mean_sd(fx), mean_sd(ad)
            pv = permutation_p(fx, ad)
            judged = key not in ("mean_step_h", "wall_s")
            lines.append(f"| {density:g} /m², {counter:g} | {key} | {mf:.4g} ± {sf:.2g} | {ma:.4g} ± {sa:.2g} | "
                         f"{pv:.3f} | {('yes' if pv >= 0.05 else '**no**') if judged else '(cost)'} |")
    guard.write_whole(out / "ensembles.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    guard.run_main(main)
