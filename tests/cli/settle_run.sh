#!/usr/bin/env bash
# Runs that stop when their regime has settled (run.stop_when_settled, issue 19):
#   1. the run ends before its duration, complete, with the reason as run
#      value `settled` and a `settled` event, and its analysis gives the
#      verdict that stopped it;
#   2. interrupted before the stop and resumed, it stops at the same frame
#      with the same tables (the settle check's state is in the checkpoint);
#   3. `analyze --settle-check` replays the check on a run file: on the
#      stopped run (with its own options) it finds the same stop; on the same
#      crowd simulated to its full length (70 s, no stop_when_settled: the
#      default options, a 60 s lanes window) it stops at 61 s with the whole
#      run's verdict.
# usage: settle_run.sh CROWDRECON SETTLE_SCENARIO FULL_SCENARIO
set -euo pipefail
exe=$1; scenario=$2; full=$3
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
source "$(dirname "$0")/run_tables.sh"  # dump RUN.sqlite: hash of its per-frame tables
fail() { echo "FAIL: $*"; exit 1; }

"$exe" simulate "$scenario" -o "$tmp/a.sqlite" --threads 1 -q >/dev/null
value() { sqlite3 "$1" "SELECT value FROM run WHERE key='$2'"; }
[[ $(value "$tmp/a.sqlite" status) == complete ]] || fail "status $(value "$tmp/a.sqlite" status)"
settled=$(value "$tmp/a.sqlite" settled)
echo "settled: $settled"
[[ $settled == "settled in lanes at 20.0 s"* ]] || fail "expected to settle in lanes at 20.0 s"
last=$(sqlite3 "$tmp/a.sqlite" "SELECT MAX(frame) FROM frame_time")
[[ $last == 200 ]] || fail "last frame $last, expected 200 (20 s at 10 frames/s; the duration is 120 s)"
[[ $(sqlite3 "$tmp/a.sqlite" "SELECT frame || ' ' || kind FROM event") == "200 settled" ]] || fail "no settled event at frame 200"
"$exe" analyze "$tmp/a.sqlite" > "$tmp/a.txt"
grep -q "^regime: lanes" "$tmp/a.txt" || { cat "$tmp/a.txt"; fail "the stopped run's verdict is not lanes"; }

set +e
"$exe" simulate "$scenario" -o "$tmp/r.sqlite" --threads 2 -q --stop-after 9 >/dev/null 2>&1
rc=$?
set -e
[[ $rc -eq 130 ]] || fail "interrupted run exited $rc, expected 130"
"$exe" simulate "$scenario" -o "$tmp/r.sqlite" --threads 1 -q --resume >/dev/null
[[ $(dump "$tmp/r.sqlite") == $(dump "$tmp/a.sqlite") ]] || fail "interrupted and resumed, the run differs"
[[ $(value "$tmp/r.sqlite" settled) == "$settled" ]] || fail "resumed, it settled differently: $(value "$tmp/r.sqlite" settled)"
echo "interrupted at 9 s and resumed: identical, settled at the same frame"
"$exe" analyze "$tmp/a.sqlite" --settle-check > "$tmp/a2.txt"
grep -q "^settle check: $settled\$" "$tmp/a2.txt" || { cat "$tmp/a2.txt"; fail "the replay of the stopped run differs from the run"; }

"$exe" simulate "$full" -o "$tmp/f.sqlite" --threads 1 -q >/dev/null
"$exe" analyze "$tmp/f.sqlite" --settle-check > "$tmp/f.txt"
grep "^settle check" "$tmp/f.txt"
grep -q "^settle check: settled in lanes at 61.0 s" "$tmp/f.txt" || fail "the replay does not stop at 61.0 s"
grep -q "^settle check: verdict at the stop lanes (61 s), of the whole run lanes (70 s): same" "$tmp/f.txt" || fail "verdicts"
echo "settle: OK"
