#!/bin/bash
# observe fd on trajectories that never enter the measurement area is
# refused, naming the file and the area, and writes nothing (issue 40:
# before, "density 1000000000-0" and an empty diagram).
# Usage: fd_without_people.sh CROWDRECON SCENARIO SPEC
set -euo pipefail
crowdrecon=$1
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
"$crowdrecon" simulate "$2" -o "$d/run.sqlite" -q > /dev/null 2>&1
python3 - "$3" "$d/far.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
for r in s["regions"]:
    r["polygon"] = [[x + 100, y] for x, y in r["polygon"]]
json.dump(s, open(sys.argv[2], "w"))
PY
if "$crowdrecon" observe fd "$d/run.sqlite" --spec "$d/far.json" -o "$d/fd.png" > "$d/out.txt" 2>&1; then
  echo "accepted"; cat "$d/out.txt"; exit 1
fi
cat "$d/out.txt"
grep -q "run.sqlite: no frame (of every 5) has anyone in the measurement area" "$d/out.txt"
test ! -e "$d/fd.png"
echo "refused: OK"
