# Sourced by the tests of run-file storage (packed_frames.sh, segments.sh):
# what every command writes from a run, and the comparison of two runs'
# outputs with their folders made alike.
#   write_outputs CROWDRECON DIR [FRAMES]   DIR/run.sqlite -> DIR/analysis.txt, ...
#   same_outputs DIR_A DIR_B                fails unless both wrote the same
# The report's provenance differs where it should: the run file's bytes and
# the scenario (its text and hash); its venue's hash is kept. The report's
# summary ends with the seconds it took.
write_outputs() {
  local cr=$1 dir=$2 frames=${3:-all}
  # In the folder with the same names: figures print the run file's name.
  (cd "$dir"
   "$cr" analyze run.sqlite --full --json analysis.json > analysis.txt
   "$cr" timeline run.sqlite -o timeline.svg --density-maps density.svg > timeline.txt
   "$cr" report run.sqlite -o report --no-pdf -q > report.txt
   "$cr" export run.sqlite -o export.sqlite > /dev/null
   "$cr" render run.sqlite -o frames --frames "$frames" > /dev/null
   sqlite3 export.sqlite ".mode quote" "SELECT * FROM trajectory_data ORDER BY frame, id" > export.txt)
}
alike_output() {  # alike_output FILE
  sed -E -e "s#(/[^ ]*)?/[^/ ]+/(run\.sqlite|analysis\.json|report|frames|timeline\.svg|density\.svg)#DIR/\2#g" \
    -e '/&quot;/d' -e '/^  [0-9.]+ s$/d' \
    -e '/^<tr><td>runs<\/td>/s#<code>[0-9a-f]{64}</code></td><td><code>[0-9a-f]{64}</code>#FILE</td><td>SCENARIO#' "$1"
}
same_outputs() {
  local a=$1 b=$2 f drawn=0
  for f in analysis.txt analysis.json timeline.txt timeline.svg density.svg report.txt report/report.html \
           report/people.csv export.txt; do
    if ! cmp -s <(alike_output "$a/$f") <(alike_output "$b/$f"); then
      diff <(alike_output "$a/$f") <(alike_output "$b/$f") | head -20 >&2
      echo "FAIL: $f differs" >&2
      return 1
    fi
    echo "$f: the same"
  done
  for f in "$a"/frames/*; do
    cmp -s "$f" "$b/frames/$(basename "$f")" || { echo "FAIL: frame $(basename "$f") differs" >&2; return 1; }
    drawn=$((drawn + 1))
  done
  (( drawn > 0 )) || { echo "FAIL: no frames drawn" >&2; return 1; }
  echo "render: $drawn frames the same"
}
