#!/usr/bin/env bash
# One bad-input case of tests/cli/bad_input_geometry.cmake, whose input is made
# by the test itself (no large file is committed):
#   geometry_case.sh INPUT STATUS REGEX SECONDS -- COMMAND [ARGS...]
# INPUT: "KIND ARG... NAME" for make_geometry_input.py (the file is written as
# $tmp/NAME), "dir NAME" (a folder), or "none". @TMP@ in the command is the
# scratch folder. Checks: the exit status (ok: 0; fail: 2, a user error: never
# a signal or an internal error), the output matches REGEX (extended), the
# command's processor time (user + system) is within SECONDS, and a failing
# command wrote no @TMP@/out.*. Processor time, not wall time: the limit
# guards against work that grows faster than the input (a 34-s picture
# before its fix), and a machine whose cores are shared with other jobs
# stretches the wall time (18-38 s for these 10-s cases beside two
# simulations) but not the work. A hang is stopped at ten times SECONDS of
# wall time.
set -u
input=$1; status=$2; regex=$3; seconds=$4; shift 4
[[ "$1" == "--" ]] && shift
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
read -r -a made <<<"$input"
case ${made[0]} in
  none) ;;
  dir) mkdir -p "$tmp/${made[1]}" ;;
  *) last=$((${#made[@]} - 1))
     "${PYTHON:-python3}" "$here/make_geometry_input.py" "${made[@]:0:$last}" "$tmp/${made[$last]}" || exit 1 ;;
esac
args=()
for a in "$@"; do args+=("${a//@TMP@/$tmp}"); done
start=$EPOCHREALTIME
TIMEFORMAT='%3U %3S'
{ time timeout "$((seconds * 10))" "${args[@]}" >"$tmp/log.txt" 2>&1; } 2>"$tmp/time.txt"
rc=$?
elapsed=$(awk -v a="$start" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.2f", b - a }')
cpu=$(awk '{ printf "%.2f", $1 + $2 }' "$tmp/time.txt")
cat "$tmp/log.txt"
echo "geometry_case.sh: exit $rc after ${elapsed} s (processor time ${cpu} s)"
if [[ $rc -eq 124 ]]; then echo "geometry_case.sh: did not finish within $((seconds * 10)) s"; exit 1; fi
if awk -v c="$cpu" -v s="$seconds" 'BEGIN { exit !(c > s) }'; then
  echo "geometry_case.sh: took ${cpu} s of processor time; expected at most $seconds s"; exit 1
fi
if [[ $status == ok && $rc -ne 0 ]]; then echo "geometry_case.sh: expected success, got exit $rc"; exit 1; fi
if [[ $status == fail && $rc -ne 2 ]]; then echo "geometry_case.sh: expected exit 2 (a user error), got $rc"; exit 1; fi
if ! grep -Eq -- "$regex" "$tmp/log.txt"; then echo "geometry_case.sh: output does not match /$regex/"; exit 1; fi
if [[ $status == fail ]] && compgen -G "$tmp/out.*" >/dev/null; then
  echo "geometry_case.sh: a failing command wrote $(ls "$tmp"/out.*)"; exit 1
fi
echo "geometry_case.sh: as expected"
