#!/usr/bin/env bash
# Runs a command as expect.sh does, in a scratch folder prepared by SETUP, and
# checks afterwards that the paths in KEEP are unchanged: each file's sha256,
# and each folder's entries with theirs (nothing written, nothing destroyed).
#   expect_unchanged.sh ok|fail REGEX SETUP KEEP -- COMMAND [ARGS...]
# SETUP is bash run in the scratch folder, with these helpers:
#   make_scenario      scenario.json, venue.json, body.json (a 0.2 s hallway run)
#   make_run           run.sqlite, a run of scenario.json (a previous run file)
#   make_sweep         sweep.json (the tiny test sweep)
#   make_observation   ref.json + ref.csv, an observation of run.sqlite
#   foreign NAME       a text file that is nobody's output
# KEEP is a space-separated list of paths relative to the scratch folder ("."
# for all of it). COMMAND runs in the scratch folder; $SRC is the project root.
set -u
status=$1; regex=$2; setup=$3; keep=$4; shift 4
[[ "$1" == "--" ]] && shift
export SRC=$PWD EXE=$1
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

make_scenario() {
  cp "$SRC/venues/madrid-arena/hallway-periodic.json" venue.json
  cp "$SRC/venues/bodies/thorax-18.json" body.json
  sed -e 's#"\.\./\.\./\.\./venues/madrid-arena/hallway-periodic.json"#"venue.json"#' \
      -e 's#"\.\./\.\./\.\./venues/bodies/thorax-18.json"#"body.json"#' \
      -e 's#"duration_s": 3#"duration_s": 0.2#' "$SRC/tests/data/scenarios/hallway-short.json" >scenario.json
}
make_run() { "$EXE" simulate scenario.json -o run.sqlite -q >/dev/null; }
make_sweep() {
  sed -e "s#\"\.\./scenarios/sweep-tiny.json\"#\"$SRC/tests/data/scenarios/sweep-tiny.json\"#" \
      "$SRC/tests/data/sweeps/tiny.json" >sweep.json
}
# ref.json and ref.csv: an observation of run.sqlite (needs make_scenario, make_run).
make_observation() {
  "$EXE" observe trajectories run.sqlite --spec "$SRC/venues/madrid-arena/observations/hallway.json" -o ref.json >/dev/null
}
foreign() { echo "notes of an investigator, not an output of crowdrecon" >"$1"; }

# One line per entry under each kept path: its name and, for files, sha256.
snapshot() {
  local p
  for p in $keep; do
    [[ -e "$p" || -L "$p" ]] || { echo "missing $p"; continue; }
    find "$p" -print0 | sort -z | while IFS= read -r -d '' f; do
      if [[ -f "$f" ]]; then echo "$(sha256sum <"$f" | cut -c1-16) $f"; else echo "folder $f"; fi
    done
  done
}

cd "$work" || exit 1
if ! (set -e; eval "$setup"); then echo "expect_unchanged.sh: SETUP failed: $setup"; exit 1; fi
before=$(snapshot)
bash "$here/expect.sh" "$status" "$regex" -- "$@"
rc=$?
after=$(snapshot)
if [[ "$before" != "$after" ]]; then
  echo "expect_unchanged.sh: these paths changed (KEEP: $keep):"
  diff <(echo "$before") <(echo "$after")
  exit 1
fi
echo "expect_unchanged.sh: $keep unchanged"
exit $rc
