#!/usr/bin/env bash
# A run file cut short (half its bytes) is called damaged, by SQLite's own
# words, by simulate --resume, export, timeline and report, and no command
# offers to resume it (issue 65, R07, M04, N04: it was "not a crowdrecon run
# file", and --force was offered for a resume).
#   damaged_run_file.sh CROWDRECON SCENARIO
set -uo pipefail
exe=$1; scenario=$2
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
"$exe" simulate "$scenario" -o "$d/run.sqlite" -q > /dev/null 2>&1 || { echo "the run failed"; exit 1; }
size=$(stat -c %s "$d/run.sqlite")
truncate -s $((size / 2)) "$d/run.sqlite"
fails=0
check() {  # NAME COMMAND...
  local name=$1; shift
  "$@" > "$d/out.txt" 2>&1; local rc=$?
  if [[ $rc -ne 2 ]] || ! grep -q "a damaged SQLite file (SQLite: database disk image is malformed" "$d/out.txt"; then
    echo "FAIL $name: exit $rc"; cat "$d/out.txt"; fails=$((fails + 1))
  elif grep -q -- "--resume to" "$d/out.txt"; then
    echo "FAIL $name: offers a resume"; cat "$d/out.txt"; fails=$((fails + 1))
  else
    echo "ok   $name: $(head -c 200 "$d/out.txt")"
  fi
}
check "simulate --resume" "$exe" simulate "$scenario" -o "$d/run.sqlite" --resume -q
check "export" "$exe" export "$d/run.sqlite" -o "$d/e.sqlite"
check "timeline" "$exe" timeline "$d/run.sqlite" -o "$d/t.png"
check "report" "$exe" report "$d/run.sqlite" -o "$d/r" --no-pdf -q
[[ $fails -eq 0 ]] && echo "damaged_run_file.sh: OK"
exit $((fails > 0))
