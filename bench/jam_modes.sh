#!/usr/bin/env bash
# Two ways of running a frozen jam, timed in turn (the machine's speed
# drifts): the periodic Madrid Arena hallway at 9 /m2 with 40 % counter-flow
# (seed 3) is run to 95 s in each mode (the jam forms and freezes), then its
# last 55 s are timed, resumed from the checkpoint at 95 s, REPEAT times, the
# two modes in turn. A mode is a name and a JSON object of model settings;
# PROFILE (empty: the scenario's) names the model profile. Prints per repeat
# the line of the run's summary that starts with SUMMARY (or "-"), then the
# median wall time of the 55 s per mode and their ratio A / B.
# The benches bench/adaptive_step_jam.sh and bench/sleeping_jam.sh call it.
# usage: bench/jam_modes.sh CROWDRECON REPEAT THREADS PROFILE SUMMARY NAME_A JSON_A NAME_B JSON_B
set -euo pipefail
exe=$(realpath "$1"); repeat=$2; threads=$3; profile=$4; summary=$5
names=("$6" "$8"); settings=("$7" "$9")
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg); $("$exe" --version)"
for k in 0 1; do
  mode=${names[$k]}
  python3 - "$src" "${settings[$k]}" "$work/jam-$mode.json" "$profile" <<'PY'
import json, sys, pathlib
src, settings, out, profile = pathlib.Path(sys.argv[1]), json.loads(sys.argv[2]), sys.argv[3], sys.argv[4]
base = src / "venues/madrid-arena/scenarios/hallway-5pm2-30cf.json"
d = json.loads(base.read_text())
d["venue"] = str((base.parent / d["venue"]).resolve())
d["population"]["body"]["reference"] = str((base.parent / d["population"]["body"]["reference"]).resolve())
d["population"].update({"density_per_m2": 9.0, "counter_flow_fraction": 0.4, "seed": 3})
if profile:
    d["profile"] = profile
d["model"].update(settings)
d["run"].update({"duration_s": 150, "checkpoint_interval_s": 0, "contacts": True})
pathlib.Path(out).write_text(json.dumps(d, indent=1))
PY
  set +e
  "$exe" simulate "$work/jam-$mode.json" -o "$work/jam-$mode.sqlite" --threads "$threads" --stop-after 95 >/dev/null 2>&1
  rc=$?
  set -e
  [[ $rc -eq 130 ]] || { echo "the run to 95 s ($mode) exited $rc"; exit 1; }
done
declare -A times
for rep in $(seq 1 "$repeat"); do
  for mode in "${names[@]}"; do
    cp "$work/jam-$mode.sqlite" "$work/r.sqlite"; cp "$work/jam-$mode.sqlite.checkpoint" "$work/r.sqlite.checkpoint"
    rm -f "$work/r.sqlite-wal" "$work/r.sqlite-shm"
    start=$(date +%s.%N)
    "$exe" simulate "$work/jam-$mode.json" -o "$work/r.sqlite" --threads "$threads" --resume >"$work/$mode.out" 2>&1
    t=$(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN {printf "%.2f", e - s}')
    times[$mode]="${times[$mode]:-} $t"
    echo "rep $rep $mode: $t s; $(grep -E "^$summary" "$work/$mode.out" || echo '-')"
  done
done
median() { tr ' ' '\n' | grep -v '^$' | sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
ma=$(echo "${times[${names[0]}]}" | median); mb=$(echo "${times[${names[1]}]}" | median)
echo "median wall for the last 55 s of the jam${profile:+ ($profile)}: ${names[0]} $ma s, ${names[1]} $mb s, ratio $(awk -v a="$ma" -v b="$mb" 'BEGIN {printf "%.2f", a / b}')"
