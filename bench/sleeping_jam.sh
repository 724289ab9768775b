#!/usr/bin/env bash
# Sleeping in a jam (issue 66, point 3): the periodic Madrid Arena hallway at
# 9 /m2 with 40 % counter-flow (seed 3), PROFILE's model (paper by default),
# is run to 95 s with sleeping off and on (2 mm/s over 1 s, wake at 20 N:
# studies/sleeping/) (the jam forms and freezes), then its last 55 s are
# timed, resumed from the checkpoint at 95 s, REPEAT times, the two in turn
# (interleaved on a machine whose speed drifts). Prints per mode the median
# wall time of the 55 s, the share of steps asleep, and the ratio off / on.
# usage: bench/sleeping_jam.sh CROWDRECON [REPEAT=3] [THREADS=1] [PROFILE=paper]
set -euo pipefail
exe=$(realpath "$1"); repeat=${2:-3}; threads=${3:-1}; profile=${4:-paper}
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg); $("$exe" --version)"
for mode in off on; do
  python3 - "$src" "$mode" "$work/jam-$mode.json" "$profile" <<'PY'
import json, sys, pathlib
src, mode, out, profile = pathlib.Path(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
base = src / "venues/madrid-arena/scenarios/hallway-5pm2-30cf.json"
d = json.loads(base.read_text())
d["venue"] = str((base.parent / d["venue"]).resolve())
d["population"]["body"]["reference"] = str((base.parent / d["population"]["body"]["reference"]).resolve())
d["population"].update({"density_per_m2": 9.0, "counter_flow_fraction": 0.4, "seed": 3})
d["profile"] = profile
d["model"].update({"sleep_speed_m_per_s": 0.002 if mode == "on" else 0.0, "sleep_time_s": 1.0, "sleep_wake_force_n": 20.0})
d["run"].update({"duration_s": 150, "checkpoint_interval_s": 0, "contacts": True})
pathlib.Path(out).write_text(json.dumps(d, indent=1))
PY
  set +e
  "$exe" simulate "$work/jam-$mode.json" -o "$work/jam-$mode.sqlite" --threads "$threads" --stop-after 95 >/dev/null 2>&1
  rc=$?
  set -e
  [[ $rc -eq 130 ]] || { echo "the run to 95 s exited $rc"; exit 1; }
done
declare -A times
for rep in $(seq 1 "$repeat"); do
  for mode in off on; do
    cp "$work/jam-$mode.sqlite" "$work/r.sqlite"; cp "$work/jam-$mode.sqlite.checkpoint" "$work/r.sqlite.checkpoint"
    rm -f "$work/r.sqlite-wal" "$work/r.sqlite-shm"
    start=$(date +%s.%N)
    "$exe" simulate "$work/jam-$mode.json" -o "$work/r.sqlite" --threads "$threads" --resume >"$work/$mode.out" 2>&1
    t=$(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN {printf "%.2f", e - s}')
    times[$mode]="${times[$mode]:-} $t"
    echo "rep $rep $mode: $t s; $(grep -E '^sleeping' "$work/$mode.out" || echo 'sleeping off')"
  done
done
median() { tr ' ' '\n' | grep -v '^$' | sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
mf=$(echo "${times[off]}" | median); ma=$(echo "${times[on]}" | median)
echo "median wall for the last 55 s of the jam ($profile): sleeping off $mf s, on $ma s, ratio $(awk -v f="$mf" -v a="$ma" 'BEGIN {printf "%.2f", f / a}')"
