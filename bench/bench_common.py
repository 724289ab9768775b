"""Shared helpers of the benchmark scripts (bench/README.md): the machine and
commit a measurement belongs to, medians, markdown tables, and the sections of
bench/RESULTS.md. Python 3 standard library only."""

import datetime
import json
import os
import pathlib
import platform
import re
import statistics
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
BENCH = ROOT / "bench"
RESULTS_MD = BENCH / "RESULTS.md"
MARKER = "<!-- measurements below: appended and updated by bench/run_benchmarks.py and bench/lammps_compare.py -->"


def fail(message):
    print(f"{pathlib.Path(sys.argv[0]).name}: {message}", file=sys.stderr)
    sys.exit(1)


def add_comparison_arguments(parser, program):
    """The options every before/after script takes: --build (of `program`),
    --repeat, --label, --no-results-md."""
    parser.add_argument("--build", action="append", required=True, metavar="NAME=EXE",
                        help=f"a {program} to run (give two or more; the first is the reference)")
    parser.add_argument("--repeat", type=int, default=5, help="repetitions (default: %(default)s)")
    parser.add_argument("--label", default="", help="names the RESULTS.md section and the JSON file")
    parser.add_argument("--no-results-md", action="store_true", help="do not write bench/RESULTS.md")


def add_whole_run_arguments(parser, repeat=3):
    """The options every whole-run script of one program takes: --exe,
    --repeat, --label, --no-results-md (checked_exe_and_repeat reads the
    first two)."""
    parser.add_argument("--exe", default="build/release/cli/crowdrecon", help="the crowdrecon program")
    parser.add_argument("--repeat", type=int, default=repeat, help="rounds (default: %(default)s)")
    parser.add_argument("--label", default="", help="names the RESULTS.md section and the JSON file")
    parser.add_argument("--no-results-md", action="store_true", help="do not write bench/RESULTS.md")


def parse_builds(args):
    """The builds of add_comparison_arguments' options: [(name, path)], paths
    made absolute from the repository root; at least two, and --repeat >= 1."""
    if args.repeat < 1:
        fail("--repeat must be at least 1")
    builds = []
    for spec in args.build:
        name, sep, exe = spec.partition("=")
        if not sep or not name or not exe:
            fail(f"--build {spec}: expected NAME=EXE")
        path = pathlib.Path(exe)
        path = path if path.is_absolute() else ROOT / path
        if not path.exists():
            fail(f"--build {spec}: {path} not found")
        builds.append((name, path))
    if len(builds) < 2:
        fail("give at least two --build NAME=EXE")
    return builds


def save_comparison(kind, what, args, started, load_before, load_after, notes, table, data):
    """Writes a before/after script's raw results (JSON, with the load
    averages) and, unless --no-results-md, its section of RESULTS.md titled
    `what` (e.g. "interleaved builds")."""
    data = dict(data, load_before=load_before, load_after=load_after)
    json_path = write_json(default_json_path(kind, started, args.label), data)
    print(f"raw results: {json_path}", file=sys.stderr)
    if not args.no_results_md:
        body = header_lines(command_line(), started, load_before, load_after, notes) + "\n\n" + table + "\n"
        title = f"{started.strftime('%Y-%m-%d %H:%M UTC')} · {what}" + (f" · {args.label}" if args.label else "")
        print(f"updated {update_results(kind, args.label, title, body, started)}", file=sys.stderr)


def machine():
    """CPU model, logical cores (and how many this process may use), memory, kernel."""
    model = "unknown CPU"
    cores = 0
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name") and model == "unknown CPU":
                model = line.split(":", 1)[1].strip()
            if line.startswith("processor"):
                cores += 1
    except OSError:
        pass
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    memory_gib = None
    try:
        for line in pathlib.Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                memory_gib = int(line.split()[1]) / 1024 / 1024
    except OSError:
        pass
    text = f"{model}, {cores} logical cores"
    if usable and usable != cores:
        text += f" ({usable} usable by this process)"
    if memory_gib:
        text += f", {memory_gib:.1f} GiB RAM"
    text += f", Linux {platform.release()}"
    return {"description": text, "cpu_model": model, "cores": cores, "usable_cores": usable,
            "memory_gib": memory_gib, "kernel": platform.release()}


def load_average():
    try:
        return [float(x) for x in pathlib.Path("/proc/loadavg").read_text().split()[:3]]
    except OSError:
        return None


def warn_if_busy(threshold=0.5):
    load = load_average()
    if load and load[0] > threshold:
        print(f"warning: 1-minute load average is {load[0]:.2f}: other processes are running; "
              "timings (above all with 2 threads) will be slower and noisier than on a quiet machine",
              file=sys.stderr)
    return load


