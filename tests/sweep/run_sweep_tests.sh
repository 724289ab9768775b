#!/usr/bin/env bash
# Sweeps (sweep/, docs/sweeps.md): the results table does not depend on how
# the runs were spread, nor on interruptions.
#   run_sweep_tests.sh CROWDRECON SWEEP OUT local
#       OUT/j1 with --jobs 1 (the reference), OUT/j2 with --jobs 2, and OUT/resume:
#       stopped after 3 runs (--stop-after-runs 3, exit 130, runs in progress
#       interrupted with their checkpoints), resumed, then run once more (nothing
#       left to do); OUT/killed: killed with SIGKILL after 2 rows and started
#       again; every results.csv equal to the reference but for wall_s.
#       Also: the same DIR with another sweep file is refused.
#   run_sweep_tests.sh CROWDRECON SWEEP OUT mpi
#       OUT/mpi under `mpirun -np 2 --oversubscribe`, compared with OUT/j1;
#       OUT/mpi-stop interrupted after 2 runs (every rank exits 130), then
#       continued and compared (exit 77 = skipped if mpirun is absent).
set -euo pipefail
exe=$1; sweep=$2; out=$3; mode=$4
mkdir -p "$out"

# results.csv without its last column (wall_s, the only one that may differ).
strip() { [[ $(head -1 "$1") == *,wall_s ]] || { echo "FAIL: $1 does not end with wall_s"; exit 1; }; sed 's/,[^,]*$//' "$1"; }
same() {  # same REFERENCE_DIR DIR WHAT
  if ! diff <(strip "$1/results.csv") <(strip "$2/results.csv") >"$out/diff.txt"; then
    echo "FAIL: $3: results differ from $1"; head -20 "$out/diff.txt"; exit 1
  fi
  echo "$3: $(($(wc -l <"$2/results.csv") - 1)) rows, identical to the reference"
}

if [[ $mode == local ]]; then
  rm -rf "$out/j1" "$out/j2" "$out/resume"
  "$exe" sweep "$sweep" -o "$out/j1" --jobs 1 -q
  rows=$(($(wc -l <"$out/j1/results.csv") - 1))
  [[ $rows -ge 8 ]] || { echo "FAIL: only $rows rows"; exit 1; }
  [[ -z $(ls "$out/j1/runs") ]] || { echo "FAIL: run files left in $out/j1/runs"; exit 1; }
  "$exe" sweep "$sweep" -o "$out/j2" --jobs 2 -q >/dev/null
  same "$out/j1" "$out/j2" "--jobs 2"

  set +e
  "$exe" sweep "$sweep" -o "$out/resume" --jobs 2 -q --stop-after-runs 3 >"$out/stop.txt" 2>&1
  rc=$?
  set -e
  [[ $rc -eq 130 ]] || { echo "FAIL: stopped sweep exited $rc, expected 130"; cat "$out/stop.txt"; exit 1; }
  grep -q "run the same command again to continue" "$out/stop.txt" || { echo "FAIL: no resume hint"; cat "$out/stop.txt"; exit 1; }
  done=$(sqlite3 "$out/resume/results.sqlite" "SELECT COUNT(*) FROM runs")
  [[ $done -ge 3 && $done -lt $rows ]] || { echo "FAIL: $done rows after stopping at 3"; exit 1; }
  echo "stopped after $done rows ($(ls "$out/resume/runs" | wc -l) file(s) of interrupted runs left)"
  "$exe" sweep "$sweep" -o "$out/resume" --jobs 1 -q >"$out/resume.txt"
  grep -q "$done done before" "$out/resume.txt" || { echo "FAIL: resumed sweep redid runs"; cat "$out/resume.txt"; exit 1; }
  same "$out/j1" "$out/resume" "stopped and resumed"
  "$exe" sweep "$sweep" -o "$out/resume" -q >"$out/again.txt"
  grep -q "$rows done before, 0 now" "$out/again.txt" || { echo "FAIL: a finished sweep ran again"; cat "$out/again.txt"; exit 1; }
  [[ -z $(ls "$out/resume/runs") ]] || { echo "FAIL: run files left after resuming"; exit 1; }

  # Killed outright (SIGKILL: no checkpoint written at the end) once two rows
  # are in, then started again: the same table as the reference.
  rm -rf "$out/killed"
  "$exe" sweep "$sweep" -o "$out/killed" --jobs 2 -q >"$out/killed.txt" 2>&1 &
  pid=$!
  for _ in $(seq 600); do
    n=$(sqlite3 "$out/killed/results.sqlite" "SELECT COUNT(*) FROM runs" 2>/dev/null || echo 0)
    [[ ${n:-0} -ge 2 ]] && break
    kill -0 $pid 2>/dev/null || break
    sleep 0.1
  done
  kill -9 $pid 2>/dev/null || true
  wait $pid 2>/dev/null || true
  killed=$(sqlite3 "$out/killed/results.sqlite" "SELECT COUNT(*) FROM runs")
  [[ $killed -lt $rows ]] || { echo "FAIL: the sweep finished before it could be killed"; exit 1; }
  echo "killed with SIGKILL after $killed rows"
  "$exe" sweep "$sweep" -o "$out/killed" --jobs 2 -q >/dev/null
  same "$out/j1" "$out/killed" "killed (SIGKILL) and started again"

  # Another sweep into the same folder is refused.
  sed 's/"count": 2}/"count": 3}/' "$sweep" >"$out/other.json"
  sed -i "s#\"\\.\\./scenarios/#\"$(cd "$(dirname "$sweep")" && pwd)/../scenarios/#" "$out/other.json"
  if "$exe" sweep "$out/other.json" -o "$out/j1" -q >"$out/other.txt" 2>&1; then
    echo "FAIL: a different sweep was run into an existing folder"; exit 1
  fi
  grep -q "holds the results of a different sweep (the sweep file changed" "$out/other.txt" ||
    { echo "FAIL: unclear message"; cat "$out/other.txt"; exit 1; }
  # A sweep started by a build of other sources is not continued (its runs
  # may differ); one of another commit of the same sources is.
  rm -rf "$out/other-build" "$out/old-build" "$out/other-commit"  # (cp -r into an existing folder nests)
  cp -r "$out/resume" "$out/other-build"
  sqlite3 "$out/other-build/results.sqlite" "UPDATE sweep SET value = '0123456789abcdef' WHERE key = 'source_fingerprint'"
  if "$exe" sweep "$sweep" -o "$out/other-build" -q >"$out/other-build.txt" 2>&1; then
    echo "FAIL: a sweep of other sources was continued"; exit 1
  fi
  grep -q "holds runs made by crowdrecon .* (sources 0123456789abcdef); this is crowdrecon .*not mixed" "$out/other-build.txt" ||
    { echo "FAIL: unclear message"; cat "$out/other-build.txt"; exit 1; }
  # A sweep stored before fingerprints: its version decides.
  cp -r "$out/resume" "$out/old-build"
  sqlite3 "$out/old-build/results.sqlite" "DELETE FROM sweep WHERE key = 'source_fingerprint'; UPDATE sweep SET value = 'v0.0-other' WHERE key = 'crowdrecon_version'"
  if "$exe" sweep "$sweep" -o "$out/old-build" -q >"$out/old-build.txt" 2>&1; then
    echo "FAIL: a sweep of another build was continued"; exit 1
  fi
  grep -q "holds runs made by crowdrecon v0.0-other; this is crowdrecon .*not mixed" "$out/old-build.txt" ||
    { echo "FAIL: unclear message"; cat "$out/old-build.txt"; exit 1; }
  cp -r "$out/resume" "$out/other-commit"
  sqlite3 "$out/other-commit/results.sqlite" "UPDATE sweep SET value = 'v0.0-other-commit' WHERE key = 'crowdrecon_version'"
  "$exe" sweep "$sweep" -o "$out/other-commit" -q >"$out/other-commit.txt" 2>&1 ||
    { echo "FAIL: a sweep of the same sources (another commit) was not continued"; cat "$out/other-commit.txt"; exit 1; }
  same "$out/j1" "$out/other-commit" "continued by another commit of the same sources"
  echo "sweeps, local: OK"
