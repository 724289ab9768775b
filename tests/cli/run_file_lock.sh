#!/usr/bin/env bash
# A run file being written is locked (issue 65: two simulate with the same
# -o and different scenarios both said "complete" and the file held the
# second): a second simulate, a resume and analyze --write are refused with
# a message while the first writes, and the first's run completes intact;
# the lock goes with the writer.
#   run_file_lock.sh CROWDRECON SCENARIO
set -uo pipefail
exe=$1; scenario=$2
source "$(dirname "$0")/run_tables.sh"  # last_frame RUN.sqlite
d=$(mktemp -d); trap 'kill "$pid" 2>/dev/null; rm -rf "$d"' EXIT
python3 "$(dirname "$0")/../../scripts/scenario-with.py" "$scenario" "$d/long.json" run.duration_s=30
python3 "$(dirname "$0")/../../scripts/scenario-with.py" "$scenario" "$d/other.json" run.duration_s=2 name='"another"'
"$exe" simulate "$d/long.json" -o "$d/run.sqlite" -q --threads 1 > /dev/null 2> "$d/first.txt" &
pid=$!
for _ in $(seq 600); do
  [[ $(last_frame "$d/run.sqlite") -ge 2 ]] && break
  sleep 0.05
done
[[ -e $d/run.sqlite.lock ]] || { echo "run_file_lock.sh: no lock file while the run is written"; exit 1; }
"$exe" simulate "$d/other.json" -o "$d/run.sqlite" -q > /dev/null 2> "$d/second.txt"; rc=$?
[[ $rc -eq 2 ]] || { cat "$d/second.txt"; echo "run_file_lock.sh: a second simulate exited $rc, expected 2"; exit 1; }
grep -q "run.sqlite: being written by another crowdrecon process" "$d/second.txt" ||
  { cat "$d/second.txt"; echo "run_file_lock.sh: unclear message"; exit 1; }
"$exe" analyze "$d/run.sqlite" --write > /dev/null 2> "$d/analyze.txt"; rc=$?
[[ $rc -eq 2 ]] || { cat "$d/analyze.txt"; echo "run_file_lock.sh: analyze --write exited $rc, expected 2"; exit 1; }
wait "$pid"; rc=$?
[[ $rc -eq 0 ]] || { cat "$d/first.txt"; echo "run_file_lock.sh: the first run exited $rc"; exit 1; }
status=$(sqlite3 "$d/run.sqlite" "SELECT value FROM run WHERE key = 'status'")
name=$(sqlite3 "$d/run.sqlite" "SELECT value FROM run WHERE key = 'scenario'" | python3 -c "import json,sys; print(json.load(sys.stdin)['name'])")
[[ $status == complete && $name != another ]] || { echo "run_file_lock.sh: the first run's file is $status, of \"$name\""; exit 1; }
[[ ! -e $d/run.sqlite.lock ]] || { echo "run_file_lock.sh: the lock file stayed after the run"; exit 1; }
# Free again: the second runs now.
"$exe" simulate "$d/other.json" -o "$d/run.sqlite" -q > /dev/null || { echo "run_file_lock.sh: the file stayed locked"; exit 1; }
echo "run file lock: OK"
