#!/usr/bin/env bash
# A report says when its run is unfinished, in its summary and on its page,
# and refuses an ensemble that pools an unfinished run with finished ones, as
# the timeline's ensembles do (issue 65, M10, M11, V02).
#   report_unfinished.sh CROWDRECON SCENARIO
set -uo pipefail
exe=$1; scenario=$2
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail() { echo "report_unfinished.sh: $*"; exit 1; }
"$exe" simulate "$scenario" -o "$d/part.sqlite" -q --stop-after 1 > /dev/null 2>&1
"$exe" simulate "$scenario" -o "$d/whole.sqlite" -q > /dev/null 2>&1 || fail "the whole run failed"
python3 "$(dirname "$0")/../../scripts/scenario-with.py" "$scenario" "$d/seed2.json" population.seed=99 > /dev/null
"$exe" report "$d/part.sqlite" -o "$d/r" --no-pdf -q > "$d/out.txt" 2>&1 || { cat "$d/out.txt"; fail "the report of one unfinished run failed"; }
grep -q 'part.sqlite is unfinished (status "interrupted"' "$d/out.txt" || { cat "$d/out.txt"; fail "no note in the summary"; }
grep -q 'An unfinished run' "$d/r/report.html" || fail "the page does not say it"
"$exe" simulate "$d/seed2.json" -o "$d/other.sqlite" -q --stop-after 1 > /dev/null 2>&1
"$exe" report "$d/whole.sqlite" "$d/other.sqlite" -o "$d/e" --no-pdf -q > "$d/out.txt" 2>&1; rc=$?
[[ $rc -eq 2 ]] || { cat "$d/out.txt"; fail "an ensemble with an unfinished run: exit $rc, expected 2"; }
grep -q 'other.sqlite: the run.s status is "interrupted"; an ensemble pools finished runs' "$d/out.txt" || { cat "$d/out.txt"; fail "no such message"; }
[[ ! -e $d/e ]] || fail "the refused report left its folder"
echo "report_unfinished.sh: OK"
