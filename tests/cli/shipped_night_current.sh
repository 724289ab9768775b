#!/usr/bin/env bash
# The shipped Madrid night (results/timelines/madrid-night/) is what today's
# engine gives: its first PREFIX_S simulated seconds are run again and their
# census (walking, fallen, removed, queued, entered of every frame) must be
# the shipped census.csv line for line. The whole night takes over an hour,
# so a change that alters results would otherwise leave the shipped night,
# its figures and the report made from it stale without anyone noticing (as
# happened once: results/timelines/madrid-night/README.md). 300 s covers the
# free flow, the first releases and the 151 s where that stale night parted.
# usage: shipped_night_current.sh CROWDRECON SOURCE_DIR [PREFIX_S]
set -euo pipefail
exe=$1; src=$2; prefix_s=${3:-300}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
shipped="$src/results/timelines/madrid-night/census.csv"
set +e
"$exe" simulate "$src/venues/madrid-arena/scenarios/madrid-night.json" --profile paper -o "$tmp/night.sqlite" \
  --stop-after "$prefix_s" -q >/dev/null 2>"$tmp/err.txt"
rc=$?
set -e
[[ $rc -eq 130 ]] || { echo "FAIL: the night stopped at ${prefix_s} s exited $rc, expected 130"; cat "$tmp/err.txt"; exit 1; }
frames=$(sqlite3 "$tmp/night.sqlite" "SELECT MAX(frame) FROM census")
sqlite3 -csv -header "$tmp/night.sqlite" "SELECT * FROM census ORDER BY frame" >"$tmp/census.csv"
lines=$((frames + 2))  # header and frames 0..frames
head -n "$lines" "$shipped" >"$tmp/shipped.csv"
if ! diff -q "$tmp/shipped.csv" "$tmp/census.csv" >/dev/null; then
  first=$(diff "$tmp/shipped.csv" "$tmp/census.csv" | head -n 4 || true)
  echo "FAIL: the shipped night ($shipped) is not what this build gives: the census differs in the first ${prefix_s} s"
  echo "$first"
  echo "Run the night again (results/timelines/madrid-night/README.md) and replace its files and the report made from it."
  exit 1
fi
echo "the shipped night's census matches this build's for frames 0-$frames (${prefix_s} s)"
