#!/usr/bin/env python3
"""crowdrecon against LAMMPS on the same packing (bench/README.md, "LAMMPS comparison").

1. crowdrecon_bench_lammps builds the packing of a benchmark scenario (default
   bench/scenarios/lammps-2000.json: 2,000 people at 5 /m2, 8-vertex thorax,
   periodic box), writes it with the same stiffness, damping and time step as
   a LAMMPS data file and input script, and times crowdrecon's Step() on it for
   STEPS steps with each thread count;
2. LAMMPS (Debian's `lmp`, BODY package: pair_style body/rounded/polygon, fix
   nve/body) runs the same number of steps under `mpirun -np P` for each
   process count; its "Loop time of X on P procs for S steps with A atoms" is
   the time;
3. both are reported as agent-steps/s (people x steps / seconds) and as the
   ratio crowdrecon / LAMMPS at the same number of cores (threads = processes).

LAMMPS is checked to be doing contact work: its pair energy must be non-zero
during the run, and its neighbour count is reported next to crowdrecon's.

Examples:
  python3 bench/lammps_compare.py --label before
  python3 bench/lammps_compare.py --steps 200 --bench-exe build/ha/bench/crowdrecon_bench_lammps --label smoke
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


def find_lammps(given):
    if given:
        return given
    for name in ("lmp", "lmp_stable", "lmp_mpi", "lmp_serial"):
        if shutil.which(name):
            return name
    bc.fail("LAMMPS not found (lmp, lmp_stable, lmp_mpi, lmp_serial): run scripts/install-bench-deps.sh or give --lmp")


def run_crowdrecon(exe, scenario, steps, threads, work):
    cmd = [str(exe), "--scenario", scenario, "--out", str(work), "--steps", str(steps),
           "--threads", ",".join(str(t) for t in threads)]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=bc.ROOT)
    if proc.returncode != 0:
        bc.fail(f"{' '.join(cmd)} failed with status {proc.returncode}:\n{proc.stdout}{proc.stderr}")
    mapping, results = None, []
    for line in proc.stdout.splitlines():
        if line.startswith("MAPPING "):
            mapping = json.loads(line[len("MAPPING "):])
        elif line.startswith("RESULT "):
            results.append(json.loads(line[len("RESULT "):]))
    if mapping is None or len(results) != len(threads):
        bc.fail(f"unexpected output of {' '.join(cmd)}:\n{proc.stdout}")
    return mapping, results


def parse_lammps_log(text):
    out = {}
    m = re.search(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms", text)
    if not m:
        raise ValueError("no 'Loop time of ...' line")
    out["seconds"], out["procs"], out["steps"], out["atoms"] = float(m[1]), int(m[2]), int(m[3]), int(m[4])
    thermo = []
    block = re.search(r"^\s*Step\s+KinEng\s+PotEng\s*\n(.*?)^Loop time", text, re.S | re.M)
    if block:
        for line in block.group(1).splitlines():
            parts = line.split()
            if len(parts) == 3 and parts[0].isdigit():
                thermo.append({"step": int(parts[0]), "ke_j": float(parts[1]), "pe_j": float(parts[2])})
    out["thermo"] = thermo
    for key, pattern, conv in (("total_neighbours", r"Total # of neighbors = (\d+)", int),
                               ("neighbours_per_atom", r"Ave neighs/atom = ([0-9.]+)", float),
                               ("neighbour_builds", r"Neighbor list builds = (\d+)", int),
                               ("dangerous_builds", r"Dangerous builds = (\d+)", int)):
        m = re.search(pattern, text)
        out[key] = conv(m[1]) if m else None
    # Share of the loop time in each section (Pair, Neigh, Comm, Output, Modify, Other).
    sections = {}
    for name, pct in re.findall(r"^(Pair|Neigh|Comm|Output|Modify|Other)\s*\|.*\|\s*([0-9.]+)\s*$", text, re.M):
        sections[name.lower()] = float(pct)
    out["sections_percent"] = sections
    return out


def run_lammps(mpirun, lmp, procs, steps, work, extra_mpi_args):
    env = dict(os.environ, OMP_NUM_THREADS="1")
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        # Open MPI refuses to run as root unless told to.
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    log = pathlib.Path(work) / f"log.np{procs}"
    cmd = [mpirun, "-np", str(procs)] + extra_mpi_args + [lmp, "-in", "in.packing", "-var", "steps", str(steps),
                                                          "-log", log.name, "-screen", "none"]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=work, env=env)
    text = log.read_text() if log.exists() else ""
    if proc.returncode != 0 or "Loop time of" not in text:
        bc.fail(f"{' '.join(cmd)} (in {work}) failed with status {proc.returncode}:\n{proc.stdout}{proc.stderr}\n"
                f"--- end of {log} ---\n{text[-3000:]}")
    result = parse_lammps_log(text)
    result["agent_steps_per_s"] = result["atoms"] * result["steps"] / result["seconds"]
    pe = [row["pe_j"] for row in result["thermo"]]
    result["pe_min_j"], result["pe_max_j"] = (min(pe), max(pe)) if pe else (None, None)
    result["contacts_computed"] = bool(pe) and min(pe) > 0.0
    return result


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenario", default="lammps-2000", help="scenario name under bench/scenarios/ or file "
                   "(default: %(default)s)")
    p.add_argument("--steps", type=int, default=2000, help="time steps on both sides (default: %(default)s)")
    p.add_argument("--threads", default="1,2", help="crowdrecon threads = LAMMPS MPI processes, comma-separated "
                   "(default: %(default)s)")
    p.add_argument("--repeat", type=int, default=3, help="repetitions; medians are reported (default: %(default)s)")
    p.add_argument("--label", default="", help="what the measurement is; a later run with the same label replaces "
                   "its section of bench/RESULTS.md")
    p.add_argument("--bench-exe", default="build/release/bench/crowdrecon_bench_lammps",
                   help="crowdrecon side (default: %(default)s)")
    p.add_argument("--lmp", help="LAMMPS executable (default: the first of lmp, lmp_stable, lmp_mpi, lmp_serial)")
    p.add_argument("--mpirun", default="mpirun", help="MPI launcher (default: %(default)s)")
    p.add_argument("--mpi-args", default="", help="extra launcher arguments, e.g. '--oversubscribe'")
    p.add_argument("--workdir", help="keep the LAMMPS files and logs here (default: a temporary folder)")
    p.add_argument("--json", help="raw results file (default: results/bench/DATE-lammps[-LABEL].json)")
    p.add_argument("--no-results-md", action="store_true", help="do not write bench/RESULTS.md")
    args = p.parse_args()
    if args.repeat < 1 or args.steps < 1:
        bc.fail("--repeat and --steps must be at least 1")
    exe = pathlib.Path(args.bench_exe)
    if not exe.is_absolute():
        exe = bc.ROOT / exe
    if not exe.exists():
        bc.fail(f"{exe}: not found; build the release preset with libbenchmark-dev installed, or give --bench-exe")
    lmp = find_lammps(args.lmp)
    if not shutil.which(args.mpirun):
        bc.fail(f"{args.mpirun} not found: run scripts/install-bench-deps.sh")
    threads = [int(t) for t in args.threads.split(",") if t]

    started = bc.now()
    load_before = bc.warn_if_busy()
    temporary = None
    if args.workdir:
        work = pathlib.Path(args.workdir).resolve()
        work.mkdir(parents=True, exist_ok=True)
    else:
        temporary = tempfile.TemporaryDirectory(prefix="crowdrecon-lammps-")
        work = pathlib.Path(temporary.name)
    crowd = {t: [] for t in threads}
    lammps = {t: [] for t in threads}
    mapping = None
    for rep in range(args.repeat):
        # Alternate the two codes so that a change in the machine's load affects both.
        mapping, results = run_crowdrecon(exe, args.scenario, args.steps, threads, work)
        for r in results:
            crowd[r["threads"]].append(r)
            print(f"  run {rep + 1}/{args.repeat} crowdrecon threads {r['threads']}: "
                  f"{bc.si(r['agent_steps_per_s'])} agent-steps/s", file=sys.stderr)
        for t in threads:
            r = run_lammps(args.mpirun, lmp, t, args.steps, work, args.mpi_args.split())
            lammps[t].append(r)
            print(f"  run {rep + 1}/{args.repeat} LAMMPS -np {t}: {bc.si(r['agent_steps_per_s'])} agent-steps/s, "
                  f"pair energy {r['pe_min_j']:.3g}..{r['pe_max_j']:.3g} J", file=sys.stderr)
    load_after = bc.load_average()

    rows, summary = [], []
    for t in threads:
        c = bc.median([r["agent_steps_per_s"] for r in crowd[t]])
        l_rate = bc.median([r["agent_steps_per_s"] for r in lammps[t]])
        lr = lammps[t][-1]
        cr = crowd[t][-1]
        ratio = c / l_rate if c and l_rate else None
        active = all(r["contacts_computed"] for r in lammps[t])
        summary.append({"cores": t, "crowdrecon_agent_steps_per_s": c, "lammps_agent_steps_per_s": l_rate,
                        "ratio": ratio, "lammps_contacts_computed": active,
                        "crowdrecon_spread": bc.spread([r["agent_steps_per_s"] for r in crowd[t]]),
                        "lammps_spread": bc.spread([r["agent_steps_per_s"] for r in lammps[t]])})
        rows.append([t, cr["people"], args.steps, bc.si(c), bc.si(l_rate), f"{ratio:.2f}" if ratio else "–",
                     f"{cr['contacts_start']} → {cr['contacts_end']}", cr["neighbour_pairs"],
                     lr["total_neighbours"], f"{lr['pe_min_j']:.3g}–{lr['pe_max_j']:.3g}" if lr["thermo"] else "–",
                     "yes" if active else "**NO**",
                     f"{lr['sections_percent'].get('pair', 0):.0f}/{lr['sections_percent'].get('modify', 0):.0f}/"
                     f"{lr['sections_percent'].get('comm', 0):.0f}"])
    header = ["cores (threads = MPI procs)", "people", "steps", "crowdrecon agent-steps/s", "LAMMPS agent-steps/s",
              "ratio", "crowdrecon contacts start → end", "crowdrecon pairs", "LAMMPS neighbours",
              "LAMMPS pair energy J (min–max)", "LAMMPS computes contacts", "LAMMPS % pair/modify/comm"]
    table = bc.markdown_table(header, rows)
    ke_c = crowd[threads[0]][-1]["kinetic_energy_end_j"]
    ke_l = lammps[threads[0]][-1]["thermo"][-1]["ke_j"] if lammps[threads[0]][-1]["thermo"] else None
    notes = [f"- medians of {args.repeat} run(s) of {args.steps} steps; time step {mapping['time_step_s']:.6g} s, "
             f"k_n {mapping['k_n_n_per_m']:.6g} N/m, c_n {mapping['c_n_n_s_per_m']:.6g} N s/m, "
             f"c_t {mapping['c_t_n_s_per_m']:.6g} N s/m, mu 0, neighbour skin {mapping['skin_m']:.3g} m "
             "(mapping: bench/README.md)",
             "- crowdrecon: Step() only (the world built beforehand); LAMMPS: its 'Loop time' (setup excluded)",
             f"- kinetic energy after the run (translational; a check that both move the same crowd): crowdrecon "
             f"{ke_c:.4g} J, LAMMPS {ke_l:.4g} J" if ke_l is not None else "- LAMMPS printed no thermo output"]
    if args.workdir:
        notes.append(f"- LAMMPS files and logs: {work}")
    title = f"{started.strftime('%Y-%m-%d %H:%M UTC')} · LAMMPS comparison" + (f" · {args.label}" if args.label else "")
    head = bc.header_lines(bc.command_line(), started, load_before, load_after,
                           [f"- LAMMPS: `{lmp}` ({lammps_version(lmp)}) under `{args.mpirun} -np P`"])
    body = head + "\n" + "\n".join(notes) + "\n\n" + table + "\n"
    print(f"\n### {title}\n\n{body}")
    json_path = bc.write_json(args.json or bc.default_json_path("lammps", started, args.label),
                              {"kind": "lammps", "label": args.label, "date": started.isoformat(),
                               "machine": bc.machine(), "commit": bc.git_commit(), "command": bc.command_line(),
                               "load_average_before": load_before, "load_average_after": load_after,
                               "mapping": mapping, "summary": summary,
                               "crowdrecon_runs": {str(t): v for t, v in crowd.items()},
                               "lammps_runs": {str(t): v for t, v in lammps.items()}})
    print(f"raw results: {json_path}", file=sys.stderr)
    if not args.no_results_md:
        path = bc.update_results("lammps", args.label, title, body, started.strftime("%Y%m%d%H%M%S"))
        print(f"updated {path}", file=sys.stderr)
    if temporary:
        temporary.cleanup()
    if not all(s["lammps_contacts_computed"] for s in summary):
        bc.fail("LAMMPS reported zero pair energy: it computed no contacts, the comparison is not valid")


def lammps_version(lmp):
    try:
        proc = subprocess.run([lmp, "-h"], capture_output=True, text=True, timeout=30)
        m = re.search(r"Large-scale Atomic/Molecular Massively Parallel Simulator - (.*?)\n", proc.stdout)
        if m:
            return m[1].strip()
        m = re.search(r"LAMMPS \((.*?)\)", proc.stdout)
        return m[1] if m else "version unknown"
    except (OSError, subprocess.SubprocessError):
        return "version unknown"


if __name__ == "__main__":
    main()
