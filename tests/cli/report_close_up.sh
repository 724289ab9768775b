#!/usr/bin/env bash
# The force network's close-up (issue 43: a 3-m alley in a 75-m street
# network is unreadable in the whole view): with --close-up S on a run whose
# whole view is more than 3 S across, the report draws a second network, an
# S x S window around the most loaded person at the worst moment, inside the
# whole view (now the figure, the whole venue an inset beside it with the
# region marked: issue 65); with --close-up 0, none; a window out of range is refused.
#   report_close_up.sh CROWDRECON RUN_FILE
set -uo pipefail
exe=$1; run=$2
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail() { echo "report_close_up.sh: $*"; exit 1; }
"$exe" report "$run" -o "$d/none" --no-pdf -q --close-up 0 > /dev/null 2>&1 || fail "report --close-up 0 failed"
"$exe" report "$run" -o "$d/close" --no-pdf -q --close-up 2 > "$d/out.txt" 2>&1 || { cat "$d/out.txt"; fail "report --close-up 2 failed"; }
grep -q "the worst region" "$d/none/report.html" && fail "a close-up with --close-up 0"
caption=$(grep -o "the worst region, x [-0-9.]* to [-0-9.]* m, y [-0-9.]* to [-0-9.]* m, around person [0-9]*" "$d/close/report.html")
[[ -n $caption ]] || fail "no close-up caption with --close-up 2"
echo "$caption"
python3 - "$caption" <<'PY' || fail "the close-up is not a 2 m x 2 m window"
import re, sys
m = re.search(r"x (-?[0-9.]+) to (-?[0-9.]+) m, y (-?[0-9.]+) to (-?[0-9.]+) m", sys.argv[1])
x0, x1, y0, y1 = map(float, m.groups())
assert abs((x1 - x0) - 2) < 1e-3 and abs((y1 - y0) - 2) < 1e-3, (x0, x1, y0, y1)
PY
n_none=$(grep -o "<figure" "$d/none/report.html" | wc -l)
n_close=$(grep -o "<figure" "$d/close/report.html" | wc -l)
[[ $n_close -eq $((n_none + 1)) ]] || fail "expected one figure more with the close-up: $n_none and $n_close"
if "$exe" report "$run" -o "$d/bad" --no-pdf -q --close-up 0.2 > "$d/bad.txt" 2>&1; then fail "accepted --close-up 0.2"; fi
grep -q -- "--close-up: 0.2 m, expected 0 (none) or 0.5 .. 10000" "$d/bad.txt" || { cat "$d/bad.txt"; fail "no message for --close-up 0.2"; }
[[ ! -e $d/bad/report.html ]] || fail "wrote a report for a refused option"
echo "report_close_up.sh: $n_none figures without the close-up, $n_close with it"
