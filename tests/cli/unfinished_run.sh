#!/bin/bash
# What is exported, drawn or shown of an unfinished run says so (issue 40);
# nothing is said of a finished one.
# Usage: unfinished_run.sh CROWDRECON SCENARIO (a timeline scenario of a few seconds)
set -euo pipefail
crowdrecon=$1
scenario=$2
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
"$crowdrecon" simulate "$scenario" -o "$d/run.sqlite" -q --stop-after 1 > /dev/null 2>&1 || true
note='note: .*run.sqlite is unfinished (status "interrupted": stopped before its end): what follows covers its frames up to t = 1 s only'
for command in "export $d/run.sqlite -o $d/e.sqlite" "render $d/run.sqlite -o $d/frames --frames last" \
               "timeline $d/run.sqlite -o $d/t.png" \
               "observe trajectories $d/run.sqlite --spec $(dirname "$0")/../../venues/madrid-arena/observations/hallway.json -o $d/o.json"; do
  # shellcheck disable=SC2086
  "$crowdrecon" $command > "$d/out.txt"
  grep -q "$note" "$d/out.txt" || { echo "$command: no note"; cat "$d/out.txt"; exit 1; }
done
# A failed run is said to be one, and not offered a resume that simulate
# refuses (issue 65, V03): its status as the engine's failure writes it.
cp "$d/run.sqlite" "$d/failed.sqlite"
sqlite3 "$d/failed.sqlite" "UPDATE run SET value = 'failed: person 14 went through wall 0 at t = 1 s' WHERE key = 'status'"
"$crowdrecon" export "$d/failed.sqlite" -o "$d/f.sqlite" > "$d/out.txt"
grep -q 'went numerically wrong and stopped).*it cannot be resumed' "$d/out.txt" || { echo "failed run: no such note"; cat "$d/out.txt"; exit 1; }
if grep -q -- "--resume" "$d/out.txt"; then echo "a failed run was offered --resume"; cat "$d/out.txt"; exit 1; fi
"$crowdrecon" simulate "$scenario" -o "$d/whole.sqlite" -q > /dev/null
"$crowdrecon" export "$d/whole.sqlite" -o "$d/w.sqlite" > "$d/out.txt"
if grep -q unfinished "$d/out.txt"; then echo "a finished run was called unfinished"; exit 1; fi
echo "unfinished runs are said: OK"
