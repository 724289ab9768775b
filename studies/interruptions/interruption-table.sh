#!/usr/bin/env bash
# The interruption table of issue 40: each long-running command, stopped by
# SIGINT, SIGTERM or SIGKILL at two moments, then checked for what it left
# (files beside its output), for processes it left running, and for a rerun
# (or --resume) that ends as the uninterrupted command did.
#   studies/interruptions/interruption-table.sh CROWDRECON OUT_DIR
# Writes OUT_DIR/table.md. Needs sqlite3 and ps (scripts/install-deps.sh).
set -uo pipefail
exe=$(readlink -f "$1"); out=$2
root=$(cd "$(dirname "$0")/../.." && pwd)  # the repository root: studies/NAME/ is two levels down
mkdir -p "$out"; out=$(cd "$out" && pwd)
w=$(mktemp -d); trap 'rm -rf "$w"' EXIT
# A 20-s run of the hallway (5 /m2, 30 % counter-flow), checkpoints every 2 s.
python3 "$root/scripts/scenario-with.py" "$root/venues/madrid-arena/scenarios/hallway-5pm2-30cf.json" "$w/scenario.json" \
  run.duration_s=20 run.checkpoint_interval_s=2 run.output_fps=10
"$exe" simulate "$w/scenario.json" -o "$w/whole.sqlite" -q --threads 1 > /dev/null || exit 1
whole_digest=$("$exe" analyze "$w/whole.sqlite" --digest)
"$exe" export "$w/whole.sqlite" -o "$w/whole-export.sqlite" > /dev/null || exit 1
export_dump=$(sqlite3 "$w/whole-export.sqlite" .dump | sha256sum | cut -c1-16)
"$exe" render "$w/whole.sqlite" -o "$w/whole-frames" --frames every:20 > /dev/null || exit 1
frames_sum=$(cat "$w"/whole-frames/*.png | sha256sum | cut -c1-16)
# A stand-in browser for report: ignores SIGINT and SIGTERM while "printing".
cat > "$w/browser" <<SH
#!/usr/bin/env bash
trap '' INT TERM
echo \$\$ >> "$w/browser.pids"
sleep 30
SH
chmod +x "$w/browser"
echo "| command | signal | at | exit | left beside the output | still running | rerun | rerun's result |" > "$out/table.md"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |" >> "$out/table.md"
left_of() {  # hidden and sidecar files beside $1 (a file) or inside it (a folder)
  local target=$1 dir base
  if [[ -d $target ]]; then dir=$target; base=""; else dir=$(dirname "$target"); base=$(basename "$target"); base=${base%.*}; fi
  (cd "$dir" 2>/dev/null && ls -A | grep -E "^\.${base}|^${base}.*(-wal|-shm|-journal|\.checkpoint)$|^\.chromium|partial" | tr '\n' ' ')
}
running() {  # the stand-in browser's processes still alive (not zombies)
  local n=0 pid s
  [[ -f $w/browser.pids ]] || { echo 0; return; }
  for pid in $(cat "$w/browser.pids"); do s=$(ps -o stat= -p "$pid" 2>/dev/null); [[ -n $s && $s != Z* ]] && n=$((n + 1)); done
  echo "$n"
}
row() { echo "| $1 | $2 | $3 | $4 | ${5:-nothing} | $6 | $7 | $8 |" >> "$out/table.md"; echo "$1 $2 $3: exit $4, left '${5:-nothing}', running $6, rerun $7: $8"; }
stop_at() {  # stop_at SIGNAL SECONDS command...: runs it in a group of its own, signals the group
  local signal=$1 after=$2; shift 2
  set -m; "$@" > "$w/cmd.out" 2>&1 & local pid=$!; set +m
  sleep "$after"; kill -s "$signal" -- "-$pid" 2>/dev/null; wait "$pid"; echo $?
}
for signal in INT TERM KILL; do
  for at in 0.5 1.5; do
    # simulate, then --resume
    rm -f "$w"/r.sqlite*
    rc=$(stop_at $signal $at "$exe" simulate "$w/scenario.json" -o "$w/r.sqlite" -q --threads 1)
    left=$(left_of "$w/r.sqlite")
    "$exe" simulate "$w/scenario.json" -o "$w/r.sqlite" -q --threads 1 --resume > "$w/rerun.out" 2>&1; rr=$?
    same=$([[ $("$exe" analyze "$w/r.sqlite" --digest 2>/dev/null) == "$whole_digest" ]] && echo "tables identical" || echo "**tables differ**")
    row simulate SIG$signal "${at} s" "$rc" "$left" 0 "--resume: exit $rr" "$same"
    # export, then the same export again
    rm -rf "$w"/e.sqlite "$w"/.e.partial*
    rc=$(stop_at $signal 0.1 "$exe" export "$w/whole.sqlite" -o "$w/e.sqlite")
    left=$(left_of "$w/e.sqlite")
    "$exe" export "$w/whole.sqlite" -o "$w/e.sqlite" --force > "$w/rerun.out" 2>&1; rr=$?
    same=$([[ $(sqlite3 "$w/e.sqlite" .dump | sha256sum | cut -c1-16) == "$export_dump" ]] && echo "export identical" || echo "**export differs**")
    [[ $at == 0.5 ]] && row export SIG$signal "0.1 s" "$rc" "$left" 0 "again: exit $rr" "$same"
    # render, then the same render again
    rm -rf "$w/frames"
    rc=$(stop_at $signal 0.3 "$exe" render "$w/whole.sqlite" -o "$w/frames" --frames every:20)
    left=$(left_of "$w/frames")
    "$exe" render "$w/whole.sqlite" -o "$w/frames" --frames every:20 > "$w/rerun.out" 2>&1; rr=$?
    same=$([[ $(cat "$w"/frames/*.png 2>/dev/null | sha256sum | cut -c1-16) == "$frames_sum" ]] && echo "frames identical" || echo "**frames differ**")
    [[ $at == 0.5 ]] && row render SIG$signal "0.3 s" "$rc" "$left" 0 "again: exit $rr" "$same"
    # report while the browser prints, then again without the PDF
    rm -rf "$w/report" "$w/browser.pids"
    rc=$(stop_at $signal 1.5 "$exe" report "$w/whole.sqlite" -o "$w/report" --chromium "$w/browser" -q)
    sleep 0.3
    alive=$(running); left=$(left_of "$w/report")
    "$exe" report "$w/whole.sqlite" -o "$w/report" --no-pdf -q > "$w/rerun.out" 2>&1; rr=$?
    same=$([[ $rr -eq 0 && -s $w/report/report.html ]] && echo "report written" || echo "**$(tail -c 120 "$w/rerun.out")**")
    [[ $at == 0.5 ]] && row report "SIG$signal" "printing" "$rc" "$left" "$alive" "again: exit $rr" "$same"
    pkill -KILL -f "$w/browser" 2>/dev/null
  done
done
echo "table: $out/table.md"
