#!/usr/bin/env bash
# The adaptive step in a jam (issue 42): the periodic Madrid Arena hallway at
# 9 /m2 with 40 % counter-flow (seed 3) is run to 95 s with each step (the
# jam forms and freezes), then its last 55 s are timed, resumed from the
# checkpoint at 95 s, REPEAT times, the two steps in turn (interleaved on a
# machine whose speed drifts). Prints per step the median wall time of the
# 55 s, its steps by length, and the ratio fixed / adaptive.
# usage: bench/adaptive_step_jam.sh CROWDRECON [REPEAT=3] [THREADS=1]
set -euo pipefail
exe=$(realpath "$1"); repeat=${2:-3}; threads=${3:-1}
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg); $("$exe" --version)"
for mode in fixed adaptive; do
  python3 - "$src" "$mode" "$work/jam-$mode.json" <<'PY'
import json, sys, pathlib
src, mode, out = pathlib.Path(sys.argv[1]), sys.argv[2], sys.argv[3]
base = src / "venues/madrid-arena/scenarios/hallway-5pm2-30cf.json"
d = json.loads(base.read_text())
d["venue"] = str((base.parent / d["venue"]).resolve())
d["population"]["body"]["reference"] = str((base.parent / d["population"]["body"]["reference"]).resolve())
d["population"].update({"density_per_m2": 9.0, "counter_flow_fraction": 0.4, "seed": 3})
d["model"]["time_step_mode"] = mode
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
  for mode in fixed adaptive; do
    cp "$work/jam-$mode.sqlite" "$work/r.sqlite"; cp "$work/jam-$mode.sqlite.checkpoint" "$work/r.sqlite.checkpoint"
    rm -f "$work/r.sqlite-wal" "$work/r.sqlite-shm"
    start=$(date +%s.%N)
    "$exe" simulate "$work/jam-$mode.json" -o "$work/r.sqlite" --threads "$threads" --resume >"$work/$mode.out" 2>&1
    t=$(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN {printf "%.2f", e - s}')
    times[$mode]="${times[$mode]:-} $t"
    echo "rep $rep $mode: $t s; $(grep -E '^adaptive step' "$work/$mode.out" || echo 'every step 1 h')"
  done
done
median() { tr ' ' '\n' | grep -v '^$' | sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
mf=$(echo "${times[fixed]}" | median); ma=$(echo "${times[adaptive]}" | median)
echo "median wall for the last 55 s of the jam: fixed $mf s, adaptive $ma s, ratio $(awk -v f="$mf" -v a="$ma" 'BEGIN {printf "%.2f", f / a}')"
