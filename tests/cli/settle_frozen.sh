#!/usr/bin/env bash
# A run known to freeze stops when settled (run.stop_when_settled, issue 19):
# the open-decision study's full-size-bodies run at 4.5 /m2, 30 % counter-flow,
# seed 2 froze; simulated to 240 s, `analyze --settle-check` found that it
# would stop frozen at 65.0 s with the 240 s verdict (clogging). Simulated
# with the stop, it must stop there, complete, and its analysis say clogging.
# usage: settle_frozen.sh CROWDRECON SCENARIO
set -euo pipefail
exe=$1; scenario=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
"$exe" simulate "$scenario" -o "$tmp/a.sqlite" --threads 2 -q >/dev/null
settled=$(sqlite3 "$tmp/a.sqlite" "SELECT value FROM run WHERE key='settled'")
echo "settled: $settled"
[[ $settled == "settled frozen at 65.0 s: every direction frozen at the end"* ]] || fail "expected to settle frozen at 65.0 s"
[[ $(sqlite3 "$tmp/a.sqlite" "SELECT value FROM run WHERE key='status'") == complete ]] || fail "status"
"$exe" analyze "$tmp/a.sqlite" > "$tmp/a.txt"
grep -q "^regime: clogging (every direction frozen at the end" "$tmp/a.txt" || { cat "$tmp/a.txt"; fail "verdict"; }
echo "settled frozen: OK"
