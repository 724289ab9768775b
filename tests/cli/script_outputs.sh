#!/usr/bin/env bash
# The Python scripts users run protect their inputs and outputs as crowdrecon
# does and answer bad arguments in one line (issue 65, scripts/script_guard.py):
# each hostile command below must exit with status 2, say what is wrong in one
# line "SCRIPT: error: ..." (no traceback), and leave every file of the scratch
# folder as it was (names and sha256 before and after). A few good commands
# must still work, a rerun replacing their previous outputs.
#   script_outputs.sh PYTHON ROOT
# ROOT: the repository whose scripts/ and studies/ are run (and whose venues/
# the stand-in inputs use). The inputs are made by make_script_inputs.py with
# sqlite3 alone (no simulation).
set -u
py=$1; root=$(cd "$2" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
s=$work/scratch; log=$work/log.txt
mkdir "$s" && cd "$s" || exit 1

# --- the inputs
make() { "$py" "$here/make_script_inputs.py" "$@" || { echo "script_outputs.sh: cannot make the inputs ($*)"; exit 1; }; }
make run run.sqlite "$root/venues/itaewon/alley.json"
make sweep hallway-sweep "$root/venues/madrid-arena/hallway-open.json" --runs 6
make nights nights "$root/venues/madrid-arena/hallway-open.json"
ln -s run.sqlite link.sqlite
ln run.sqlite hard.sqlite
cp "$root/tests/data/scenarios/hallway-short.json" scenario.json
mkdir anthro notes
for f in ANSURIIMALEPublic.csv ANSURIIFEMALEPublic.csv; do
  sex=$([[ $f == *FEMALE* ]] && echo Female || echo Male)
  printf 'subjectid,Gender,chestbreadth,chestdepth,biacromialbreadth,bideltoidbreadth,weightkg,stature\n1,%s,300,250,400,450,700,1750\n' "$sex" > "anthro/$f"
done
echo "my own notes" > notes/notes.txt
echo "my own notes" > notes.txt
mkdir jsonfolder && cp scenario.json jsonfolder/
# A copy of the scripts without the data folder ../shared/data beside it.
mkdir -p norepo/main/studies && cp -r "$root/scripts" norepo/main/ && cp -r "$root/studies/wuppertal-bottleneck" norepo/main/studies/

snapshot() {  # every entry (type, name, link target) and every file's sha256
  (cd "$s" && find . -mindepth 1 -printf '%y %p %l\n' | LC_ALL=C sort &&
     find . -type f -print0 | LC_ALL=C sort -z | xargs -0 -r sha256sum)
}

fails=0
report() {  # report LABEL PROBLEMS...
  local label=$1; shift
  if (($#)); then
    echo "FAIL $label: $*"; head -c 1500 "$log" | sed 's/^/    | /'; fails=$((fails + 1))
  else
    echo "ok   $label: $(head -1 "$log")"
  fi
}

refused() {  # refused LABEL REGEX -- COMMAND...: status 2, one line matching REGEX, nothing changed
  local label=$1 regex=$2; shift 3
  local before after rc problems=()
  before=$(snapshot)
  "$@" > "$log" 2>&1; rc=$?
  after=$(snapshot)
  [[ $rc -eq 2 ]] || problems+=("exit status $rc, expected 2;")
  grep -q "Traceback" "$log" && problems+=("a traceback;")
  [[ $(wc -l < "$log") -eq 1 ]] && grep -Eq '^[A-Za-z_.-]+\.py: error: ' "$log" ||
    problems+=("not one line \"SCRIPT: error: ...\";")
  grep -Eq -- "$regex" "$log" || problems+=("no /$regex/ in the message;")
  [[ "$before" == "$after" ]] || problems+=("files changed: $(diff <(echo "$before") <(echo "$after") | grep '^[<>]' | head -4 | tr '\n' ' ')")
  report "$label" "${problems[@]}"
}

accepted() {  # accepted LABEL FILE -- COMMAND...: status 0 and FILE written
  local label=$1 file=$2; shift 3
  local rc problems=()
  "$@" > "$log" 2>&1; rc=$?
  [[ $rc -eq 0 ]] || problems+=("exit status $rc, expected 0;")
  [[ -s $file ]] || problems+=("$file not written;")
  report "$label" "${problems[@]}"
}

S=$root/scripts
D=$root/studies
dens=$D/itaewon-evening-ensemble/itaewon-densities.py

# --- an input is never an output (by name, another spelling, a symbolic or a hard link; not even with --force)
refused "itaewon-densities: -o the run" "is an input" -- "$py" "$dens" run.sqlite -o run.sqlite
refused "itaewon-densities: --csv the run by another spelling" "is an input" -- "$py" "$dens" run.sqlite -o d.md --csv ./notes/../run.sqlite
refused "itaewon-densities: -o a symbolic link to the run, --force" "is an input" -- "$py" "$dens" run.sqlite -o link.sqlite --force
refused "itaewon-densities: --csv a hard link to the run" "is an input" -- "$py" "$dens" run.sqlite -o d.md --csv hard.sqlite
refused "sweep-ensembles: -o DIR/results (the sweep's results.csv), --force" "is an input" -- \
  "$py" "$S/sweep-ensembles.py" hallway-sweep two-way one-way -o hallway-sweep/results --metrics mean_speed_m_per_s --force
refused "scenario-with: OUT is SCENARIO" "is an input" -- "$py" "$S/scenario-with.py" scenario.json ./scenario.json population.seed=2
refused "night-path: -o a hard link to the run" "is an input" -- "$py" "$D/night-cheap-model/night-path.py" run.sqlite -o hard.sqlite
refused "reaction-time-from-data: -o the run through a link" "is an input" -- \
  "$py" "$D/reaction-time/reaction-time-from-data.py" run.sqlite -o link.sqlite --bootstrap 5
refused "decision_study: OUT_DIR the sweep's results.csv" "is an input" -- \
  "$py" "$D/open-decisions/decision_study.py" /bin/true hallway-sweep hallway-sweep/results.csv

# --- two outputs, one path; a folder never replaced by a file; a foreign file or folder only with --force
refused "itaewon-densities: -o and --csv one file" "both name" -- "$py" "$dens" run.sqlite -o d.md --csv ./d.md
refused "itaewon-densities: -o a folder" "a folder is never replaced by a file" -- "$py" "$dens" run.sqlite -o notes --force
refused "itaewon-densities: -o someone's notes" "--force \(which replaces it\)" -- "$py" "$dens" run.sqlite -o notes.txt
refused "make-ansur-extract: TARGET someone's notes" "--force" -- "$py" "$S/make-ansur-extract.py" anthro notes.txt
refused "falls-study: OUT_DIR someone's folder" "deletes nothing" -- "$py" "$D/falls-verification/falls-study.py" /bin/false notes

# --- bad arguments and inputs: one line, status 2
refused "itaewon-densities: --scale 0" "argument --scale" -- "$py" "$dens" run.sqlite -o d.md --scale 0
refused "itaewon-densities: a JSON file as the run" "not an SQLite file" -- "$py" "$dens" scenario.json -o d.md
refused "calibration-coverage: --truths 0" "argument --truths" -- \
  "$py" "$D/calibration-coverage/calibration-coverage.py" coverage --truths 0
refused "itaewon-envelope: a hallway sweep" "not of the Itaewon alley" -- \
  "$py" "$D/itaewon-design-envelope/itaewon-envelope.py" hallway-sweep -o envelope
refused "bottleneck-study: no ../shared/data beside the repository" "\.\./shared/data" -- \
  "$py" norepo/main/studies/wuppertal-bottleneck/bottleneck-study.py /bin/true study
refused "gait-jitter-from-data: no ../shared/data beside the repository" "\.\./shared/data" -- \
  "$py" norepo/main/studies/wuppertal-bottleneck/gait-jitter-from-data.py
refused "gait-jitter-from-data: a JSON file as trajectories" "PeTrack" -- "$py" "$D/wuppertal-bottleneck/gait-jitter-from-data.py" scenario.json
refused "sweep-ensembles: a variant the sweep lacks" "has no variant" -- \
  "$py" "$S/sweep-ensembles.py" hallway-sweep two-way three-way -o cmp
refused "phase-table: a folder that is not a sweep" "not a crowdrecon sweep folder" -- "$py" "$S/phase-table.py" notes
refused "sweep-compare: DIR without :VARIANT" "DIR:VARIANT" -- "$py" "$S/sweep-compare.py" hallway-sweep hallway-sweep:two-way
refused "scenario-with: a change that is not JSON" "is not JSON" -- \
  "$py" "$S/scenario-with.py" scenario.json copy.json population.body.mode=paper
refused "area-stops: no run file" "required" -- "$py" "$D/local-avalanche-reading/results/area-stops.py"
refused "releases: a sweep's results as a run" "has no run, .*tables" -- \
  "$py" "$D/night-full-ensemble/results/releases.py" hallway-sweep/results.sqlite
refused "compare-nights: -o the sweep's results.csv" "is an input" -- \
  "$py" "$D/sleeping/compare-nights.py" notes hallway-sweep/results.csv notes hallway-sweep/results.csv -o hallway-sweep/results.csv
refused "compare-nights: a folder without summaries" "no summaries" -- \
  "$py" "$D/sleeping/compare-nights.py" notes hallway-sweep/results.csv notes hallway-sweep/results.csv -o nights.md
refused "compare-nights: a scenario as a summary" "has no seed" -- \
  "$py" "$D/sleeping/compare-nights.py" jsonfolder hallway-sweep/results.csv jsonfolder hallway-sweep/results.csv -o nights.md
refused "passing-side: -o the sweep's results.csv" "is an input" -- \
  "$py" "$D/side-preference/passing-side.py" hallway-sweep -o hallway-sweep/results.csv
refused "passing-side: -o someone's notes" "expected another name, or --force" -- \
  "$py" "$D/side-preference/passing-side.py" hallway-sweep -o notes.txt
refused "passing-side: not a sweep folder" "expected a crowdrecon sweep folder" -- \
  "$py" "$D/side-preference/passing-side.py" notes -o sides.md
gl=$D/hallway-validated/gamma-lambda-table.py
refused "gamma-lambda-table: -o the sweep's results" "is an input" -- \
  "$py" "$gl" hallway-sweep/results.csv hallway-sweep/results.csv -o hallway-sweep/results.csv --base-variant two-way
refused "gamma-lambda-table: a base without its variant" "no runs of the variant 'thorax'" -- \
  "$py" "$gl" hallway-sweep/results.csv hallway-sweep/results.csv -o gl.md
refused "gamma-lambda-table: a paths CSV as the sweep" "expected a crowdrecon sweep's results.csv" -- \
  "$py" "$gl" nights/paths.csv hallway-sweep/results.csv -o gl.md
hz=$D/night-validated-calibration/night-hazard.py
refused "night-hazard: -o the summaries folder" "is an input|deletes nothing" -- \
  "$py" "$hz" --paths nights/paths.csv --summaries nights/summaries --unfinished n6:1.5 -o nights/summaries --coverage 0
refused "night-hazard: a night neither summarised nor unfinished" "night n6 has no summary" -- \
  "$py" "$hz" --paths nights/paths.csv --summaries nights/summaries -o hz --coverage 0
refused "night-hazard: --unfinished without its scale" "expected RUN:SCALE" -- \
  "$py" "$hz" --paths nights/paths.csv --summaries nights/summaries --unfinished n6 -o hz --coverage 0
refused "night-hazard: scenarios as summaries" "expected an ensemble run summary" -- \
  "$py" "$hz" --paths nights/paths.csv --summaries jsonfolder --unfinished n6:1.5 -o hz --coverage 0
refused "night-hazard: the entering group's push raised during the night" "expected only the entering group's" -- \
  "$py" "$hz" --paths nights/paths.csv --summaries nights/summaries-late --unfinished n6:1.5 -o hz --coverage 0
refused "night-hazard: --unfinished with a push of 0" "expected RUN:SCALE or RUN:SCALE:GAMMA" -- \
  "$py" "$hz" --paths nights/paths.csv --summaries nights/summaries-push --unfinished n6:1.5:0 -o hz --coverage 0
refused "night-hazard: a run file as the paths CSV" "expected night-path.py's CSV" -- \
  "$py" "$hz" --paths run.sqlite --summaries nights/summaries --unfinished n6:1.5 -o hz --coverage 0

# --- good input still works; a rerun replaces its previous outputs
accepted "itaewon-densities: a table" d.md -- "$py" "$dens" run.sqlite -o d.md --csv d.csv
accepted "itaewon-densities: run again (previous outputs replaced)" d.csv -- "$py" "$dens" run.sqlite -o d.md --csv d.csv
accepted "sweep-ensembles: two variants" cmp.md -- \
  "$py" "$S/sweep-ensembles.py" hallway-sweep two-way one-way -o cmp --metrics mean_speed_m_per_s,max_load_n
accepted "sweep-ensembles: run again" cmp.csv -- \
  "$py" "$S/sweep-ensembles.py" hallway-sweep two-way one-way -o cmp --metrics mean_speed_m_per_s,max_load_n
accepted "gamma-lambda-table: a sweep against its own base" gl.md -- \
  "$py" "$gl" hallway-sweep/results.csv hallway-sweep/results.csv -o gl.md --base-variant two-way
accepted "night-hazard: seven nights, coverage 3" hz/hazard.md -- \
  "$py" "$hz" --paths nights/paths.csv --summaries nights/summaries --unfinished n6:1.5 -o hz --coverage 3
accepted "night-hazard: run again" hz/nights.csv -- \
  "$py" "$hz" --paths nights/paths.csv --summaries nights/summaries --unfinished n6:1.5 -o hz --coverage 0
accepted "night-hazard: three nights pushing harder (the scale and the push together)" hzp/joint.png -- \
  "$py" "$hz" --paths nights/paths.csv --summaries nights/summaries-push --unfinished n6:1.5:4.8 -o hzp --coverage 2
leftovers=$(find "$s" -name '.*partial-*')
[[ -z $leftovers ]] || { echo "FAIL partial files left: $leftovers"; fails=$((fails + 1)); }

if ((fails)); then echo "script_outputs.sh: $fails check(s) failed"; exit 1; fi
echo "script_outputs.sh: every hostile command refused in one line, nothing changed; good ones work"
