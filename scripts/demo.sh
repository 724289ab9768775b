#!/usr/bin/env bash
# The main job on the embedded default, the Madrid Arena case (called by `make demo`).
#   scripts/demo.sh CROWDRECON OUTDIR
set -euo pipefail
exe=${1:?usage: demo.sh CROWDRECON OUTDIR}
out=${2:?usage: demo.sh CROWDRECON OUTDIR}
mkdir -p "$out/venues" "$out/bodies" "$out/hallway" "$out/phase" "$out/madrid-night" "$out/evacuation"

echo "== Madrid Arena venues"
for venue in venues/madrid-arena/*.json; do
  name=$(basename "$venue" .json)
  "$exe" venue check "$venue" --picture "$out/venues/$name.png" > "$out/venues/$name.txt"
  "$exe" venue check "$venue" --picture "$out/venues/$name.svg" >/dev/null
  head -n 3 "$out/venues/$name.txt"
done

echo "== Reference thorax body (18 vertices, sphero-radius 0.05 m)"
"$exe" shape venues/bodies/thorax-reference.json --vertices 18 --radius 0.05 \
  -o "$out/bodies/thorax-18.json" --picture "$out/bodies/thorax-18.png" > "$out/bodies/thorax-18.txt"
for mode in paper anthropometric circle; do
  "$exe" population --mode "$mode" --count 400 --seed 2012 \
    -o "$out/bodies/population-$mode.json" --picture "$out/bodies/population-$mode.png" >/dev/null
done

echo "== Madrid Arena hallway: periodic, 5 persons/m2, 30 % counter-flow, 60 s"
"$exe" simulate venues/madrid-arena/scenarios/hallway-5pm2-30cf.json -o "$out/hallway/run.sqlite" \
  | tee "$out/hallway/summary.txt"
echo "== Rendering the hallway run (every other frame, as PNG and as a real-time video)"
"$exe" render "$out/hallway/run.sqlite" -o "$out/hallway/frames" --frames every:2 \
  --video "$out/hallway/hallway.mp4" --width 1600 | tee -a "$out/hallway/summary.txt"

echo "== Analysis of the hallway run (regime, flows, lanes, loads against 400 N)"
"$exe" analyze "$out/hallway/run.sqlite" --json "$out/hallway/analysis.json" | tee "$out/hallway/analysis.txt"

echo "== The Madrid Arena night, shortened (open hallway: inflow at both ends, exits, falls; the full 95-minute"
echo "   reconstruction is venues/madrid-arena/scenarios/madrid-night.json, docs/scenarios.md)"
"$exe" simulate venues/madrid-arena/scenarios/madrid-night-demo.json -o "$out/madrid-night/run.sqlite" \
  | tee "$out/madrid-night/summary.txt"
"$exe" timeline "$out/madrid-night/run.sqlite" -o "$out/madrid-night/timeline.png" -o "$out/madrid-night/timeline.svg" \
  --phase results/sweeps/madrid-arena/hallway-bodies --phase-output "$out/madrid-night/phase" --path-step 10 \
  | tee -a "$out/madrid-night/summary.txt"

echo "== The 6,800-person evacuation of the ground floor, its first 20 s (the run to 95 % is"
echo "   venues/madrid-arena/scenarios/evacuation-6800.json, docs/scenarios.md)"
"$exe" simulate venues/madrid-arena/scenarios/evacuation-6800-demo.json -o "$out/evacuation/run.sqlite" \
  | tee "$out/evacuation/summary.txt"

echo "== Injury-risk report: the Madrid night (demo) compared with the evacuation (docs/reports.md)"
"$exe" report "$out/madrid-night/run.sqlite" --label "Madrid night (demo)" \
  --compare "$out/evacuation/run.sqlite" --compare-label "evacuation, first 20 s" -o "$out/report" \
  --validation results/validation-validated/results.json | tee "$out/report-summary.txt"

echo "== Phase diagrams of the shipped Madrid Arena sweeps (results/sweeps/madrid-arena/)"
for sweep in hallway-bodies hallway-gamma hallway-lambda; do
  "$exe" phase "results/sweeps/madrid-arena/$sweep" -o "$out/phase/$sweep" | tail -n 1
done

echo "Outputs written under $out/: venues/, bodies/, hallway/ (run.sqlite and its analysis; for PedPy: crowdrecon export out/hallway/run.sqlite -o run-pedpy.sqlite), madrid-night/ (timeline run, its figure and its path over the phase diagram), evacuation/, report/ (report.html, report.pdf, people.csv), phase/"
