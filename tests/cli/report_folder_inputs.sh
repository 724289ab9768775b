#!/usr/bin/env bash
# What report does with a folder of runs (issue 40): a .sqlite file that is
# not a run is left out and said (before: silently), and a run of another
# scenario is refused rather than pooled into the ensemble as another seed.
#   report_folder_inputs.sh CROWDRECON RUN_FILE
set -uo pipefail
exe=$1; run=$2
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail() { echo "report_folder_inputs.sh: $*"; exit 1; }
mkdir -p "$d/runs"
cp "$run" "$d/runs/seed-1.sqlite"
cp "$run" "$d/runs/seed-2.sqlite"
echo "not a database" > "$d/runs/notes.sqlite"
"$exe" report "$d/runs" -o "$d/report" --no-pdf -q > "$d/out.txt" 2>&1 || { cat "$d/out.txt"; fail "refused a folder with a stray file"; }
cat "$d/out.txt"
grep -q "note: left out $d/runs/notes.sqlite: a .sqlite file that is not a crowdrecon run file" "$d/out.txt" || fail "the stray file was not said"
grep -q "(2 runs)" "$d/out.txt" || fail "expected an ensemble of 2 runs"
# A label with a comma and quotes stays one field of people.csv (RFC 4180).
"$exe" report "$d/runs" -o "$d/labelled" --no-pdf -q --label 'night, "seeds" 1-2' > /dev/null 2>&1 || fail "refused a label"
python3 - "$d/labelled/people.csv" <<'PY' || fail "people.csv does not keep the label as one field"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1], newline="")))
assert rows and all(r["set"] == 'night, "seeds" 1-2' for r in rows), rows[:1]
assert all(r["zone"] in ("safe", "uncomfortable", "danger") for r in rows), rows[:1]
PY
sqlite3 "$d/runs/seed-2.sqlite" "UPDATE run SET value = json_set(value, '\$.name', 'another scenario') WHERE key = 'scenario'"
if "$exe" report "$d/runs" -o "$d/report2" --no-pdf -q > "$d/mixed.txt" 2>&1; then fail "pooled two scenarios into one ensemble"; fi
cat "$d/mixed.txt"
grep -q "seed-2.sqlite: a run of scenario \"another scenario\" in an ensemble of .*expected the seeds of one scenario" "$d/mixed.txt" ||
  fail "no message naming the run and both scenarios"
[[ ! -e $d/report2/report.html ]] || fail "wrote a report"
