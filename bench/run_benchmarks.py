#!/usr/bin/env python3
"""Whole-run and kernel benchmarks of crowdrecon (bench/README.md).

Whole runs (default): for each scenario and thread count, runs
    crowdrecon simulate SCENARIO -o TMP.sqlite --threads T -q
under /usr/bin/time -v, REPEAT times, and reports the medians of
  * agent-steps/s = people x steps / seconds, with three denominators:
      engine  the engine's own stage timers (Step() only),
      loop    the run loop's wall time from the summary: stepping plus writing
              every frame (with contacts) to the run file,
      process the whole process: start-up, world building (placement and its
              relaxation), the run loop and closing the file;
  * the real-time factor (simulated / loop wall seconds, as printed);
  * peak resident memory (with contact output at the scenario's frame rate);
  * the engine's stage percentages.
Tables go to stdout and to bench/RESULTS.md; raw results to a JSON file.

Kernels (--kernels): runs crowdrecon_bench_kernels with
--benchmark_repetitions=REPEAT and tabulates the medians.

Examples:
  python3 bench/run_benchmarks.py --label before
  python3 bench/run_benchmarks.py --scenarios hallway-400 --threads 1 --repeat 1 --duration 0.5 \\
      --exe build/ha/cli/crowdrecon --label smoke
  python3 bench/run_benchmarks.py --kernels --label before
  python3 bench/run_benchmarks.py --scenarios box-10000 --steady-from 4 --duration 2 --label "developed crowd"
"""

import argparse
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import bench_common as bc  # noqa: E402

DEFAULT_SCENARIOS = ["hallway-400", "box-2000", "box-10000"]
STAGES = ["pairs", "shapes", "collide", "gather", "drive", "integrate", "check"]
TIME = "/usr/bin/time"


def scenario_path(name):
    p = pathlib.Path(name)
    if p.suffix == ".json" and p.exists():
        return p.resolve()
    candidate = bc.BENCH / "scenarios" / f"{name}.json"
    if candidate.exists():
        return candidate
    bc.fail(f"{name}: no such scenario (expected a file or a name under bench/scenarios/)")


def scenario_copy(source, duration, folder):
    """The scenario with run.duration_s replaced, written to `folder`, with its
    relative paths (venue, bodies) made absolute so that they still resolve."""
    data = json.loads(source.read_text())
    base = source.parent
    if "venue" in data and not pathlib.Path(data["venue"]).is_absolute():
        data["venue"] = str((base / data["venue"]).resolve())
    body = data.get("population", {}).get("body", {})
    for key in ("reference", "anthropometry"):
        if key in body and not pathlib.Path(body[key]).is_absolute():
            body[key] = str((base / body[key]).resolve())
    data.setdefault("run", {})["duration_s"] = duration
    target = pathlib.Path(folder) / source.name
    target.write_text(json.dumps(data, indent=2))
    return target


def parse_elapsed(text):
    """'1:02:03' or '2:03.45' -> seconds."""
    parts = [float(p) for p in text.split(":")]
    seconds = 0.0
    for p in parts:
        seconds = seconds * 60 + p
    return seconds


def parse_summary(stdout):
    out = {}
    m = re.search(r"people: (\d+), time step ([0-9.eE+-]+) s, (\d+) thread", stdout)
    if not m:
        raise ValueError("no 'people: ...' line in the summary")
    out["people"], out["time_step_s"], out["threads"] = int(m[1]), float(m[2]), int(m[3])
    m = re.search(r"simulated: (?:from [0-9.]+ to )?([0-9.]+) s in ([0-9.]+) s wall \(real-time factor ([0-9.eE+-]+)\)", stdout)
    if not m:
        raise ValueError("no 'simulated: ...' line in the summary")
    out["simulated_s"], out["loop_wall_s"], out["real_time_factor"] = float(m[1]), float(m[2]), float(m[3])
    m = re.search(r"\((\d+) frames\), status (\S+)", stdout)
    if m:
        out["frames"], out["status"] = int(m[1]), m[2]
    m = re.search(r"engine time ([0-9.]+) s: (.*)", stdout)
    if m:
        out["engine_s"] = float(m[1])
        out["stages_percent"] = {name: float(v) for name, v in re.findall(r"(\w+) ([0-9.]+) %", m[2])}
        r = re.search(r"\((\d+) rebuilds\)", m[2])
        out["pair_rebuilds"] = int(r[1]) if r else None
    # The adaptive step (model.time_step_mode) says how many steps of each
    # length it took; the fixed step takes simulated / time step.
    m = re.search(r"adaptive step: (.*?); mean step", stdout)
    if m:
        out["steps"] = sum(int(n) for n in re.findall(r"(\d+) steps", m[1]))
    return out


