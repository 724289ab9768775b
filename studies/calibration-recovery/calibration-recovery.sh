#!/bin/bash
# The calibration's recovery problem (docs/calibration.md, "Recovery"): four
# synthetic recordings of the periodic Madrid Arena hallway made with known
# values of Γ, λ and ε (venues/madrid-arena/calibrations/hallway-recovery-truth.json),
# observed as footage or trajectories would be (venues/madrid-arena/observations/hallway.json),
# then calibrated from other starting values
# (venues/madrid-arena/calibrations/hallway-recovery.json).
#
#   studies/calibration-recovery/calibration-recovery.sh [OUT]        (default out/calibration/hallway-recovery)
#
#
# CROWDRECON names the program (default build/release/cli/crowdrecon);
# CALIBRATION_APPROACH=gradient runs the other approach on the same problem;
# RECOVERY_RECORDINGS=N (default 4) makes N recordings (seeds 1001 ...) and
# matches each as the four are matched: more information, the same runs.
# Their observation files then go to OUT-truth/observations/ (the default
# four, made into the default OUT, are the repository's). RECOVERY_SEEDS=K (default 8) runs K seeds per
# parameter set instead: the simulated means' error falls with K as the
# recordings' falls with N (docs/calibration.md, "The objective").
set -euo pipefail
cd "$(dirname "$0")/../.."  # the repository root: studies/NAME/ is two levels down
crowdrecon=${CROWDRECON:-build/release/cli/crowdrecon}
out=${1:-out/calibration/hallway-recovery}
dir=venues/madrid-arena/calibrations
recordings=${RECOVERY_RECORDINGS:-4}
seeds=${RECOVERY_SEEDS:-8}
approach=${CALIBRATION_APPROACH:-surrogate}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

truth="$dir/hallway-recovery-truth.json"
observations="$dir/recovery"
# The repository's four observation files are written only by the default
# run (they name its runs); any other OUT or N writes its own.
if [ "$recordings" != 4 ] || [ "$out" != out/calibration/hallway-recovery ]; then
  truth="$work/hallway-recovery-truth.json"
  observations="$out-truth/observations"
  python3 - "$dir/hallway-recovery-truth.json" "$truth" "$PWD/$dir" "$recordings" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))
t["scenario"] = sys.argv[3] + "/" + t["scenario"]
t["seeds"] = list(range(1001, 1001 + int(sys.argv[4])))
json.dump(t, open(sys.argv[2], "w"), indent=1, ensure_ascii=False)
PY
fi

echo "1. the synthetic recordings (known values; $recordings seeds from 1001)"
# (the recordings' runs are kept in OUT-truth/, the path their observations name)
"$crowdrecon" sweep "$truth" -o "$out-truth" -q
mkdir -p "$observations"
for run in "$out-truth"/runs/*.sqlite; do
  seed=${run##*-seed}
  seed=${seed%.sqlite}
  # (named relative to the repository, so that the shipped observation files
  # do not record one machine's folders)
  "$crowdrecon" observe trajectories "$(realpath --relative-to=. "$run")" \
    --spec venues/madrid-arena/observations/hallway.json \
    -o "$observations/truth-seed$seed.observation.json" -q --force
done

echo "2. the calibration"
calibration="$dir/hallway-recovery.json"
if [ "$approach" = gradient ] || [ "$observations" != "$dir/recovery" ] || [ "$seeds" != 8 ]; then
  calibration="$work/hallway-recovery-variant.json"
  python3 - "$dir/hallway-recovery.json" "$calibration" "$PWD/$dir" "$approach" "$recordings" \
    "$(cd "$observations" && pwd)" "$seeds" <<'PY'
import copy, json, sys
c = json.load(open(sys.argv[1]))
base, approach, recordings, observations = sys.argv[3], sys.argv[4], int(sys.argv[5]), sys.argv[6]
c["seeds"]["count"] = int(sys.argv[7])
c["scenario"] = base + "/" + c["scenario"]
if approach == "gradient":
    c["approach"] = "gradient"
    # The gradient approach also measures the objective's noise first, which
    # says whether its central differences see the slope.
    c["options"].update({"measure_noise": True, "max_iterations": 4})
if recordings != 4:
    c["name"] = c["name"].replace("four synthetic recordings", "%d synthetic recordings" % recordings)
# Every recording matched as the first one is.
first = c["observations"][0]
c["observations"] = []
for seed in range(1001, 1001 + recordings):
    o = copy.deepcopy(first)
    o["file"] = "%s/truth-seed%d.observation.json" % (observations, seed)
    c["observations"].append(o)
json.dump(c, open(sys.argv[2], "w"), indent=1, ensure_ascii=False)
PY
fi
/usr/bin/time -f "calibration: %e s wall, %M kB peak" "$crowdrecon" calibrate "$calibration" -o "$out"