def git_commit():
    """Short commit id of the working tree, with a note if it has uncommitted changes."""
    try:
        commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short=12", "HEAD"], capture_output=True,
                                text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True).stdout.strip()
        return commit + (" (with uncommitted changes)" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown (not a git checkout)"


def now():
    return datetime.datetime.now(datetime.timezone.utc)


def median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def spread(values):
    """(max - min) / median, the relative spread of repeated measurements."""
    values = [v for v in values if v is not None]
    if len(values) < 2:
        return None
    m = statistics.median(values)
    return (max(values) - min(values)) / m if m else None


def si(value, digits=3):
    """1234567 -> '1.23 M'."""
    if value is None:
        return "–"
    for factor, suffix in ((1e9, " G"), (1e6, " M"), (1e3, " k")):
        if abs(value) >= factor:
            return f"{value / factor:.{digits}g}{suffix}"
    return f"{value:.{digits}g}"


def fixed(value, digits=2):
    return "–" if value is None else f"{value:.{digits}f}"


def percent(value):
    return "–" if value is None else f"{100 * value:.0f} %"


def checked_exe_and_repeat(args):
    """The program of --exe (relative to the repository) and --repeat, checked;
    exits with a message if the program is missing or the count below 1."""
    exe = pathlib.Path(args.exe)
    exe = exe if exe.is_absolute() else ROOT / exe
    if not exe.exists():
        fail(f"{exe} not found")
    if args.repeat < 1:
        fail("--repeat must be at least 1")
    return exe


def cut_scenario_copy(path, duration_s, tag):
    """The scenario with its duration set and no checkpoints, written next to
    the original (its relative paths stay valid) as .bench-TAG-PID-NAME
    (ignored by git); the caller removes it after the runs."""
    data = json.loads(path.read_text())
    data["run"]["duration_s"] = duration_s
    data["run"]["checkpoint_interval_s"] = 0
    copy = path.parent / f".bench-{tag}-{os.getpid()}-{path.name}"
    copy.write_text(json.dumps(data))
    return copy


def fresh_run_file(folder):
    """FOLDER/run.sqlite with no run file (or its SQLite journals) left there
    by the previous run of a script."""
    out = pathlib.Path(folder) / "run.sqlite"
    for leftover in (out, pathlib.Path(str(out) + "-wal"), pathlib.Path(str(out) + "-shm")):
        leftover.unlink(missing_ok=True)
    return out


def markdown_table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(" --- " for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def section_id(kind, label, stamp):
    """Sections with a label replace an earlier one of the same kind and label;
    unlabelled ones are always appended."""
    return f"{kind}|{label}" if label else f"{kind}|{stamp}"


def update_results(kind, label, title, body, stamp):
    """Appends (or replaces, see section_id) a section of bench/RESULTS.md."""
    sid = section_id(kind, label, stamp)
    begin, end = f"<!-- bench-section: {sid} -->", f"<!-- /bench-section: {sid} -->"
    block = f"{begin}\n### {title}\n\n{body.rstrip()}\n{end}\n"
    text = RESULTS_MD.read_text() if RESULTS_MD.exists() else f"# Benchmark results\n\n{MARKER}\n"
    if MARKER not in text:
        text = text.rstrip() + f"\n\n{MARKER}\n"
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end) + r"\n?", re.S)
    if pattern.search(text):
        text = pattern.sub(lambda _: block, text, count=1)
    else:
        text = text.rstrip() + "\n\n" + block
    RESULTS_MD.write_text(text)
    return RESULTS_MD


def write_json(path, data):
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=2) + "\n")
    return path


def default_json_path(kind, stamp, label):
    safe = re.sub(r"[^A-Za-z0-9._-]+", "-", label).strip("-") if label else ""
    name = f"{stamp.strftime('%Y%m%d-%H%M%S')}-{kind}" + (f"-{safe}" if safe else "") + ".json"
    return ROOT / "results" / "bench" / name


def header_lines(command, started, load_before, load_after, extra=()):
    m = machine()
    lines = [f"- date: {started.strftime('%Y-%m-%d %H:%M UTC')}",
             f"- machine: {m['description']}",
             f"- commit: {git_commit()}",
             f"- command: `{command}`"]
    if load_before or load_after:
        fmt = lambda l: "/".join(f"{x:.2f}" for x in l) if l else "?"  # noqa: E731
        lines.append(f"- load average (1/5/15 min) before: {fmt(load_before)}, after: {fmt(load_after)}")
    openmp = {k: v for k, v in os.environ.items() if k.startswith(("OMP_", "GOMP_"))}
    lines.append("- OpenMP environment: " + (", ".join(f"`{k}={v}`" for k, v in sorted(openmp.items()))
                                            if openmp else "none set (defaults)"))
    lines += list(extra)
    return "\n".join(lines)


def command_line():
    args = [pathlib.Path(sys.argv[0]).as_posix()] + sys.argv[1:]
    try:
        args[0] = str(pathlib.Path(sys.argv[0]).resolve().relative_to(ROOT))
    except ValueError:
        pass
    return "python3 " + " ".join(a if re.fullmatch(r"[\w./,:=+-]+", a) else json.dumps(a) for a in args)