def parse_time_v(text):
    out = {}
    for key, pattern, conv in (("process_wall_s", r"Elapsed \(wall clock\) time.*?\): (\S+)", parse_elapsed),
                               ("max_rss_kib", r"Maximum resident set size \(kbytes\): (\d+)", int),
                               ("user_s", r"User time \(seconds\): ([0-9.]+)", float),
                               ("system_s", r"System time \(seconds\): ([0-9.]+)", float),
                               ("cpu_percent", r"Percent of CPU this job got: (\d+)%", int)):
        m = re.search(pattern, text)
        out[key] = conv(m[1]) if m else None
    return out


_FIXED_THREADS = {}


def fixed_threads_option(exe):
    """["--fixed-threads"] where this build has the thread governor (whose
    adaptation would blur a measurement of two-thread scaling), else []."""
    if exe not in _FIXED_THREADS:
        help_text = subprocess.run([str(exe), "simulate", "--help"], capture_output=True, text=True).stdout
        _FIXED_THREADS[exe] = ["--fixed-threads"] if "--fixed-threads" in help_text else []
    return _FIXED_THREADS[exe]


def run_once(exe, scenario, threads, workdir, device="cpu"):
    run_file = pathlib.Path(workdir) / "run.sqlite"
    time_file = pathlib.Path(workdir) / "time.txt"
    for stale in (run_file, pathlib.Path(str(run_file) + ".checkpoint")):
        stale.unlink(missing_ok=True)
    cmd = [TIME, "-v", "-o", str(time_file), str(exe), "simulate", str(scenario), "-o", str(run_file),
           "--threads", str(threads), "-q"] + fixed_threads_option(exe)
    if device != "cpu":
        cmd += ["--device", device]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=bc.ROOT)
    if proc.returncode != 0:
        bc.fail(f"{' '.join(cmd)} failed with status {proc.returncode}:\n{proc.stdout}{proc.stderr}")
    result = parse_summary(proc.stdout)
    result.update(parse_time_v(time_file.read_text()))
    result.setdefault("steps", round(result["simulated_s"] / result["time_step_s"]))
    agent_steps = result["people"] * result["steps"]
    result["agent_steps"] = agent_steps
    for key, seconds in (("engine", result.get("engine_s")), ("loop", result["loop_wall_s"]),
                         ("process", result["process_wall_s"])):
        result[f"agent_steps_per_s_{key}"] = agent_steps / seconds if seconds else None
    result["setup_s"] = (result["process_wall_s"] - result["loop_wall_s"]) if result["process_wall_s"] else None
    for stale in (run_file, pathlib.Path(str(run_file) + ".checkpoint")):
        stale.unlink(missing_ok=True)
    return result


