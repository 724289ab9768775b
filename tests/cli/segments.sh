#!/usr/bin/env bash
# Issue 66: a run in segments (simulate --stop-after, then --continue-from
# into a new file, and again) is the run made in one go. The scenario run
# whole (two threads) and in three segments (the second on one thread, in
# another folder): the chain's digest is the whole run's (every per-frame
# table, value for value: also packed frames, and contacts kept at the worst
# moment, whose superseded rows a later segment drops in an earlier one);
# analyze, timeline, report, export and render read the last segment as the
# whole run, and export --tables writes it as one file with the same digest; a segment killed is resumed in place; and what cannot be a
# chain is refused: a missing segment, a complete run, another scenario, the
# segment itself as the output.
#   segments.sh CROWDRECON SCENARIO [OTHER_SCENARIO]
set -euo pipefail
cr=$1 scenario=$2 other=${3:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
source "$(dirname "${BASH_SOURCE[0]}")/same_outputs.sh"
mkdir -p "$tmp/whole" "$tmp/chain/b"

"$cr" simulate "$scenario" -o "$tmp/whole/run.sqlite" -q --threads 2 > /dev/null 2>&1
whole=$("$cr" analyze "$tmp/whole/run.sqlite" --digest)
(cd "$tmp/chain"
 "$cr" simulate "$scenario" -o seg1.sqlite -q --stop-after 1.55 > /dev/null 2>&1 || true
 [[ $(sqlite3 seg1.sqlite "SELECT value FROM run WHERE key = 'status'") == interrupted ]] || fail "segment 1 not stopped"
 "$cr" simulate "$scenario" -o b/seg2.sqlite -q --continue-from seg1.sqlite --stop-after 3.05 --threads 1 > /dev/null 2>&1 || true
 [[ $(sqlite3 b/seg2.sqlite "SELECT value FROM run WHERE key = 'continues'") == ../seg1.sqlite ]] || fail "continues"
 "$cr" simulate "$scenario" -o run.sqlite -q --continue-from b/seg2.sqlite > /dev/null 2>&1)
chain=$("$cr" analyze "$tmp/chain/run.sqlite" --digest)
[[ $chain == "$whole" ]] || fail "the chain's digest differs from the whole run's: $chain / $whole"
echo "three segments: the whole run's digest ($whole)"
[[ $(sqlite3 "$tmp/chain/run.sqlite" "SELECT MIN(frame) FROM frame_time") -gt 30 ]] || fail "the last segment holds early frames"

"$cr" export "$tmp/chain/run.sqlite" -o "$tmp/joined.sqlite" --tables > /dev/null
[[ $("$cr" analyze "$tmp/joined.sqlite" --digest) == "$whole" ]] || fail "export --tables of the chain differs"
echo "export --tables: one file, the whole run's digest"

write_outputs "$cr" "$tmp/whole"
write_outputs "$cr" "$tmp/chain"
same_outputs "$tmp/whole" "$tmp/chain" || fail "outputs differ"

# A segment killed before its end is resumed in place.
(cd "$tmp/chain"
 "$cr" simulate "$scenario" -o again.sqlite -q --continue-from b/seg2.sqlite --stop-after 3.5 > /dev/null 2>&1 || true
 "$cr" simulate "$scenario" -o again.sqlite -q --resume > /dev/null 2>&1)
[[ $("$cr" analyze "$tmp/chain/again.sqlite" --digest) == "$whole" ]] || fail "a segment resumed differs"
echo "a segment stopped and resumed: the same run"

refused() {  # refused WHAT PATTERN COMMAND...
  local what=$1 pattern=$2 out
  shift 2
  if out=$("$@" 2>&1); then fail "$what: accepted"; fi
  grep -q -- "$pattern" <<< "$out" || fail "$what: said: $out"
  echo "refused, $what: $(grep -m1 -- "$pattern" <<< "$out" | cut -c1-160)"
}
refused "a complete run" 'only a segment stopped at its checkpoint' \
  "$cr" simulate "$scenario" -o "$tmp/x.sqlite" -q --continue-from "$tmp/whole/run.sqlite"
refused "the segment as its own continuation" 'an input is never overwritten' \
  "$cr" simulate "$scenario" -o "$tmp/chain/seg1.sqlite" -q --continue-from "$tmp/chain/seg1.sqlite" --force
if [[ -n $other ]]; then
  refused "another scenario" 'scenario' "$cr" simulate "$other" -o "$tmp/y.sqlite" -q --continue-from "$tmp/chain/b/seg2.sqlite"
fi
# A segment's head (export --segment-head): the segment without its frames
# and a copy of its checkpoint, all another machine needs to go on. Carried
# alone to a new folder, continued there twice: the chain is refused while
# the head stands in for the segment, and is the whole run once the whole
# segment is put in its place.
mkdir -p "$tmp/heads" "$tmp/far/b"
"$cr" export "$tmp/chain/seg1.sqlite" -o "$tmp/heads/seg1.sqlite" --segment-head > "$tmp/head.txt"
grep -q "segment head: $tmp/heads/seg1.sqlite at t = " "$tmp/head.txt" || fail "the head's line: $(cat "$tmp/head.txt")"
[[ -s "$tmp/heads/seg1.sqlite.checkpoint" ]] || fail "no checkpoint beside the head"
cmp -s "$tmp/heads/seg1.sqlite.checkpoint" "$tmp/chain/seg1.sqlite.checkpoint" || fail "the head's checkpoint is not the segment's"
[[ $(stat -c %s "$tmp/heads/seg1.sqlite") -lt $(stat -c %s "$tmp/chain/seg1.sqlite") ]] || fail "the head is not smaller"
[[ $(sqlite3 "$tmp/heads/seg1.sqlite" "SELECT COUNT(*) FROM frame_time") == 1 ]] || fail "the head keeps more than its last frame's time"
cp "$tmp/heads/seg1.sqlite" "$tmp/heads/seg1.sqlite.checkpoint" "$tmp/far/"
(cd "$tmp/far"
 "$cr" simulate "$scenario" -o b/seg2.sqlite -q --continue-from seg1.sqlite --stop-after 3.05 --threads 1 > /dev/null 2>&1 || true
 [[ $(sqlite3 b/seg2.sqlite "SELECT value FROM run WHERE key = 'status'") == interrupted ]] || fail "the head's continuation not stopped"
 "$cr" simulate "$scenario" -o run.sqlite -q --continue-from b/seg2.sqlite > /dev/null 2>&1)
refused "a chain through a head" "which is a segment's head" "$cr" analyze "$tmp/far/run.sqlite"
refused "a head read as a run" "is a segment's head" "$cr" analyze "$tmp/far/seg1.sqlite"
refused "a head of a head" "a segment's head already" "$cr" export "$tmp/far/seg1.sqlite" -o "$tmp/far/again.sqlite" --segment-head
refused "a head of a complete run" 'made of a segment stopped' \
  "$cr" export "$tmp/whole/run.sqlite" -o "$tmp/whole-head.sqlite" --segment-head
cp "$tmp/chain/seg1.sqlite" "$tmp/far/seg1.sqlite"
[[ $("$cr" analyze "$tmp/far/run.sqlite" --digest) == "$whole" ]] || fail "continued from a head, then made whole: not the whole run"
echo "a segment's head: continued elsewhere, the whole run once the segment is back"

mv "$tmp/chain/seg1.sqlite" "$tmp/seg1-moved.sqlite"
refused "a missing segment" 'which is not there' "$cr" analyze "$tmp/chain/run.sqlite"
echo "segments: the run made in one go"
