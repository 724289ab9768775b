#!/usr/bin/env bash
# `simulate --resume` of a run that stopped before its first checkpoint (issue
# 17): the run starts again from the beginning and ends byte-identical to an
# uninterrupted run; a run file that cannot be resumed is named exactly.
#   1. killed (SIGKILL) before its first checkpoint, then --resume;
#   2. stopped with --stop-after before the first periodic checkpoint, its
#      checkpoint lost, then --resume;
#   3. --resume of a complete run, of a missing file and of another
#      scenario's run: a message saying which.
# usage: resume_before_checkpoint.sh CROWDRECON SCENARIO
set -euo pipefail
exe=$1; scenario=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
source "$(dirname "$0")/run_tables.sh"  # dump RUN.sqlite: hash of its per-frame tables
fail() { echo "FAIL: $*"; exit 1; }
# The scenario with no periodic checkpoint: a kill always comes before the first.
# (Its relative paths made absolute, as the copy lives elsewhere.)
dir=$(cd "$(dirname "$scenario")" && pwd)
sc="$tmp/no-checkpoint.json"
sed -e 's#"checkpoint_interval_s": [0-9.]*#"checkpoint_interval_s": 0#' -e "s#\"\.\./#\"$dir/../#g" "$scenario" >"$sc"

"$exe" simulate "$sc" -o "$tmp/full.sqlite" --threads 1 -q >/dev/null
ref=$(dump "$tmp/full.sqlite")
echo "uninterrupted: $ref"

# 1. Killed after a few frames, with no checkpoint yet.
"$exe" simulate "$sc" -o "$tmp/k.sqlite" --threads 1 -q >/dev/null 2>&1 &
pid=$!
for _ in $(seq 1 600); do
  [[ $(last_frame "$tmp/k.sqlite") -ge 3 ]] && break
  sleep 0.05
done
kill -9 $pid 2>/dev/null || true
wait $pid 2>/dev/null || true
[[ ! -e "$tmp/k.sqlite.checkpoint" ]] || fail "a checkpoint exists although the interval is 0"
echo "killed after frame $(sqlite3 "$tmp/k.sqlite" "SELECT MAX(frame) FROM frame_time"), no checkpoint"
"$exe" simulate "$sc" -o "$tmp/k.sqlite" --threads 2 -q --resume >/dev/null 2>"$tmp/k.txt" || { cat "$tmp/k.txt"; fail "resume after kill"; }
grep -q "has no checkpoint yet.*starting it again from the beginning" "$tmp/k.txt" || { cat "$tmp/k.txt"; fail "no note"; }
[[ $(dump "$tmp/k.sqlite") == "$ref" ]] || fail "killed + resumed differs from the uninterrupted run"
echo "killed + resumed: identical"

# 2. Stopped before the first periodic checkpoint of the original scenario
#    (interval 0.5 s), its stop checkpoint lost.
"$exe" simulate "$scenario" -o "$tmp/s.sqlite" -q --stop-after 0.2 >/dev/null 2>&1 && fail "--stop-after did not stop"
rm -f "$tmp/s.sqlite.checkpoint"
"$exe" simulate "$scenario" -o "$tmp/s.sqlite" -q --resume >/dev/null 2>&1 || fail "resume after stop"
# (Checkpoints do not change results: the uninterrupted run above is the reference.)
[[ $(dump "$tmp/s.sqlite") == "$ref" ]] || fail "stopped + resumed differs"
echo "stopped (checkpoint lost) + resumed: identical"

# 3. What cannot be resumed is said exactly.
expect_fail() {  # REGEX ARGS...
  local regex=$1; shift
  if "$exe" "$@" >"$tmp/m.txt" 2>&1; then fail "$* succeeded"; fi
  grep -Eq -- "$regex" "$tmp/m.txt" || { cat "$tmp/m.txt"; fail "message does not match /$regex/"; }
  echo "refused as expected: $(tail -1 "$tmp/m.txt")"
}
expect_fail "full.sqlite: nothing to resume: the run is complete; run without --resume" \
  simulate "$sc" -o "$tmp/full.sqlite" -q --resume
expect_fail "none.sqlite: nothing to resume: the run file does not exist; start the run without --resume" \
  simulate "$sc" -o "$tmp/none.sqlite" -q --resume
"$exe" simulate "$scenario" -o "$tmp/other.sqlite" -q --stop-after 0.2 >/dev/null 2>&1 || true
rm -f "$tmp/other.sqlite.checkpoint"
expect_fail "other.sqlite: nothing to resume: the run file was written for a different scenario" \
  simulate "$sc" -o "$tmp/other.sqlite" -q --resume
echo "resume before the first checkpoint: OK"
