#!/usr/bin/env bash
# Draws a sweep's pictures with `crowdrecon phase` (extra options after the
# results folder) and checks that every picture index.html shows or links to
# was written, and that SVG heat maps are there exactly when asked for.
#   check_phase_links.sh CROWDRECON RESULTS_DIR [PHASE OPTIONS...]
set -euo pipefail
exe=$1 results=$2
shift 2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$exe" phase "$results" -o "$dir" "$@" >/dev/null
links=$(grep -oE '(href|src)="[^"]+"' "$dir/index.html" | sed -E 's/^(href|src)="(.*)"$/\2/' | sort -u)
count=0
for f in $links; do
  count=$((count + 1))
  if [[ ! -s "$dir/$f" ]]; then
    echo "index.html refers to $f, which was not written" >&2
    exit 1
  fi
done
svg_heat=$(find "$dir" -name 'heat-*.svg' | wc -l)
png_heat=$(find "$dir" -name 'heat-*.png' | wc -l)
if [[ " $* " == *" --heat-maps-png-only "* ]]; then
  [[ $svg_heat -eq 0 ]] || { echo "--heat-maps-png-only wrote $svg_heat SVG heat maps" >&2; exit 1; }
else
  [[ $svg_heat -eq $png_heat ]] || { echo "$png_heat PNG but $svg_heat SVG heat maps" >&2; exit 1; }
fi
[[ $png_heat -gt 0 ]] || { echo "no heat maps written" >&2; exit 1; }
echo "index.html: $count pictures referred to, all written; heat maps: $png_heat PNG, $svg_heat SVG"
