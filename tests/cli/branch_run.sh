#!/usr/bin/env bash
# A run branched at a checkpoint (issue 43, `simulate --branch-from`):
#   1. the open-hallway timeline without its recorded fall, interrupted at
#      1.2 s, branched under the timeline with it (a fall at 2 s) and run
#      on, gives the same tables as the timeline with it run whole;
#   2. the run branched from is untouched; a branch resumes like any run; the
#      branch's scenario may live in another folder (paths compared resolved);
#   3. a scenario that differs before the checkpoint (a seed, an event
#      before it) is refused naming the JSON path, and nothing is written;
#      -o the same as --branch-from, and --branch-from with --resume, are refused.
# usage: branch_run.sh CROWDRECON SCENARIO (tests/data/scenarios/timeline-hallway.json)
set -euo pipefail
exe=$1; scenario=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
python3 - "$scenario" "$tmp" <<'PY'
import json, os, sys
src, tmp = sys.argv[1], sys.argv[2]
base = os.path.dirname(os.path.abspath(src))
s = json.load(open(src))
s["venue"] = os.path.normpath(os.path.join(base, s["venue"]))
s["population"]["body"]["reference"] = os.path.normpath(os.path.join(base, s["population"]["body"]["reference"]))
with_fall = json.loads(json.dumps(s))
assert any("fall" in e for e in with_fall["timeline"]["events"])
s["timeline"]["events"] = [e for e in s["timeline"]["events"] if "fall" not in e]
s["name"] = "without the recorded fall"
json.dump(s, open(f"{tmp}/without.json", "w"))
json.dump(with_fall, open(f"{tmp}/with.json", "w"))
seed = json.loads(json.dumps(with_fall)); seed["population"]["seed"] += 1
json.dump(seed, open(f"{tmp}/seed.json", "w"))
early = json.loads(json.dumps(with_fall)); early["timeline"]["events"].append({"time_s": 0.5, "close_exit": "exit"})
json.dump(early, open(f"{tmp}/early.json", "w"))
# The same scenario in another folder, its files named relative to it.
os.makedirs(f"{tmp}/elsewhere")
moved = json.loads(json.dumps(with_fall))
moved["venue"] = os.path.relpath(moved["venue"], f"{tmp}/elsewhere")
moved["population"]["body"]["reference"] = os.path.relpath(moved["population"]["body"]["reference"], f"{tmp}/elsewhere")
json.dump(moved, open(f"{tmp}/elsewhere/with.json", "w"))
PY
set +e
"$exe" simulate "$tmp/without.json" -o "$tmp/a.sqlite" -q --stop-after 1.2 >/dev/null 2>&1
rc=$?
set -e
[[ $rc -eq 130 ]] || { echo "FAIL: the run to branch from exited $rc, expected 130"; exit 1; }
before=$("$exe" analyze "$tmp/a.sqlite" --digest); cp "$tmp/a.sqlite.checkpoint" "$tmp/a.checkpoint.copy"
"$exe" simulate "$tmp/with.json" -o "$tmp/whole.sqlite" -q >/dev/null
"$exe" simulate "$tmp/with.json" -o "$tmp/branch.sqlite" -q --branch-from "$tmp/a.sqlite" >/dev/null 2>"$tmp/branch.txt"
grep -q "branched from .*a.sqlite at t = 1.200 s" "$tmp/branch.txt" || { echo "FAIL: no branch note"; cat "$tmp/branch.txt"; exit 1; }
dw=$("$exe" analyze "$tmp/whole.sqlite" --digest); db=$("$exe" analyze "$tmp/branch.sqlite" --digest)
echo "whole: $dw"; echo "branch: $db"
[[ "$dw" == "$db" ]] || { echo "FAIL: the branch differs from the run made whole"; exit 1; }
[[ $(sqlite3 "$tmp/branch.sqlite" "SELECT COUNT(*) FROM event WHERE kind = 'recorded_fall'") == 1 ]] || { echo "FAIL: no recorded fall"; exit 1; }
[[ $(sqlite3 "$tmp/branch.sqlite" "SELECT value FROM run WHERE key = 'branched_from'") == *"a.sqlite at t = 1.2 s (frame 12)" ]] || { echo "FAIL: branched_from"; exit 1; }
[[ $("$exe" analyze "$tmp/a.sqlite" --digest) == "$before" ]] && cmp -s "$tmp/a.sqlite.checkpoint" "$tmp/a.checkpoint.copy" \
  || { echo "FAIL: the run branched from changed"; exit 1; }
# The branch's scenario may live in another folder (its file paths are compared as resolved).
"$exe" simulate "$tmp/elsewhere/with.json" -o "$tmp/moved.sqlite" -q --branch-from "$tmp/a.sqlite" >/dev/null 2>&1
[[ $("$exe" analyze "$tmp/moved.sqlite" --digest) == "$dw" ]] || { echo "FAIL: the branch from another folder differs"; exit 1; }
# A branch is a run like any: interrupted, it resumes to the same tables.
set +e
"$exe" simulate "$tmp/with.json" -o "$tmp/b2.sqlite" -q --branch-from "$tmp/a.sqlite" --stop-after 2.6 >/dev/null 2>&1
rc=$?
set -e
[[ $rc -eq 130 ]] || { echo "FAIL: the interrupted branch exited $rc"; exit 1; }
"$exe" simulate "$tmp/with.json" -o "$tmp/b2.sqlite" -q --resume >/dev/null
[[ $("$exe" analyze "$tmp/b2.sqlite" --digest) == "$dw" ]] || { echo "FAIL: the resumed branch differs"; exit 1; }
refused() {  # refused EXPECTED-MESSAGE ARGS...
  local expected=$1; shift
  set +e; "$exe" simulate "$@" -q >/dev/null 2>"$tmp/err.txt"; local rc=$?; set -e
  [[ $rc -ne 0 ]] || { echo "FAIL: accepted: $*"; exit 1; }
  grep -q -- "$expected" "$tmp/err.txt" || { echo "FAIL: '$expected' not in:"; cat "$tmp/err.txt"; exit 1; }
}
refused "seed.json: /population/seed: differs from the scenario of .*a.sqlite (a branch at t = 1.2 s may change only" \
  "$tmp/seed.json" -o "$tmp/x.sqlite" --branch-from "$tmp/a.sqlite"
refused "early.json: /timeline/events: the events before t = 1.2 s differ" "$tmp/early.json" -o "$tmp/x.sqlite" --branch-from "$tmp/a.sqlite"
[[ ! -e "$tmp/x.sqlite" && ! -e "$tmp/x.sqlite.checkpoint" ]] || { echo "FAIL: a refused branch wrote something"; exit 1; }
refused "the run to branch from" "$tmp/with.json" -o "$tmp/a.sqlite" --branch-from "$tmp/a.sqlite"
refused "excludes" "$tmp/with.json" -o "$tmp/y.sqlite" --branch-from "$tmp/a.sqlite" --resume
refused "has no checkpoint to branch from" "$tmp/with.json" -o "$tmp/y.sqlite" --branch-from "$tmp/whole.sqlite"
refused "not a crowdrecon run file" "$tmp/with.json" -o "$tmp/y.sqlite" --branch-from "$tmp/with.json"
echo "PASS"
