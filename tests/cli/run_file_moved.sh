#!/usr/bin/env bash
# A run file is self-contained: simulated from a scenario and venue that are
# then deleted, moved, and analysed from another folder, it still has its
# venue's measurement line and target directions (the venue is stored in the
# file; nothing is looked up next to the scenario).
#   run_file_moved.sh CROWDRECON SCENARIO.json VENUE.json BODY.json SCRATCH_DIR
set -euo pipefail
exe=$1 scenario=$2 venue=$3 body=$4 dir=$5
rm -rf "$dir"
mkdir -p "$dir/sc" "$dir/elsewhere"
cp "$venue" "$dir/sc/venue.json"
sed -e 's|"venue": *"[^"]*"|"venue": "venue.json"|' -e "s|\"reference\": *\"[^\"]*\"|\"reference\": \"$body\"|" \
  "$scenario" > "$dir/sc/scenario.json"
cd "$dir"
"$exe" simulate sc/scenario.json -o run.sqlite -q
rm -rf sc
mv run.sqlite elsewhere/moved.sqlite
cd elsewhere
"$exe" analyze moved.sqlite --json a.json > report.txt
grep -q 'flow through venue line "middle"' report.txt || { cat report.txt; echo "FAIL: no venue line"; exit 1; }
grep -q 'venue targets (the venue stored in the run file)' a.json || { echo "FAIL: directions not from the venue"; exit 1; }
echo "ok: the moved run file was analysed with its own venue"
