#!/usr/bin/env bash
# A sweep stopped by a signal exits as the shell expects, as simulate does:
# 143 after SIGTERM, 130 after SIGINT (issue 65: both gave 130), and a rerun
# continues it to the end.
#   sweep_sigterm.sh CROWDRECON SWEEP
set -uo pipefail
exe=$1; sweep=$2
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
python3 - "$sweep" "$d/long.json" <<'PY'
import json, os, sys
s = json.load(open(sys.argv[1]))
s["scenario"] = os.path.join(os.path.dirname(os.path.abspath(sys.argv[1])), s["scenario"])
s["set"]["run.duration_s"] = 600.0
json.dump(s, open(sys.argv[2], "w"))
PY
for signal in TERM INT; do
  rm -rf "$d/out"
  "$exe" sweep "$d/long.json" -o "$d/out" --jobs 1 -q > "$d/out.txt" 2> "$d/err.txt" &
  pid=$!
  for _ in $(seq 300); do
    compgen -G "$d/out/runs/*.sqlite" > /dev/null && break
    sleep 0.05
  done
  sleep 0.5
  kill -s $signal "$pid"; wait "$pid"; rc=$?
  expected=$([[ $signal == TERM ]] && echo 143 || echo 130)
  echo "SIG$signal: exit $rc"
  [[ $rc -eq $expected ]] || { cat "$d/err.txt" "$d/out.txt"; echo "sweep_sigterm.sh: SIG$signal gave exit $rc, expected $expected"; exit 1; }
done
echo "sweep_sigterm.sh: SIGTERM 143, SIGINT 130: OK"
