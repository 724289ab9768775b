#!/usr/bin/env bash
# Determinism and restart of `crowdrecon simulate` (engine issue, "Must show"):
#   1. the same scenario and seed with 1 and 2 threads give byte-identical
#      trajectory tables (and person_state and contact tables);
#   2. a run interrupted (--stop-after, as on Ctrl-C) and resumed with --resume
#      gives the same tables as the uninterrupted run;
#   3. a run killed with SIGKILL mid-way resumes from its last periodic
#      checkpoint to the same tables.
# usage: run_determinism.sh CROWDRECON SCENARIO
set -euo pipefail
exe=$1; scenario=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
source "$(dirname "$0")/run_tables.sh"  # dump RUN.sqlite: hash of its per-frame tables
"$exe" simulate "$scenario" -o "$tmp/t1.sqlite" --threads 1 -q >/dev/null
"$exe" simulate "$scenario" -o "$tmp/t2.sqlite" --threads 2 -q >/dev/null
h1=$(dump_all "$tmp/t1.sqlite"); h2=$(dump_all "$tmp/t2.sqlite")
rows=$(sqlite3 "$tmp/t1.sqlite" "SELECT COUNT(*) FROM trajectory_data")
echo "1 thread: $h1 ($rows trajectory rows)"; echo "2 threads: $h2"
[[ "$h1" == "$h2" ]] || { echo "FAIL: thread count changed the results"; exit 1; }

set +e
"$exe" simulate "$scenario" -o "$tmp/r.sqlite" --threads 2 -q --stop-after 1.25 >/dev/null 2>"$tmp/stop.txt"
rc=$?
set -e
[[ $rc -eq 130 ]] || { echo "FAIL: interrupted run exited $rc, expected 130"; cat "$tmp/stop.txt"; exit 1; }
grep -q -- "--resume" "$tmp/stop.txt" || { echo "FAIL: no resume hint"; exit 1; }
[[ $(sqlite3 "$tmp/r.sqlite" "SELECT value FROM run WHERE key='status'") == interrupted ]] || { echo "FAIL: status"; exit 1; }
"$exe" simulate "$scenario" -o "$tmp/r.sqlite" --threads 1 -q --resume >/dev/null
hr=$(dump_all "$tmp/r.sqlite")
echo "interrupted + resumed: $hr"
[[ "$hr" == "$h1" ]] || { echo "FAIL: resumed run differs"; exit 1; }
[[ ! -e "$tmp/r.sqlite.checkpoint" ]] || { echo "FAIL: checkpoint left after completion"; exit 1; }
# crowdrecon's own statement of it: the tables' digest (the files' bytes may differ).
d1=$("$exe" analyze "$tmp/t1.sqlite" --digest); d2=$("$exe" analyze "$tmp/t2.sqlite" --digest)
dr=$("$exe" analyze "$tmp/r.sqlite" --digest)
echo "$d1"
[[ "$d1" == *"tables digest (SHA-256 of every per-frame table, row by row): "* ]] || { echo "FAIL: no digest"; exit 1; }
[[ "$d1" == "$d2" && "$d1" == "$dr" ]] || { echo "FAIL: digests differ: $d1 / $d2 / $dr"; exit 1; }
cp "$tmp/t1.sqlite" "$tmp/changed.sqlite"
sqlite3 "$tmp/changed.sqlite" "UPDATE person_state SET vel_x = vel_x + 1e-12 WHERE rowid = 7"
[[ $("$exe" analyze "$tmp/changed.sqlite" --digest) != "$d1" ]] || { echo "FAIL: the digest missed a changed value"; exit 1; }

# Killed: wait until a periodic checkpoint exists and a few frames are past it,
# then SIGKILL. A short run on a fast step can finish between two polls (seen on
# a loaded CI machine: "killed after frame 30" of 30, nothing to resume); such a
# try tests nothing, so it is said and made again, at most five times.
killed=0
for attempt in 1 2 3 4 5; do
  rm -f "$tmp/k.sqlite" "$tmp/k.sqlite.checkpoint"
  "$exe" simulate "$scenario" -o "$tmp/k.sqlite" --threads 1 -q >/dev/null 2>&1 &
  pid=$!
  for _ in $(seq 1 3000); do
    if [[ -e "$tmp/k.sqlite.checkpoint" ]] && \
       [[ $(last_frame "$tmp/k.sqlite") -ge 7 ]]; then break; fi
    kill -0 $pid 2>/dev/null || break
    sleep 0.01
  done
  kill -9 $pid 2>/dev/null || true
  wait $pid 2>/dev/null || true
  status=$(sqlite3 "$tmp/k.sqlite" "SELECT value FROM run WHERE key='status'" 2>/dev/null || echo none)
  if [[ -e "$tmp/k.sqlite.checkpoint" && "$status" != complete ]]; then killed=1; break; fi
  echo "try $attempt: the run finished (status $status) before the kill landed; again"
done
[[ $killed -eq 1 ]] || { echo "FAIL: the run finished before the kill in five tries"; exit 1; }
frames=$(sqlite3 "$tmp/k.sqlite" "SELECT MAX(frame) FROM frame_time")
echo "killed after frame $frames"
"$exe" simulate "$scenario" -o "$tmp/k.sqlite" --threads 2 -q --resume >/dev/null
hk=$(dump_all "$tmp/k.sqlite")
echo "killed + resumed: $hk"
[[ "$hk" == "$h1" ]] || { echo "FAIL: killed-and-resumed run differs"; exit 1; }
echo "determinism and restart: OK"
