#!/usr/bin/env bash
# A full disk for every writer (issue 40), played by a file-size limit of
# 8 KiB with SIGXFSZ ignored, so that a write past it fails as on a full
# disk (EFBIG) instead of killing the command. Each writer must answer with
# an error (exit 2, not an internal error, not a crash) and leave nothing
# under its output's name: a half-written file that looks complete is the
# failure this guards against.
#   disk_full.sh CROWDRECON RUN_FILE SCENARIO SPEC
set -uo pipefail
exe=$1; run=$2; scenario=$3; spec=$4
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail() { echo "disk_full.sh: $*"; exit 1; }
check() {  # check NAME OUTPUT_THAT_MUST_NOT_EXIST crowdrecon-arguments...
  local name=$1 output=$2; shift 2
  ( trap '' XFSZ; ulimit -f 8; "$exe" "$@" > "$d/msg.txt" 2>&1 ); local rc=$?
  echo "$name: exit $rc: $(grep -m1 'error' "$d/msg.txt")"
  [[ $rc -eq 2 ]] || { cat "$d/msg.txt"; fail "$name: exit $rc, expected 2 (a clear error)"; }
  grep -q "crowdrecon: error: " "$d/msg.txt" || fail "$name: no error message"
  [[ ! -e $output ]] || fail "$name: left $output"
  if compgen -G "$d/out/.*partial*" > /dev/null; then fail "$name: left $(ls -A "$d"/out/.*partial*)"; fi
}
mkdir -p "$d/out"
check simulate "$d/out/run.sqlite" simulate "$scenario" -o "$d/out/run.sqlite" -q
[[ ! -e $d/out/run.sqlite-wal && ! -e $d/out/run.sqlite-shm ]] || fail "simulate: left the run file's logs"
check export "$d/out/export.sqlite" export "$run" -o "$d/out/export.sqlite"
check render "$d/out/frames/frame_000000.png" render "$run" -o "$d/out/frames" --frames 0
check timeline "$d/out/timeline.png" timeline "$run" -o "$d/out/timeline.png"
check report "$d/out/report/people.csv" report "$run" -o "$d/out/report" --no-pdf -q
check analyze "$d/out/analysis.json" analyze "$run" --json "$d/out/analysis.json"
check observe "$d/out/observation.json" observe trajectories "$run" --spec "$spec" -o "$d/out/observation.json"
[[ ! -e $d/out/observation.csv ]] || fail "observe: left observation.csv"
# A video: OpenCV's writer reports no write error (before: a truncated
# video and "31 frames", exit 0); the container is checked before the rename.
check synthesize "$d/out/clip.avi" observe synthesize "$run" -o "$d/out/clip.avi" --homography-out "$d/out/h.json"
[[ ! -e $d/out/h.json ]] || fail "synthesize: left h.json"
check population "$d/out/people.json" population --mode anthropometric --count 3000 --seed 7 -o "$d/out/people.json"
# Over a previous report made with other options, a full disk leaves that
# report whole (before: a new people.csv beside the old report.html).
"$exe" report "$run" -o "$d/out/previous" --no-pdf --label first -q > /dev/null || fail "report: the first report failed"
before=$(cd "$d/out/previous" && ls -A && sha256sum report.html people.csv)
# (400 KiB: people.csv, ~15 KiB, and the network picture the report draws
# first fit; report.html, ~470 KiB, does not)
( trap '' XFSZ; ulimit -f 400; "$exe" report "$run" -o "$d/out/previous" --no-pdf --label second -q > "$d/msg.txt" 2>&1 ); rc=$?
echo "report over a previous one: exit $rc: $(grep -m1 'error' "$d/msg.txt")"
[[ $rc -eq 2 ]] || { cat "$d/msg.txt"; fail "report over a previous one: exit $rc, expected 2"; }
[[ $(cd "$d/out/previous" && ls -A && sha256sum report.html people.csv) == "$before" ]] || fail "report over a previous one: it changed"
if compgen -G "$d/out/.*partial*" > /dev/null; then fail "report over a previous one: left $(ls -A "$d"/out/.*partial*)"; fi
echo "every writer refused cleanly on a full disk"
