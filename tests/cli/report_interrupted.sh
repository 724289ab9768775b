#!/usr/bin/env bash
# Ctrl-C and SIGTERM while `report` prints its PDF (issue 40: 2 of 4 tries
# hung for minutes, Chromium left idle). A stand-in for Chromium that
# ignores SIGINT and SIGTERM, and starts a helper that ignores them too,
# plays the worst case. Checks, for each signal sent to report's process
# group: exit 128 + signal within 2 s, no process of the stand-in left, no
# leftover (.chromium-profile, .chromium.log, a partial PDF, report.pdf),
# and a rerun into the same folder that succeeds; then SIGKILL to the report
# alone while it rewrites a previous report (the browser must die with it,
# the previous report stays whole; the rerun cleans up). Then a browser that
# fails at once is reported with its exit status (not a raw wait status),
# and leaves the previous report in its folder as it was.
#   report_interrupted.sh CROWDRECON RUN_FILE
set -uo pipefail
exe=$1; run=$2
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
cat > "$d/fake-chromium" <<SH
#!/usr/bin/env bash
trap '' INT TERM
sleep 120 &
echo \$! > "$d/helper.pid"
echo \$\$ > "$d/browser.pid"
wait
SH
chmod +x "$d/fake-chromium"
fail() { echo "report_interrupted.sh: $*"; exit 1; }
# Running: a process that exists and is not a zombie (an orphan ended by
# SIGKILL waits a moment for init to reap it).
alive() { [[ -f $1 ]] || return 1; local s; s=$(ps -o stat= -p "$(cat "$1")" 2>/dev/null) || return 1; [[ -n $s && $s != Z* ]]; }
set -m  # the report gets a process group of its own, as in a terminal
for signal in INT TERM; do
  rm -f "$d/browser.pid" "$d/helper.pid"
  "$exe" report "$run" -o "$d/report-$signal" --chromium "$d/fake-chromium" -q > "$d/out-$signal.txt" 2>&1 &
  pid=$!
  for _ in $(seq 100); do [[ -f $d/helper.pid ]] && break; sleep 0.1; done
  [[ -f $d/helper.pid ]] || fail "the stand-in browser never started"
  sent=$(date +%s%N)
  kill -s "$signal" -- "-$pid"
  wait "$pid"; rc=$?
  took_ms=$(( ($(date +%s%N) - sent) / 1000000 ))
  cat "$d/out-$signal.txt"
  expected=$([[ $signal == INT ]] && echo 130 || echo 143)
  [[ $rc -eq $expected ]] || fail "SIG$signal: exit $rc, expected $expected"
  (( took_ms < 2000 )) || fail "SIG$signal: took $took_ms ms to stop"
  grep -q "interrupted by SIG$signal while .*fake-chromium ran; it was ended" "$d/out-$signal.txt" || fail "SIG$signal: no message"
  sleep 0.2
  alive "$d/browser.pid" && fail "SIG$signal: the browser is still running"
  alive "$d/helper.pid" && fail "SIG$signal: the browser's helper is still running"
  left=$( (ls -A "$d/report-$signal" 2>/dev/null; ls -A "$d") | grep -E '^\.chromium|partial|report\.pdf' || true)
  [[ -z $left ]] || fail "SIG$signal: left $left"
  "$exe" report "$run" -o "$d/report-$signal" --no-pdf -q > /dev/null || fail "SIG$signal: the rerun failed"
  echo "SIG$signal: exit $rc after $took_ms ms, nothing left, rerun done"
done
# Killed outright (SIGKILL to the report alone) while it rewrites a previous
# report: the browser dies with it (the parent-death signal), the previous
# report is untouched (the new one was staged beside it), and the rerun
# removes the staging folder the killed report left, and what a report of an
# earlier version left inside its folder, and says so.
"$exe" report "$run" -o "$d/report-KILL" --no-pdf -q > /dev/null || fail "SIGKILL: the first report failed"
before=$(cd "$d/report-KILL" && sha256sum report.html people.csv)
rm -f "$d/browser.pid" "$d/helper.pid"
"$exe" report "$run" -o "$d/report-KILL" --label other --chromium "$d/fake-chromium" -q > /dev/null 2>&1 &
pid=$!
for _ in $(seq 100); do [[ -f $d/helper.pid ]] && break; sleep 0.1; done
[[ -f $d/helper.pid ]] || fail "the stand-in browser never started"
kill -KILL "$pid"; wait "$pid"
sleep 0.3
alive "$d/browser.pid" && fail "SIGKILL: the browser outlived the report"
kill -KILL "$(cat "$d/helper.pid")" 2>/dev/null  # the stand-in's own helper is the stand-in's business
[[ $(cd "$d/report-KILL" && sha256sum report.html people.csv) == "$before" ]] || fail "SIGKILL: the previous report changed"
[[ ! -e $d/report-KILL/report.pdf ]] || fail "SIGKILL: a report.pdf appeared in the previous report"
staging=$d/.report-KILL.partial-$pid
mkdir -p "$d/report-KILL/.chromium-profile"  # as an earlier version's Chromium left it
touch "$d/report-KILL/.report.partial-999999999.pdf"  # a partial PDF of a process long gone
[[ -d $staging ]] || fail "SIGKILL: no staging folder $staging (what the test expects a kill to leave)"
"$exe" report "$run" -o "$d/report-KILL" --no-pdf > "$d/rerun.txt" 2>&1 || { cat "$d/rerun.txt"; fail "SIGKILL: the rerun was refused"; }
cat "$d/rerun.txt"
for left in "$staging" "$d/report-KILL/.chromium-profile" "$d/report-KILL/.report.partial-999999999.pdf"; do
  grep -qF "note: removed $left, left by a report that was killed" "$d/rerun.txt" || fail "SIGKILL: $left not said"
  [[ ! -e $left ]] || fail "SIGKILL: $left still there"
done
echo "SIGKILL: the browser ended with the report, the previous report untouched; the rerun removed what was left and said so"
set +m
printf '#!/bin/sh\necho "no display" >&2\nexit 3\n' > "$d/broken-chromium"; chmod +x "$d/broken-chromium"
# A failing rerun over a previous report (other options) leaves it whole:
# no new people.csv beside the old report.html (issue 40).
"$exe" report "$run" -o "$d/broken" --no-pdf -q > /dev/null || fail "a failing browser: the first report failed"
before=$(cd "$d/broken" && ls -A && sha256sum report.html people.csv)
"$exe" report "$run" -o "$d/broken" --label other --f0 300 --chromium "$d/broken-chromium" -q > "$d/broken.txt" 2>&1; rc=$?
cat "$d/broken.txt"
[[ $rc -eq 2 ]] || fail "a failing browser: exit $rc, expected 2"
grep -q "could not print .* (exit status 3): no display" "$d/broken.txt" || fail "a failing browser: message"
[[ $(cd "$d/broken" && ls -A && sha256sum report.html people.csv) == "$before" ]] || fail "a failing browser: the previous report changed"
left=$(ls -A "$d" | grep partial || true)
[[ -z $left ]] || fail "left $left"
echo "a failing browser: exit 2 with its status, the previous report whole, nothing left"