elif [[ $mode == mpi ]]; then
  command -v mpirun >/dev/null || { echo "mpirun not found: skipped"; exit 77; }
  [[ -s "$out/j1/results.csv" ]] || { echo "FAIL: no reference $out/j1 (run the local test first)"; exit 1; }
  rm -rf "$out/mpi"
  # Containers run as root; one machine: shared memory between the ranks.
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl=self,vader OMPI_MCA_rmaps_base_oversubscribe=1
  mpirun -np 2 --oversubscribe "$exe" sweep "$sweep" -o "$out/mpi" -q >"$out/mpi.txt" 2>&1 ||
    { echo "FAIL: mpirun exited $?"; cat "$out/mpi.txt"; exit 1; }
  cat "$out/mpi.txt"
  grep -q "on each of 2 MPI ranks" "$out/mpi.txt" || { echo "FAIL: the sweep did not run on 2 ranks"; exit 1; }
  same "$out/j1" "$out/mpi" "mpirun -np 2"
  # Interrupted under MPI (--stop-after-runs on rank 0): every rank exits 130
  # (a worker rank used to exit 0 as if its sweep were complete), and the
  # same command again completes it, equal to the reference.
  rm -rf "$out/mpi-stop" "$out"/mpi-stop.rc.*
  set +e
  mpirun -np 2 --oversubscribe sh -c '"$0" sweep "$1" -o "$2" -q --stop-after-runs 2; echo $? >"$2.rc.$OMPI_COMM_WORLD_RANK"' \
    "$exe" "$sweep" "$out/mpi-stop" >"$out/mpi-stop.txt" 2>&1
  set -e
  for r in 0 1; do
    [[ $(cat "$out/mpi-stop.rc.$r" 2>/dev/null) == 130 ]] ||
      { echo "FAIL: rank $r of the interrupted sweep exited $(cat "$out/mpi-stop.rc.$r" 2>/dev/null), expected 130"; cat "$out/mpi-stop.txt"; exit 1; }
  done
  mpirun -np 2 --oversubscribe "$exe" sweep "$sweep" -o "$out/mpi-stop" -q >"$out/mpi-continued.txt" 2>&1 ||
    { echo "FAIL: the continued sweep exited $?"; cat "$out/mpi-continued.txt"; exit 1; }
  same "$out/j1" "$out/mpi-stop" "mpirun -np 2, interrupted and continued"
  echo "sweeps, MPI: OK"
else
  echo "usage: run_sweep_tests.sh CROWDRECON SWEEP OUT local|mpi"; exit 2
fi
