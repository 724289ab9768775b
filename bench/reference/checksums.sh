#!/usr/bin/env bash
# Reference checksums: proof that a change of structure changed no result.
# Runs each reference scenario (this folder, plus the closed room, the
# dense hallway and the open hallway's timeline of the tests) with 1 and 2 threads and prints, per run,
# the SHA-256 of its per-frame tables (trajectory_data, person_state, contact,
# frame_time; tests/cli/run_tables.sh). Run it before and after a refactoring
# and compare the two lists; they must be identical, line for line.
#
#   bench/reference/checksums.sh [CROWDRECON] > before.txt
#   ...change...
#   bench/reference/checksums.sh [CROWDRECON] > after.txt && diff before.txt after.txt
#   bench/reference/checksums.sh --check [CROWDRECON]   # against checksums.txt (a ctest)
# The two hallway-extensions-* scenes switch on every behaviour extension of
# the drive (each one changes their results: switched off one at a time, each
# gives other tables), the timeline a group's own back force and arrivals;
# hallway-validated and door-validated run the profile validated (anticipation
# by time to collision across a periodic boundary and among walls, yielding,
# gait jitter), timeline-validated with arrivals into empty slots (the
# neighbour stage's list at a placement, ListComebacks): they change when
# that profile's values change.
# checksums.txt holds the values of the current model: a change of physics
# changes them on purpose (then regenerate it and say so in the commit); a
# change of structure must not.
set -euo pipefail
cd "$(dirname "$0")/../.."
if [[ "${1:-}" == "--check" ]]; then
  shift
  expected=bench/reference/checksums.txt
  actual=$(mktemp)
  trap 'rm -f "$actual"' EXIT
  bash "$0" "$@" >"$actual"
  if diff -u "$expected" "$actual"; then
    echo "reference checksums: all $(wc -l <"$expected") runs identical to $expected"
    exit 0
  fi
  echo "reference checksums differ from $expected (above): a change of structure changed results"
  exit 1
fi
exe=${1:-build/release/cli/crowdrecon}
source tests/cli/run_tables.sh
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scenarios=(bench/reference/*.json tests/data/scenarios/closed-room-polygon.json tests/data/scenarios/dense-7pm2.json
           tests/data/scenarios/timeline-hallway.json)
for scenario in "${scenarios[@]}"; do
  for threads in 1 2; do
    "$exe" simulate "$scenario" -o "$tmp/run.sqlite" --threads "$threads" --fixed-threads -q --force >/dev/null
    rows=$(sqlite3 "$tmp/run.sqlite" "SELECT COUNT(*) FROM trajectory_data")
    contacts=$(sqlite3 "$tmp/run.sqlite" "SELECT COUNT(*) FROM contact")
    printf '%s  %s threads=%s rows=%s contacts=%s\n' "$(dump "$tmp/run.sqlite")" "$(basename "$scenario" .json)" \
      "$threads" "$rows" "$contacts"
  done
done
