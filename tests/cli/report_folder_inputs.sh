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
# (Another seed of the same scenario, as far as the ensemble can tell: a copy
# under another name with its seed unchanged is one run twice, below.)
sqlite3 "$d/runs/seed-2.sqlite" "UPDATE run SET value = json_set(value, '\$.population.seed', 424242) WHERE key = 'scenario'"
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
grep -q "seed-2.sqlite: not a seed of the scenario of .*seed-1.sqlite (they differ at /name); the ensemble is the seeds of one scenario" "$d/mixed.txt" ||
  fail "no message naming the runs and where their scenarios differ"
[[ ! -e $d/report2/report.html ]] || fail "wrote a report"
# By content, not by name (issue 65): a model of its own is another scenario
# whatever its name, and a copy of a run under another name counts once.
python3 - "$d/runs/seed-1.sqlite" "$d/runs/seed-2.sqlite" <<'PY'
import json, sqlite3, sys
a = json.loads(sqlite3.connect(sys.argv[1]).execute("SELECT value FROM run WHERE key = 'scenario'").fetchone()[0])
con = sqlite3.connect(sys.argv[2])
b = json.loads(con.execute("SELECT value FROM run WHERE key = 'scenario'").fetchone()[0])
b["name"] = a["name"]
b.setdefault("model", {})["gait_jitter"] = "isotropic"
con.execute("UPDATE run SET value = ? WHERE key = 'scenario'", (json.dumps(b),))
con.commit()
PY
if "$exe" report "$d/runs" -o "$d/report3" --no-pdf -q > "$d/model.txt" 2>&1; then fail "pooled two models of one name into one ensemble"; fi
grep -q "seed-2.sqlite: not a seed of the scenario of .*(they differ at /model" "$d/model.txt" || { cat "$d/model.txt"; fail "no message naming the model"; }
rm "$d/runs/seed-2.sqlite"
cp "$run" "$d/runs/copy.sqlite"
if "$exe" report "$d/runs" -o "$d/report4" --no-pdf -q > "$d/copy.txt" 2>&1; then fail "counted a copy of a run twice"; fi
grep -q "seed-1.sqlite: the same run as .*copy.sqlite (seed [0-9]* of the same scenario): each run counts once" "$d/copy.txt" ||
  { cat "$d/copy.txt"; fail "no message naming the copy"; }