def steady_difference(first, whole):
    """The part of run `whole` after run `first` (the same scenario and seed,
    shorter): results are deterministic, so the first part is identical work
    in both, and differences of the times measure the rest alone."""
    out = {"people": whole["people"], "time_step_s": whole["time_step_s"], "threads": whole["threads"],
           "status": whole.get("status"), "max_rss_kib": whole.get("max_rss_kib"),
           "cpu_percent": whole.get("cpu_percent"), "stages_percent": whole.get("stages_percent", {}),
           "first": first, "whole": whole}
    for key in ("simulated_s", "loop_wall_s", "engine_s", "steps", "frames", "pair_rebuilds"):
        a, b = first.get(key), whole.get(key)
        out[key] = (b - a) if a is not None and b is not None else None
    agent_steps = out["people"] * out["steps"]
    out["agent_steps"] = agent_steps
    for key, seconds in (("engine", out["engine_s"]), ("loop", out["loop_wall_s"])):
        out[f"agent_steps_per_s_{key}"] = agent_steps / seconds if seconds and seconds > 0 else None
    # Start-up and world building are not part of the difference.
    out["process_wall_s"] = out["agent_steps_per_s_process"] = None
    out["real_time_factor"] = out["simulated_s"] / out["loop_wall_s"] if out["loop_wall_s"] and out["loop_wall_s"] > 0 else None
    out["setup_s"] = None
    return out


def summarise_runs(runs):
    keys = ["agent_steps_per_s_engine", "agent_steps_per_s_loop", "agent_steps_per_s_process", "real_time_factor",
            "engine_s", "loop_wall_s", "process_wall_s", "setup_s", "max_rss_kib", "cpu_percent"]
    s = {k: bc.median([r.get(k) for r in runs]) for k in keys}
    s["spread_engine"] = bc.spread([r.get("agent_steps_per_s_engine") for r in runs])
    s["stages_percent"] = {st: bc.median([r.get("stages_percent", {}).get(st) for r in runs]) for st in STAGES}
    for k in ("people", "steps", "time_step_s", "simulated_s", "frames", "pair_rebuilds"):
        s[k] = runs[0].get(k)
    return s


def whole_runs(args):
    exe = pathlib.Path(args.exe)
    if not exe.is_absolute():
        exe = bc.ROOT / exe
    if not exe.exists():
        bc.fail(f"{exe}: not found; build it (cmake --build --preset release) or give --exe")
    if not os.access(TIME, os.X_OK):
        bc.fail(f"{TIME} not found: install the Debian package 'time' (scripts/install-deps.sh)")
    scenarios = [(name, scenario_path(name)) for name in args.scenarios.split(",") if name]
    threads = [int(t) for t in args.threads.split(",") if t]
    started = bc.now()
    load_before = bc.warn_if_busy()
    results = []
    with tempfile.TemporaryDirectory(prefix="crowdrecon-bench-", dir=args.tmpdir) as work:
        for name, path in scenarios:
            if args.steady_from is not None:
                # Two copies: up to --steady-from, and --duration beyond it.
                folders = [pathlib.Path(work) / "first", pathlib.Path(work) / "whole"]
                for folder in folders:
                    folder.mkdir(exist_ok=True)
                first = scenario_copy(path, args.steady_from, folders[0])
                scenario = scenario_copy(path, args.steady_from + args.duration, folders[1])
            else:
                scenario = scenario_copy(path, args.duration, work) if args.duration is not None else path
            for t in threads:
                runs = []
                for rep in range(args.repeat):
                    if args.steady_from is not None:
                        r = steady_difference(run_once(exe, first, t, work, args.device),
                                              run_once(exe, scenario, t, work, args.device))
                    else:
                        r = run_once(exe, scenario, t, work, args.device)
                    runs.append(r)
                    print(f"  {name:>12} threads {t} run {rep + 1}/{args.repeat}: {r['people']} people, "
                          f"{r['steps']} steps, engine {bc.si(r['agent_steps_per_s_engine'])} agent-steps/s, "
                          f"real-time factor {r['real_time_factor']:.3f}, peak {r['max_rss_kib'] / 1024:.0f} MiB",
                          file=sys.stderr)
                results.append({"scenario": name, "scenario_file": str(path), "threads": t, "runs": runs,
                                "median": summarise_runs(runs)})
    load_after = bc.load_average()
    rows = []
    for r in results:
        m = r["median"]
        stages = "/".join("–" if m["stages_percent"][s] is None else f"{m['stages_percent'][s]:.0f}" for s in STAGES)
        rows.append([r["scenario"], m["people"], r["threads"], m["steps"], bc.si(m["agent_steps_per_s_engine"]),
                     bc.percent(m["spread_engine"]), bc.si(m["agent_steps_per_s_loop"]),
                     bc.si(m["agent_steps_per_s_process"]), f"{m['real_time_factor']:.3f}",
                     bc.fixed(m["loop_wall_s"]), bc.fixed(m["process_wall_s"]),
                     bc.fixed(m["max_rss_kib"] / 1024 if m["max_rss_kib"] else None, 0), stages])
    header = ["scenario", "people", "threads", "steps", "agent-steps/s engine", "spread", "agent-steps/s loop",
              "agent-steps/s process", "real-time factor", "loop s", "process s", "peak RSS MiB",
              "stages % " + "/".join(STAGES)]
    table = bc.markdown_table(header, rows)
    notes = [f"- medians of {args.repeat} run(s); spread = (max - min) / median of the engine rate",
             "- agent-steps/s = people x steps / seconds: *engine* = the engine's stage timers (Step() only); "
             "*loop* = the run loop's wall time (steps + writing every frame with contacts); *process* = "
             "the whole `crowdrecon simulate` process (start-up, world building, run loop); real-time factor = "
             "simulated / loop seconds; peak RSS from `/usr/bin/time -v`"]
    if args.steady_from is not None:
        notes.append(f"- steady state: every figure is the difference between a run of {args.steady_from + args.duration} s "
                     f"and one of {args.steady_from} s (same scenario and seed: the first {args.steady_from} s are the "
                     f"same work in both), i.e. the {args.duration} s after {args.steady_from} s of walking, when "
                     "contacts have built up; stages % and peak RSS are those of the longer run")
    elif args.duration is not None:
        notes.append(f"- run.duration_s overridden to {args.duration} s")
    return results, table, notes, started, load_before, load_after


