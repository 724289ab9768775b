#!/bin/bash
# The calibration's cheap recovery problem (docs/calibration.md, "Recovery"):
# three synthetic recordings of a small periodic hallway made with known
# values (desired speed 1.3 m/s, restitution 0.25), calibrated from the
# defaults and from a second start. Checks:
#   - the desired speed recovered within 10 % and reported determined, its
#     95 % interval holding the truth;
#   - the restitution within 10 % (determined), or reported undetermined,
#     or bounded on one side with the truth inside its interval (never a
#     confident wrong value, never a bound that excludes the truth);
#   - a second invocation on the same folder runs nothing and gives the same result;
#   - a folder with runs missing, interrupted (SIGINT) and continued, runs
#     only what is missing and gives the same result.
# The recordings are made with the calibration's own seeds (common random
# numbers with the observation), so that this cheap version tests the
# machinery; the full study (studies/calibration-recovery/calibration-recovery.sh) uses recordings
# of other seeds.
#
#   recovery_test.sh CROWDRECON DATA_DIR SPEC
set -euo pipefail
crowdrecon=$1
data=$2
spec=$3
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT

"$crowdrecon" sweep "$data/recovery-truth.json" -o "$d/truth" -q > /dev/null
for run in "$d"/truth/runs/*.sqlite; do
  seed=${run##*-seed}
  seed=${seed%.sqlite}
  "$crowdrecon" observe trajectories "$run" --spec "$spec" -o "$d/truth-seed$seed.observation.json" -q > /dev/null
done
python3 - "$data/recovery.json" "$d/recovery.json" "$data" "$d" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
import os
c["scenario"] = os.path.abspath(sys.argv[3]) + "/" + c["scenario"]
for o in c["observations"]:
    o["file"] = o["file"].replace("OBSDIR", sys.argv[4])
json.dump(c, open(sys.argv[2], "w"), indent=1)
PY

"$crowdrecon" calibrate "$d/recovery.json" -o "$d/out" -q | tee "$d/first.txt"
cat "$d/out/report.txt"

# Again on the same folder: nothing to run, the same result.
"$crowdrecon" calibrate "$d/recovery.json" -o "$d/out" -q > "$d/second.txt"
grep -q " 0 runs simulated now" "$d/second.txt" || { echo "FAIL: the second invocation ran something"; cat "$d/second.txt"; exit 1; }
cp "$d/out/calibration.json" "$d/first.json"

# Interrupted and continued: a copy of the folder with the last five sets'
# runs gone is continued, interrupted (SIGINT) after two seconds, continued
# again; it runs only what is missing and gives the same result.
cp -r "$d/out" "$d/again"
rm "$d/again/calibration.json"
python3 - "$d/again" <<'PY'
import json, shutil, sys
evals = json.load(open(sys.argv[1] + "/../first.json"))["evaluations"]
for e in evals[-5:]:
    shutil.rmtree(sys.argv[1] + "/cache/" + e["key"])
PY
set +e
timeout --preserve-status -s INT 2 "$crowdrecon" calibrate "$d/recovery.json" -o "$d/again" -q > "$d/interrupted.txt"
rc=$?
set -e
echo "interrupted invocation: exit status $rc"
cat "$d/interrupted.txt"
[ "$rc" = 130 ] || { echo "FAIL: expected exit status 130 from the interrupted calibration"; exit 1; }
grep -q "interrupted: run the same command again" "$d/interrupted.txt"
"$crowdrecon" calibrate "$d/recovery.json" -o "$d/again" -q > "$d/continued.txt"
cat "$d/continued.txt"
grep -Eq " ([1-9]|1[0-5]) runs simulated now" "$d/continued.txt" || { echo "FAIL: expected at most the 15 missing runs"; exit 1; }

python3 - "$d/first.json" "$d/again/calibration.json" <<'PY'
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
truth = {"population.desired_speed_m_per_s": 1.3, "model.restitution": 0.25}
ok = True
for p in a["parameters"]:
    t = truth[p["path"]]
    err = abs(p["value"] - t) / t
    lo, hi = p["ci95"]
    print(f'{p["path"]}: {p["value"]:.4f} (truth {t}, error {100*err:.1f} %), 95 % [{lo}, {hi}], '
          f'bootstrap {p["bootstrap_ci95"]}, {p["determination"]} {p["reason"]}')
    if p["path"] == "population.desired_speed_m_per_s":
        if not (err <= 0.10 and p["determination"] == "determined" and lo <= t <= hi):
            print("FAIL: the desired speed was not recovered within 10 % as determined with the truth in its interval"); ok = False
    elif p["determination"] == "determined" and not (err <= 0.10 and lo <= t <= hi):
        print("FAIL: a confident wrong restitution"); ok = False
    elif p["determination"] == "bounded on one side" and not lo <= t <= hi:
        print("FAIL: a bound on the restitution that excludes the truth"); ok = False
for key in ("wall_s", "runs_simulated_now", "calibration_file"):
    a.pop(key, None); b.pop(key, None)
if a != b:
    print("FAIL: the interrupted and continued calibration differs from the uninterrupted one"); ok = False
sys.exit(0 if ok else 1)
PY
