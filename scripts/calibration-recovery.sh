#!/bin/bash
# The calibration's recovery problem (docs/calibration.md, "Recovery"): four
# synthetic recordings of the periodic Madrid Arena hallway made with known
# values of Γ, λ and ε (venues/madrid-arena/calibrations/hallway-recovery-truth.json),
# observed as footage or trajectories would be (venues/madrid-arena/observations/hallway.json),
# then calibrated from other starting values
# (venues/madrid-arena/calibrations/hallway-recovery.json).
#
#   scripts/calibration-recovery.sh [OUT]        (default out/calibration/hallway-recovery)
#
# CROWDRECON names the program (default build/release/cli/crowdrecon);
# CALIBRATION_APPROACH=gradient runs the other approach on the same problem.
set -euo pipefail
cd "$(dirname "$0")/.."
crowdrecon=${CROWDRECON:-build/release/cli/crowdrecon}
out=${1:-out/calibration/hallway-recovery}
dir=venues/madrid-arena/calibrations
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "1. the synthetic recordings (known values; seeds 1001-1004)"
# (the recordings' runs are kept in OUT-truth/, the path their observations name)
"$crowdrecon" sweep "$dir/hallway-recovery-truth.json" -o "$out-truth" -q
mkdir -p "$dir/recovery"
for run in "$out-truth"/runs/*.sqlite; do
  seed=${run##*-seed}
  seed=${seed%.sqlite}
  "$crowdrecon" observe trajectories "$run" --spec venues/madrid-arena/observations/hallway.json \
    -o "$dir/recovery/truth-seed$seed.observation.json" -q --force
done

echo "2. the calibration"
calibration="$dir/hallway-recovery.json"
if [ "${CALIBRATION_APPROACH:-surrogate}" = gradient ]; then
  calibration="$work/hallway-recovery-gradient.json"
  python3 - "$dir/hallway-recovery.json" "$calibration" "$PWD/$dir" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["approach"] = "gradient"
# The gradient approach also measures the objective's noise first, which
# says whether its central differences see the slope.
c["options"].update({"measure_noise": True, "max_iterations": 4})
c["scenario"] = sys.argv[3] + "/" + c["scenario"]
for o in c["observations"]:
    o["file"] = sys.argv[3] + "/" + o["file"]
json.dump(c, open(sys.argv[2], "w"), indent=1, ensure_ascii=False)
PY
fi
/usr/bin/time -f "calibration: %e s wall, %M kB peak" "$crowdrecon" calibrate "$calibration" -o "$out"
