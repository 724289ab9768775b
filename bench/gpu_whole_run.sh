#!/usr/bin/env bash
# The 6,800-person evacuation's first simulated minute, whole (placement,
# steps, every frame with its contacts written), on a GPU machine (issue 42,
# point 3): once with the person-pair forces on CUDA and once on the
# processor, all cores, the same lean build, in one call. Run it from the
# repository root with the lean bundle carried along (scripts/lean-bundle.sh;
# the device tool's `carry: ["build/lean-bundle"]`):
#
#   bash bench/gpu_whole_run.sh [--seconds 60] [--devices cuda,cpu] [--bundle build/lean-bundle]
#
# Prints the machine, then per device the wall time, the simulated time, the
# real-time factor and minutes per simulated minute (the budget: 4 on two
# cores), the engine's stage profile and the run file's size; the run files
# stay in a temporary folder and are removed (they are hundreds of MB).
# A run stopped by --stop-after exits 130, which is what is expected here.
set -uo pipefail
seconds=60; devices=cuda,cpu; bundle=build/lean-bundle
while [[ $# -gt 0 ]]; do
  case $1 in
    --seconds) seconds=$2; shift 2 ;;
    --devices) devices=$2; shift 2 ;;
    --bundle) bundle=$2; shift 2 ;;
    *) echo "gpu_whole_run: unknown argument $1" >&2; exit 2 ;;
  esac
done
exe="$bundle/crowdrecon-simulate"
[[ -x "$exe" ]] || { echo "gpu_whole_run: $exe is missing: run scripts/lean-bundle.sh here and carry $bundle" >&2; exit 2; }
scenario=venues/madrid-arena/scenarios/evacuation-6800.json
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
echo "machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo), $(uname -r)"
if command -v nvidia-smi >/dev/null; then nvidia-smi -L; else echo "no nvidia-smi: no GPU here"; fi
echo "build: $("$exe" --version), scenario $scenario, first $seconds simulated s"
status=0
for device in ${devices//,/ }; do
  echo "--- device $device, $(nproc) threads"
  start=$(date +%s.%N)
  "$exe" simulate "$scenario" -o "$work/$device.sqlite" --device "$device" --threads "$(nproc)" \
    --stop-after "$seconds" >"$work/$device.out" 2>"$work/$device.err"
  rc=$?
  wall=$(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN {printf "%.1f", e - s}')
  grep -E "^(people|simulated|engine time|run loop|adaptive step)" "$work/$device.out"
  if [[ $rc -ne 130 && $rc -ne 0 ]]; then
    echo "device $device: exit $rc"; tail -5 "$work/$device.err"; status=1; continue
  fi
  grep -E "note:|warning:" "$work/$device.err" | head -5
  echo "wall $wall s for $seconds simulated s: $(awk -v w="$wall" -v s="$seconds" 'BEGIN {printf "%.2f min per simulated minute", w / s}'), run file $(du -h "$work/$device.sqlite" | cut -f1)"
  rm -f "$work/$device.sqlite"*
done
exit $status
