#!/usr/bin/env bash
# A run file with rows no crowdrecon run has (issue 40): a trajectory row
# that person_state lacks (an id of 2e9, a frame of 7.5) and frame times
# that go backwards. Every reader refuses each, naming the table and row,
# and writes nothing (before: export dropped the rows silently and counted
# frames wrongly; every command took the times as they were).
#   damaged_run_rows.sh CROWDRECON RUN_FILE
set -uo pipefail
exe=$1; run=$2
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
for k in id frame time; do cp "$run" "$d/$k.sqlite"; done
sqlite3 "$d/id.sqlite" 'UPDATE trajectory_data SET id = 2000000000 WHERE rowid = 50'
sqlite3 "$d/frame.sqlite" 'UPDATE trajectory_data SET frame = frame + 7.5 WHERE rowid = 50'
sqlite3 "$d/time.sqlite" 'UPDATE frame_time SET time_s = 0.1 WHERE frame = 3'
for k in id frame time; do
  for how in "export -o $d/out-$k.sqlite" "report --no-pdf -o $d/report-$k" "render -o $d/out-$k.png" "analyze"; do
    if "$exe" $how "$d/$k.sqlite" > "$d/msg.txt" 2>&1; then echo "damaged_run_rows.sh: '$how' accepted the damaged $k"; exit 1; fi
    echo "$k, ${how%% *}: $(cat "$d/msg.txt")"
    [[ $k == time ]] && pattern="table frame_time, row frame 3: time_s 0.1 s is not after frame 2's 0.2 s" ||
      pattern="table trajectory_data, row frame [0-9.]*, id [0-9]*"
    grep -q "$pattern" "$d/msg.txt" || { echo "damaged_run_rows.sh: no message naming the row"; exit 1; }
  done
  if compgen -G "$d/out-$k*" > /dev/null; then echo "damaged_run_rows.sh: wrote $(ls "$d"/out-$k*)"; exit 1; fi
done
