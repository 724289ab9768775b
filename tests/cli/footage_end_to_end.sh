#!/bin/bash
# Footage end to end (issue 22): a short run drawn as footage by a tilted
# camera (darkened, noisy, compressed), observed through the homography, and
# compared with the run's own trajectories: the main direction's stop and
# release found within 1 s, the mean speeds per direction within 20 %, the
# counter-flow share within 0.05, no event the trajectories do not have.
# The thresholds are the study's measured accuracies with a margin
# (studies/footage-study/results/README.md).
# Usage: footage_end_to_end.sh CROWDRECON SCENARIO SPEC
set -euo pipefail
crowdrecon=$1 scenario=$2 spec=$3
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
"$crowdrecon" simulate "$scenario" -o "$d/run.sqlite" -q > /dev/null
"$crowdrecon" observe trajectories "$d/run.sqlite" --spec "$spec" -o "$d/truth.json" -q > /dev/null
"$crowdrecon" observe synthesize "$d/run.sqlite" -o "$d/clip.avi" --homography-out "$d/h.json" \
  --darkness 0.5 --noise 3 --quality 75 > /dev/null
"$crowdrecon" observe footage "$d/clip.avi" --homography "$d/h.json" --spec "$spec" -o "$d/footage.json" -q \
  --figure "$d/figure.png" --reference "$d/truth.json" > /dev/null
test -s "$d/figure.png"
"$crowdrecon" observe compare "$d/truth.json" "$d/footage.json" --csv "$d/compare.csv" | tee "$d/compare.txt"
python3 - "$d/compare.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
def row(quantity, direction):
    found = [r for r in rows if r["quantity"] == quantity and r["direction"] == direction]
    assert found, f"no {quantity} {direction} in the comparison"
    return found[0]
failures = []
for direction in ("forward", "backward"):
    r = row("speed", direction)
    if abs(float(r["error_percent"])) > 20:
        failures.append(f"speed {direction}: {r['observed']} m/s against {r['reference']} ({r['error_percent']} %)")
r = row("counterflow_share", "all")
if abs(float(r["error"])) > 0.05:
    failures.append(f"counter-flow share {r['observed']} against {r['reference']}")
onsets = [r for r in rows if r["quantity"].endswith("_onset_s") and r["direction"] == "forward"]
kinds = sorted(r["quantity"] for r in onsets)
if kinds != ["stop_onset_s", "surge_onset_s"]:
    failures.append(f"the main direction's events: {kinds}, expected one stop and one surge")
for r in onsets:
    if r["observed"] == "" or abs(float(r["error"])) > 1.0:
        failures.append(f"{r['quantity']}: {r['observed'] or 'missed'} against {r['reference']} s")
extra = row("unmatched_events", "all")
if int(float(extra["observed"])) != 0:
    failures.append(f"{extra['observed']} events in the footage that the trajectories do not have")
if failures:
    print("FAILED:\n  " + "\n  ".join(failures))
    sys.exit(1)
print("footage end to end: speeds, counter-flow share and onsets within their bounds")
PY
