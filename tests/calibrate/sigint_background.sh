#!/bin/bash
# A calibration started as a background job of a script (which starts it
# with SIGINT ignored) answers SIGINT within seconds in a stage between its
# evaluations, here the posterior's sampling, and says how to continue
# (issue 65: it sampled on for over ten minutes); SIGTERM likewise.
#   sigint_background.sh CROWDRECON SOURCE_DIR
set -uo pipefail
crowdrecon=$1
src=$(cd "$2" && pwd)
d=$(mktemp -d)
trap 'kill $pid 2>/dev/null; [[ -n ${KEEP:-} ]] || rm -rf "$d"' EXIT
# The smoke calibration with a posterior long enough to be stopped in.
python3 "$(dirname "$0")/smoke_calibration.py" "$src" "$d" '{"bootstrap": 5, "profile_points": 0, "posterior_steps": 10000000}'
"$crowdrecon" simulate "$d/truth.json" -o "$d/truth.sqlite" -q > /dev/null
"$crowdrecon" observe trajectories "$d/truth.sqlite" --spec "$src/venues/madrid-arena/observations/hallway.json" \
  -o "$d/truth.observation.json" -q > /dev/null
for signal in INT TERM; do
  rm -rf "$d/out"
  # (A background job of a non-interactive shell starts with SIGINT ignored.)
  "$crowdrecon" calibrate "$d/calibration.json" -o "$d/out" --jobs 1 > "$d/out.txt" 2> "$d/err.txt" &
  pid=$!
  for _ in $(seq 1200); do
    grep -q "the posterior:" "$d/err.txt" && break
    kill -0 $pid 2>/dev/null || break
    sleep 0.1
  done
  grep -q "the posterior:" "$d/err.txt" || { cat "$d/err.txt"; echo "sigint_background.sh: never reached the posterior"; exit 1; }
  sleep 1
  kill -s $signal $pid
  for _ in $(seq 50); do kill -0 $pid 2>/dev/null || break; sleep 0.1; done
  if kill -0 $pid 2>/dev/null; then echo "sigint_background.sh: SIG$signal not answered within 5 s"; kill -9 $pid; exit 1; fi
  wait $pid; rc=$?
  echo "SIG$signal in the posterior: exit $rc"
  expected=$([[ $signal == TERM ]] && echo 143 || echo 130)
  [[ $rc -eq $expected ]] || { cat "$d/err.txt" "$d/out.txt"; echo "sigint_background.sh: exit $rc, expected $expected"; exit 1; }
  grep -q "interrupted: run the same command again to continue" "$d/out.txt" || { cat "$d/out.txt"; echo "sigint_background.sh: no hint"; exit 1; }
done
echo "calibrate answers SIGINT and SIGTERM as a background job: OK"
