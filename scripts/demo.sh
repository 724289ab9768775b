#!/usr/bin/env bash
# The main job on the embedded default, the Madrid Arena case (called by `make demo`).
#   scripts/demo.sh CROWDRECON OUTDIR
# At this stage: the geometry of the reconstruction. Venues of the Madrid Arena
# (hallway periodic and open, ground floor) are validated and drawn, the
# reference thorax body is built from its outline, and a body population is drawn.
set -euo pipefail
exe=${1:?usage: demo.sh CROWDRECON OUTDIR}
out=${2:?usage: demo.sh CROWDRECON OUTDIR}
mkdir -p "$out/venues" "$out/bodies"

echo "== Madrid Arena venues"
for venue in venues/madrid-arena/*.json; do
  name=$(basename "$venue" .json)
  "$exe" venue check "$venue" --picture "$out/venues/$name.png" | tee "$out/venues/$name.txt"
  "$exe" venue check "$venue" --picture "$out/venues/$name.svg" >/dev/null
done

echo "== Reference thorax body (18 vertices, sphero-radius 0.05 m)"
"$exe" shape venues/bodies/thorax-reference.json --vertices 18 --radius 0.05 \
  -o "$out/bodies/thorax-18.json" --picture "$out/bodies/thorax-18.png" | tee "$out/bodies/thorax-18.txt"

echo "== Body populations (paper, anthropometric, circle)"
for mode in paper anthropometric circle; do
  "$exe" population --mode "$mode" --count 400 --seed 2012 \
    -o "$out/bodies/population-$mode.json" --picture "$out/bodies/population-$mode.png"
done

echo "Outputs written under $out/"
