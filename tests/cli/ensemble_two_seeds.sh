#!/bin/bash
# An ensemble of two seeds of a timeline scenario (issue 39): the figure and
# both score files are written, one row per run; the same run given twice is
# refused and nothing is written; the local reading of avalanches
# (--area-avalanches) scores and draws too; two ensembles (the same seeds
# under the profile validated) are drawn and scored side by side with
# --compare, named by their profiles, and a run in both is refused; each
# run's summary scores the same as the run (--summaries).
# Usage: ensemble_two_seeds.sh CROWDRECON SCENARIO
set -euo pipefail
crowdrecon=$1
scenario=$(realpath "$2")
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
# The second seed: the same scenario with its paths made absolute.
python3 - "$scenario" "$d/b.json" <<'PY'
import json, os, sys
src, dst = sys.argv[1], sys.argv[2]
s = json.load(open(src))
base = os.path.dirname(src)
s["venue"] = os.path.normpath(os.path.join(base, s["venue"]))
s["population"]["body"]["reference"] = os.path.normpath(os.path.join(base, s["population"]["body"]["reference"]))
s["population"]["seed"] = s["population"]["seed"] + 1
json.dump(s, open(dst, "w"))
PY
python3 - "$d/b.json" "$d/va.json" "$d/vb.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["profile"] = "validated"
json.dump(s, open(sys.argv[3], "w"))
s["population"]["seed"] -= 1
json.dump(s, open(sys.argv[2], "w"))
PY
"$crowdrecon" simulate "$scenario" -o "$d/a.sqlite" -q
"$crowdrecon" simulate "$d/b.json" -o "$d/b.sqlite" -q
"$crowdrecon" timeline "$d/a.sqlite" "$d/b.sqlite" -o "$d/e.png" --scores "$d/e.md" --scores "$d/e.csv" --tolerance 1 > "$d/out.txt"
cat "$d/out.txt"
test -s "$d/e.png"
grep -q '| over the 2 runs | median (range) |' "$d/e.md"
grep -q '^| seed 11 |' "$d/e.md"
grep -q '^| seed 12 |' "$d/e.md"
test "$(wc -l < "$d/e.csv")" -eq 3
# The local reading (docs/analysis.md, "Local avalanches"): the same runs
# scored with the hallway's areas; one run's figure with it too.
"$crowdrecon" timeline "$d/a.sqlite" "$d/b.sqlite" -o "$d/l.png" --scores "$d/l.csv" --tolerance 1 --area-avalanches > /dev/null
test -s "$d/l.png"
test "$(wc -l < "$d/l.csv")" -eq 3
"$crowdrecon" timeline "$d/a.sqlite" -o "$d/one.png" --area-avalanches > "$d/one.txt"
grep -q 'avalanches and .* falls in the run' "$d/one.txt"
test -s "$d/one.png"
if "$crowdrecon" timeline "$d/a.sqlite" "$d/a.sqlite" -o "$d/f.png" > "$d/twice.txt" 2>&1; then
  echo "the same run given twice was accepted"; exit 1
fi
grep -q 'given twice' "$d/twice.txt"
test ! -e "$d/f.png"
# Each run's summary (--summaries, an existing folder): the ensemble scored
# from the summaries is the one scored from the runs (the same table); a
# summary beside its own run is the same seed twice, refused; a summary is
# not summarised again.
mkdir "$d/sum"
"$crowdrecon" timeline "$d/a.sqlite" "$d/b.sqlite" -o "$d/s1.png" --scores "$d/s1.md" --tolerance 1 --summaries "$d/sum" > /dev/null
test -s "$d/sum/a.json"; test -s "$d/sum/b.json"
"$crowdrecon" timeline "$d/sum/a.json" "$d/sum/b.json" -o "$d/s2.png" --scores "$d/s2.md" --tolerance 1 > /dev/null
cmp "$d/s1.md" "$d/s2.md"
test -s "$d/s2.png"
if "$crowdrecon" timeline "$d/sum/a.json" "$d/a.sqlite" -o "$d/s3.png" > "$d/s3.txt" 2>&1; then
  echo "a summary beside its own run was accepted"; exit 1
fi
grep -q 'the same run as' "$d/s3.txt"
mkdir "$d/sum2"
if "$crowdrecon" timeline "$d/sum/a.json" "$d/b.sqlite" -o "$d/s4.png" --summaries "$d/sum2" > "$d/s4.txt" 2>&1; then
  echo "a summary was summarised again"; exit 1
fi
grep -q 'is a summary already' "$d/s4.txt"
# A sweep of the same two seeds that writes each run's summary as it ends
# (ensemble_summaries): scored from those, the same table again.
cat > "$d/seeds.json" <<JSON
{"format": "crowdrecon-sweep", "version": 1, "scenario": "$scenario", "seeds": {"first": 11, "count": 2},
 "ensemble_summaries": true}
JSON
"$crowdrecon" sweep "$d/seeds.json" -o "$d/sweep" --jobs 2 -q > /dev/null
test "$(ls "$d/sweep/summaries" | wc -l)" -eq 2
"$crowdrecon" timeline "$d"/sweep/summaries/*.json -o "$d/s5.png" --scores "$d/s5.md" --tolerance 1 > /dev/null
cmp "$d/s1.md" "$d/s5.md"
# Two ensembles side by side (timeline --compare).
"$crowdrecon" simulate "$d/va.json" -o "$d/va.sqlite" -q
"$crowdrecon" simulate "$d/vb.json" -o "$d/vb.sqlite" -q
"$crowdrecon" timeline "$d/a.sqlite" "$d/b.sqlite" --compare "$d/va.sqlite" "$d/vb.sqlite" -o "$d/c.png" \
  --scores "$d/c.md" --scores "$d/c.csv" --tolerance 1 > "$d/c.txt"
test -s "$d/c.png"
grep -q '| over the runs | profile paper (2 runs): median (range) | profile validated (2 runs): median (range) |' "$d/c.md"
grep -q '^\*\*profile validated\*\* (2 runs)$' "$d/c.md"
test "$(wc -l < "$d/c.csv")" -eq 5
grep -q ',profile validated$' "$d/c.csv"
"$crowdrecon" timeline "$d/a.sqlite" "$d/b.sqlite" --compare "$d/va.sqlite" "$d/vb.sqlite" -o "$d/c.png" \
  --scores "$d/c.md" --tolerance 1 --label "the paper's model" --compare-label "validated crowd" > /dev/null
grep -q "runs with an avalanche within ±1 s: the paper's model | validated crowd |" "$d/c.md"
if "$crowdrecon" timeline "$d/a.sqlite" "$d/b.sqlite" --compare "$d/va.sqlite" "$d/b.sqlite" -o "$d/g.png" > "$d/g.txt" 2>&1; then
  echo "a run in both ensembles was accepted"; exit 1
fi
grep -q 'given twice' "$d/g.txt"
test ! -e "$d/g.png"
if "$crowdrecon" timeline "$d/a.sqlite" "$d/b.sqlite" -o "$d/h.png" --label x > "$d/h.txt" 2>&1; then
  echo "--label without --compare was accepted"; exit 1
fi
grep -q 'give --compare' "$d/h.txt"
echo "ensemble of two seeds: OK"
