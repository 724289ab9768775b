#!/bin/bash
# Reading a long run: the wall and processor time of `report` and `timeline`
# on one run file, for two builds in turn (bench/RESULTS.md, "Reading a long
# run's validity once").
#   bench/long_run_reading.sh OLD_CROWDRECON NEW_CROWDRECON RUN.sqlite [OUT_DIR]
set -euo pipefail
[[ $# -ge 3 ]] || { echo "usage: $0 OLD_CROWDRECON NEW_CROWDRECON RUN.sqlite [OUT_DIR]" >&2; exit 2; }
old=$1 new=$2 run=$3 out=${4:-$(mktemp -d)}
mkdir -p "$out"
measure() {  # label binary command...
  local label=$1 bin=$2
  shift 2
  /usr/bin/time -f "$label %e s wall %U s user %S s sys" "$bin" "$@" > /dev/null 2>> "$out/times.log"
}
echo "$(date -u +%FT%TZ) $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), run $run ($(du -h "$run" | cut -f1))" >> "$out/times.log"
# Alternating order, so that a change of the machine's load falls on both.
measure report-new "$new" report "$run" -o "$out/report-new" --force -q
measure timeline-old "$old" timeline "$run" -o "$out/timeline-old.png" --force
measure timeline-new "$new" timeline "$run" -o "$out/timeline-new.png" --force
measure report-old "$old" report "$run" -o "$out/report-old" --force -q
cat "$out/times.log"