def kernels(args):
    exe = pathlib.Path(args.kernels_exe)
    if not exe.is_absolute():
        exe = bc.ROOT / exe
    if not exe.exists():
        bc.fail(f"{exe}: not found; build the release preset with libbenchmark-dev installed, or give --kernels-exe")
    started = bc.now()
    load_before = bc.warn_if_busy()
    cmd = [str(exe), f"--benchmark_repetitions={args.repeat}", "--benchmark_format=json"]
    if args.filter:
        cmd.append(f"--benchmark_filter={args.filter}")
    if args.min_time:
        cmd.append(f"--benchmark_min_time={args.min_time}")
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=bc.ROOT)
    if proc.returncode != 0:
        bc.fail(f"{' '.join(cmd)} failed with status {proc.returncode}:\n{proc.stderr}")
    data = json.loads(proc.stdout)
    load_after = bc.load_average()
    groups = {}
    for b in data["benchmarks"]:
        if b.get("run_type") == "iteration":
            groups.setdefault(b.get("run_name", b["name"]), []).append(b)
    rows = []
    summary = []
    for name, runs in groups.items():
        if any(r.get("error_occurred") for r in runs):
            rows.append([name, "error: " + runs[0].get("error_message", "?"), "", "", ""])
            continue
        unit = runs[0].get("time_unit", "ns")
        t = bc.median([r["real_time"] for r in runs])
        items = bc.median([r.get("items_per_second") for r in runs])
        counters = {k: bc.median([r.get(k) for r in runs]) for k in ("people", "pairs", "contacts", "centre_distance_m")
                    if k in runs[0]}
        summary.append({"name": name, "time": t, "time_unit": unit, "items_per_second": items,
                        "spread_time": bc.spread([r["real_time"] for r in runs]), "counters": counters})
        rows.append([name.replace("/real_time", ""), f"{t:.4g} {unit}", bc.si(items), bc.percent(bc.spread([r["real_time"] for r in runs])),
                     ", ".join(f"{k} {v:.4g}" for k, v in counters.items())])
    table = bc.markdown_table(["benchmark", "time (median)", "items/s", "spread", "counters"], rows)
    notes = [f"- medians of {args.repeat} repetition(s) (Google Benchmark, wall-clock time); spread = (max - min) / "
             "median of the time",
             "- items/s: Step = agent-steps/s (people x steps), NeighbourRebuild = people/s, NarrowPhase = shape pairs/s",
             f"- library build type reported by Google Benchmark: {data.get('context', {}).get('library_build_type', '?')}"
             " (Debian's package says 'debug'; the benchmarks themselves are built as Release)"]
    return {"context": data.get("context"), "summary": summary, "raw": data["benchmarks"]}, table, notes, started, \
        load_before, load_after


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenarios", default=",".join(DEFAULT_SCENARIOS),
                   help="comma-separated names under bench/scenarios/ or scenario files (default: %(default)s)")
    p.add_argument("--threads", default="1,2", help="comma-separated thread counts (default: %(default)s)")
    p.add_argument("--device", default="cpu", choices=["cpu", "cuda"],
                   help="where person-pair forces are computed (simulate --device; default: %(default)s)")
    p.add_argument("--repeat", type=int, default=3, help="repetitions; medians are reported (default: %(default)s)")
    p.add_argument("--duration", type=float, help="override run.duration_s (simulated seconds) of every scenario")
    p.add_argument("--steady-from", type=float, metavar="S",
                   help="measure a developed crowd: the --duration seconds (default 2) after S seconds of walking, "
                        "as the difference of runs of S + duration and S seconds")
    p.add_argument("--label", default="", help='what the measurement is, e.g. "before narrow-phase optimisation"; '
                   "a later run with the same label replaces its section of bench/RESULTS.md")
    p.add_argument("--exe", default="build/release/cli/crowdrecon", help="crowdrecon program (default: %(default)s)")
    p.add_argument("--tmpdir", help="folder for the temporary run files (default: the system's)")
    p.add_argument("--kernels", action="store_true", help="run the kernel benchmarks instead of whole runs")
    p.add_argument("--kernels-exe", default="build/release/bench/crowdrecon_bench_kernels",
                   help="kernel benchmark program (default: %(default)s)")
    p.add_argument("--filter", help="--kernels: Google Benchmark filter (regular expression)")
    p.add_argument("--min-time", help="--kernels: --benchmark_min_time (seconds per benchmark)")
    p.add_argument("--json", help="raw results file (default: results/bench/DATE-KIND[-LABEL].json)")
    p.add_argument("--no-results-md", action="store_true", help="do not write bench/RESULTS.md")
    args = p.parse_args()
    if args.repeat < 1:
        bc.fail("--repeat must be at least 1")
    if args.duration is not None and args.duration <= 0:
        bc.fail("--duration must be positive")
    if args.steady_from is not None:
        if args.steady_from <= 0:
            bc.fail("--steady-from must be positive")
        if args.duration is None:
            args.duration = 2.0
    if not shutil.which("git"):
        print("warning: git not found; the commit will be 'unknown'", file=sys.stderr)

    kind = "kernels" if args.kernels else "runs"
    if args.kernels:
        results, table, notes, started, load_before, load_after = kernels(args)
    else:
        results, table, notes, started, load_before, load_after = whole_runs(args)
    title = f"{started.strftime('%Y-%m-%d %H:%M UTC')} · {'kernel benchmarks' if args.kernels else 'whole runs'}" + \
        (f" · {args.label}" if args.label else "")
    head = bc.header_lines(bc.command_line(), started, load_before, load_after)
    body = head + "\n" + "\n".join(notes) + "\n\n" + table + "\n"
    print(f"\n### {title}\n\n{body}")
    json_path = bc.write_json(args.json or bc.default_json_path(kind, started, args.label),
                              {"kind": kind, "label": args.label, "date": started.isoformat(),
                               "machine": bc.machine(), "commit": bc.git_commit(), "command": bc.command_line(),
                               "load_average_before": load_before, "load_average_after": load_after,
                               "openmp_environment": {k: v for k, v in os.environ.items()
                                                      if k.startswith(("OMP_", "GOMP_"))},
                               "results": results})
    print(f"raw results: {json_path}", file=sys.stderr)
    if not args.no_results_md:
        path = bc.update_results(kind, args.label, title, body, started.strftime("%Y%m%d%H%M%S"))
        print(f"updated {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
