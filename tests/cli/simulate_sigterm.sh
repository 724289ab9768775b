#!/usr/bin/env bash
# SIGTERM stops simulate as Ctrl-C does (a checkpoint, then a resumable
# run) and its exit status says which signal it was: 143, where SIGINT
# gives 130 (issue 40: both gave 130).
#   simulate_sigterm.sh CROWDRECON SCENARIO
set -uo pipefail
exe=$1; scenario=$2
source "$(dirname "$0")/run_tables.sh"  # last_frame RUN.sqlite
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
python3 "$(dirname "$0")/../../scripts/scenario-with.py" "$scenario" "$d/long.json" run.duration_s=600
for signal in TERM INT; do
  rm -f "$d"/run.sqlite*
  "$exe" simulate "$d/long.json" -o "$d/run.sqlite" -q --threads 1 > /dev/null 2> "$d/err.txt" &
  pid=$!
  for _ in $(seq 300); do
    [[ $(last_frame "$d/run.sqlite") -ge 3 ]] && break
    sleep 0.05
  done
  kill -s $signal "$pid"; wait "$pid"; rc=$?
  expected=$([[ $signal == TERM ]] && echo 143 || echo 130)
  echo "SIG$signal: exit $rc"
  [[ $rc -eq $expected ]] || { cat "$d/err.txt"; echo "simulate_sigterm.sh: SIG$signal gave exit $rc, expected $expected"; exit 1; }
  grep -q -- "--resume" "$d/err.txt" || { echo "simulate_sigterm.sh: no resume hint"; exit 1; }
  [[ -e $d/run.sqlite.checkpoint ]] || { echo "simulate_sigterm.sh: no checkpoint"; exit 1; }
done
