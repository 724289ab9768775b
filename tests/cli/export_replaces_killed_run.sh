#!/bin/bash
# Issue 40: a run killed mid-way leaves its write-ahead log (RUN.sqlite-wal)
# and checkpoint beside it; an export written over RUN.sqlite with --force
# removes them and says so (before, every reader applied the killed run's
# log to the export and saw the killed run).
# Usage: export_replaces_killed_run.sh CROWDRECON SCENARIO
set -euo pipefail
crowdrecon=$1
scenario=$2
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
"$crowdrecon" simulate "$scenario" -o "$d/other.sqlite" -q
"$crowdrecon" simulate "$scenario" -o "$d/run.sqlite" -q &
pid=$!
for _ in $(seq 1 400); do
  [ -e "$d/run.sqlite-wal" ] && [ -s "$d/run.sqlite-wal" ] && break
  sleep 0.02
done
kill -9 "$pid" 2> /dev/null || true
wait "$pid" 2> /dev/null || true
if [ ! -e "$d/run.sqlite-wal" ]; then echo "the killed run left no log: nothing to test (run too short?)"; exit 1; fi
"$crowdrecon" export "$d/other.sqlite" -o "$d/run.sqlite" --force > "$d/out.txt"
cat "$d/out.txt"
grep -q "removed $d/run.sqlite-wal" "$d/out.txt"
test ! -e "$d/run.sqlite-wal"
test ! -e "$d/run.sqlite-shm"
test ! -e "$d/run.sqlite.checkpoint"
# Every reader sees the export, not the killed run.
python3 - "$d/run.sqlite" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
assert db.execute("select value from metadata where key = 'crowdrecon_export'").fetchone(), "not the export"
assert not db.execute("select name from sqlite_master where name = 'run'").fetchone(), "the killed run's tables are visible"
PY
echo "stale sidecars removed: OK"
# An export killed outright leaves its unfinished file under a hidden
# partial name; the next export to the same name removes it and says so.
touch "$d/.pedpy.partial-999999999.sqlite" "$d/.other-name.partial-999999999.sqlite"
"$crowdrecon" export "$d/other.sqlite" -o "$d/pedpy.sqlite" > "$d/out2.txt"
cat "$d/out2.txt"
grep -q "removed $d/.pedpy.partial-999999999.sqlite: the unfinished file of an export to $d/pedpy.sqlite that was killed" "$d/out2.txt"
test ! -e "$d/.pedpy.partial-999999999.sqlite"
test -e "$d/.other-name.partial-999999999.sqlite"  # another file's: left alone
echo "a killed export's partial file removed: OK"
