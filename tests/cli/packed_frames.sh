#!/usr/bin/env bash
# Issue 66: a run whose frames are packed (run.frames = "packed") is the run
# with tables, number for number. The same scenario written both ways: the
# tables' digest is equal (every row of trajectory_data, person_state,
# person_load, contact, events, census, briefs, value for value); the packed
# file's own tables are empty and table frame_pack holds every frame; what
# analyze, timeline, report and export write from either file is the same
# (their file names aside); the packed run stopped and resumed from its
# checkpoint, and the packed run on one thread, are the run made in one go
# on two; and the packed people take fewer bytes.
# With `lean`, SCENARIO_PACKED keeps the contacts of some frames only
# (run.contacts as an object: every 0.7 s and the worst moment): the same
# outputs except the frames drawn where it kept no contacts; the contact
# rows it keeps are the tables run's rows of those frames, the report's worst
# moment among them.
#   packed_frames.sh CROWDRECON SCENARIO_TABLES SCENARIO_PACKED [lean]
set -euo pipefail
cr=$1 tables=$2 packed=$3 lean=${4:-} kept=
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

mkdir "$tmp/t" "$tmp/p"
"$cr" simulate "$tables" -o "$tmp/t/run.sqlite" -q
"$cr" simulate "$packed" -o "$tmp/p/run.sqlite" -q
digest_t=$("$cr" analyze "$tmp/t/run.sqlite" --digest)
digest_p=$("$cr" analyze "$tmp/p/run.sqlite" --digest)
if [[ -z $lean ]]; then
  [[ $digest_t == "$digest_p" ]] || fail "digests differ: $digest_t / $digest_p"
  echo "digest equal: $digest_p"
else
  kept=$(sqlite3 "$tmp/p/run.sqlite" "SELECT group_concat(frame) FROM (SELECT frame FROM contact_kept ORDER BY frame)")
  [[ $(sqlite3 "$tmp/p/run.sqlite" "SELECT COUNT(*) FROM contact WHERE frame NOT IN (SELECT frame FROM contact_kept)") == 0 ]] ||
    fail "contact rows of frames other than the kept ones ($kept)"
  columns="frame, a, b, wall, point_x, point_y, normal_x, normal_y, overlap_m, normal_force_n, tangential_force_n"
  [[ $(sqlite3 "$tmp/p/run.sqlite" "SELECT $columns FROM contact ORDER BY frame, rowid" | sha256sum) == \
     $(sqlite3 "$tmp/t/run.sqlite" "SELECT $columns FROM contact WHERE frame IN ($kept) ORDER BY frame, rowid" | sha256sum) ]] ||
    fail "the kept contact rows differ from the tables run's"
  [[ $(sqlite3 "$tmp/p/run.sqlite" "SELECT COUNT(*) FROM contact_forces") == $(sqlite3 "$tmp/t/run.sqlite" "SELECT COUNT(*) FROM frame_time") ]] ||
    fail "contact_forces lacks frames"
  # Superseded worst moments are dropped: one frame at most is kept for being the worst alone.
  (( $(sqlite3 "$tmp/p/run.sqlite" "SELECT COUNT(*) FROM contact_kept WHERE why = 'worst moment so far'") <= 1 )) ||
    fail "superseded worst moments kept: $(sqlite3 "$tmp/p/run.sqlite" "SELECT group_concat(frame || ' ' || why) FROM contact_kept")"
  echo "kept contacts: frames $kept, the tables run's rows"
fi
[[ $(sqlite3 "$tmp/p/run.sqlite" "SELECT value FROM run WHERE key = 'frames'") == packed ]] || fail "run value frames"
rows=$(sqlite3 "$tmp/p/run.sqlite" "SELECT (SELECT COUNT(*) FROM trajectory_data) + (SELECT COUNT(*) FROM person_state) + (SELECT COUNT(*) FROM person_load)")
[[ $rows == 0 ]] || fail "the packed file has $rows rows in its tables"
[[ $(sqlite3 "$tmp/p/run.sqlite" "SELECT COUNT(*) FROM frame_pack") == $(sqlite3 "$tmp/t/run.sqlite" "SELECT COUNT(*) FROM frame_time") ]] ||
  fail "frame_pack lacks frames"
[[ $(sqlite3 "$tmp/t/run.sqlite" "SELECT COUNT(*) FROM person_load") -gt 0 ]] || fail "the scenario has no chest loads to compare"

source "$(dirname "${BASH_SOURCE[0]}")/same_outputs.sh"
# (With kept contacts: the frames drawn are those that kept them, with their own force scale.)
write_outputs "$cr" "$tmp/t" "${kept:-all}"
write_outputs "$cr" "$tmp/p" "${kept:-all}"
same_outputs "$tmp/t" "$tmp/p" || fail "outputs differ"
drawn=$(ls "$tmp/t/frames" | wc -l)
expected=41
[[ -z $lean ]] || expected=$(tr ',' '\n' <<< "$kept" | wc -l)
(( drawn == expected )) || fail "render: $drawn frames drawn, expected $expected"

# Unpacked into one file with tables: the packed run's digest.
"$cr" export "$tmp/p/run.sqlite" -o "$tmp/unpacked.sqlite" --tables > /dev/null
[[ $("$cr" analyze "$tmp/unpacked.sqlite" --digest) == "$digest_p" ]] || fail "export --tables differs"
[[ $(sqlite3 "$tmp/unpacked.sqlite" "SELECT COUNT(*) FROM sqlite_master WHERE name = 'frame_pack'") == 0 ]] || fail "still packed"
echo "export --tables: the same digest, with tables"

# Stopped, then resumed from its checkpoint: the run made in one go.
"$cr" simulate "$packed" -o "$tmp/r.sqlite" -q --stop-after 2.25 > /dev/null 2>&1 || true
"$cr" simulate "$packed" -o "$tmp/r.sqlite" -q --resume
[[ $("$cr" analyze "$tmp/r.sqlite" --digest) == "$digest_p" ]] || fail "the resumed packed run differs"
echo "resumed: the same digest"
"$cr" simulate "$packed" -o "$tmp/one.sqlite" -q --threads 1 > /dev/null 2>&1
[[ $("$cr" analyze "$tmp/one.sqlite" --digest) == "$digest_p" ]] || fail "the packed run on one thread differs"
echo "one thread: the same digest"

# The people's bytes (SQLite's payload: a small file is mostly its pages' fixed share).
size_t=$(sqlite3 "$tmp/t/run.sqlite" "SELECT SUM(payload) FROM dbstat WHERE name IN ('trajectory_data', 'person_state',
  'person_load', 'frame_id_idx', 'person_state_idx', 'person_load_idx')")
size_p=$(sqlite3 "$tmp/p/run.sqlite" "SELECT SUM(payload) FROM dbstat WHERE name = 'frame_pack'")
echo "the people's bytes: tables $size_t, packed $size_p"
(( size_p < size_t )) || fail "the packed people are not smaller"
echo "packed frames: the same run"
