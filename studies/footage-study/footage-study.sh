#!/bin/bash
# The synthetic-footage study (issue 22; docs/observations.md): a run with
# known stops and releases (studies/footage-study/footage-study.json)
# is drawn as footage by a tilted camera, degraded one way at a time
# (darkness, blur, noise, compression, frame rate) and all together (the
# semi-dark hallway), observed, and compared with the observation of the
# run's own trajectories. Writes OUT/errors.csv (one row per condition and
# method), OUT/table.md, figures and flow pictures, and the processing speed
# on a 5-minute clip (OUT/speed.csv).
#
# Usage: studies/footage-study/footage-study.sh [OUT] [CROWDRECON]   (about 40 min on 2 cores)
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)  # the repository root: studies/NAME/ is two levels down
out=${1:-$here/studies/footage-study/results}
crowdrecon=${2:-$here/build/release/cli/crowdrecon}
spec=$here/venues/madrid-arena/observations/hallway.json
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"
"$crowdrecon" simulate "$here/studies/footage-study/footage-study.json" -o "$work/run.sqlite" -q > /dev/null
"$crowdrecon" observe trajectories "$work/run.sqlite" --spec "$spec" -o "$work/truth.json" -q > /dev/null
cp "$work/truth.json" "$out/truth.json"
cp "$work/truth.csv" "$out/truth.csv"

# name | synthesize options | flow
conditions=(
  "clean||dis-medium"
  "dark-0.5|--darkness 0.5|dis-medium"
  "dark-0.75|--darkness 0.75|dis-medium"
  "dark-0.9|--darkness 0.9|dis-medium"
  "dark-0.9-unflagged|--darkness 0.9|dis-medium --min-contrast 0"
  "blur-1.5|--blur 1.5|dis-medium"
  "blur-3|--blur 3|dis-medium"
  "noise-5|--noise 5|dis-medium"
  "noise-10|--noise 10|dis-medium"
  "noise-20|--noise 20|dis-medium"
  "jpeg-50|--quality 50|dis-medium"
  "jpeg-20|--quality 20|dis-medium"
  "jpeg-5|--quality 5|dis-medium"
  "fps-12.5|--frame-step 2|dis-medium"
  "fps-5|--frame-step 5|dis-medium"
  "semi-dark|--darkness 0.75 --noise 6 --blur 1 --quality 50|dis-medium"
  "clean||dis-fast"
  "semi-dark|--darkness 0.75 --noise 6 --blur 1 --quality 50|dis-fast"
  "clean||farneback"
  "semi-dark|--darkness 0.75 --noise 6 --blur 1 --quality 50|farneback"
)
pictures=" clean dark-0.9-unflagged noise-20 jpeg-5 semi-dark "
echo "condition,flow,options,speed_forward_error_pct,speed_backward_error_pct,counterflow_share_error,onsets_matched,onsets_expected,max_onset_error_s,unmatched_events,flagged_frames,processing_fps" > "$work/errors.csv"
for c in "${conditions[@]}"; do
  IFS='|' read -r name opts flowopts <<< "$c"
  flow=${flowopts%% *}
  video="$work/${name%-unflagged}.avi"
  # shellcheck disable=SC2086
  [ -f "$video" ] || "$crowdrecon" observe synthesize "$work/run.sqlite" -o "$video" --homography-out "${video%.avi}.h.json" $opts > /dev/null
  extra=()
  if [ "$flow" = dis-medium ] && [[ "$pictures" == *" $name "* ]]; then
    extra=(--pictures "$work/pictures-$name" --picture-at 10.5 --figure "$out/figure-$name.png" --reference "$work/truth.json")
  fi
  # shellcheck disable=SC2086
  "$crowdrecon" observe footage "$video" --homography "${video%.avi}.h.json" --spec "$spec" -o "$work/$name-$flow.json" \
    --flow $flowopts "${extra[@]}" > "$work/$name-$flow.txt"
  # (no picture when every frame near its time was flagged)
  for p in "$work/pictures-$name"/flow_*.png; do [ -f "$p" ] && cp "$p" "$out/flow-$name.png"; done
  rm -rf "$work/pictures-$name"
  "$crowdrecon" observe compare "$work/truth.json" "$work/$name-$flow.json" --csv "$work/$name-$flow.compare.csv" > "$work/$name-$flow.compare.txt"
  python3 - "$work/$name-$flow.compare.csv" "$work/$name-$flow.txt" "$name" "$flow" "$opts" >> "$work/errors.csv" <<'PY'
import csv, re, sys
rows = list(csv.DictReader(open(sys.argv[1])))
text = open(sys.argv[2]).read()
def get(q, d, key):
    for r in rows:
        if r["quantity"] == q and r["direction"] == d:
            return r[key]
    return ""
onsets = [r for r in rows if r["quantity"].endswith("_onset_s")]
matched = [r for r in onsets if r["observed"] != ""]
worst = max((abs(float(r["error"])) for r in matched), default=float("nan"))
m = re.search(r"flagged: (\d+) dark, (\d+) flat, (\d+) cut, (\d+) frozen", text)
flagged = sum(int(x) for x in m.groups()) if m else ""
fps = re.search(r", ([0-9.]+) frames/s", text)
print(",".join([sys.argv[3], sys.argv[4], sys.argv[5].strip(),
                get("speed", "forward", "error_percent"), get("speed", "backward", "error_percent"),
                get("counterflow_share", "all", "error"), str(len(matched)), str(len(onsets)),
                f"{worst:.2f}", get("unmatched_events", "all", "observed"), str(flagged), fps.group(1) if fps else ""]))
PY
  echo "$name ($flow): $(tail -1 "$work/errors.csv")"
done
cp "$work/errors.csv" "$out/errors.csv"
python3 - "$out/errors.csv" > "$out/table.md" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("| condition | flow | speed forward | speed backward | counter-flow share | onsets found (of 4, within 3 s) | largest onset error | events not in the trajectories | frames flagged | frames/s |")
print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
def f(value, form):
    return format(float(value), form) if value not in ("", "nan") else "n/a"
for r in rows:
    print(f"| {r['condition']} | {r['flow']} | {f(r['speed_forward_error_pct'], '+.1f')} % | {f(r['speed_backward_error_pct'], '+.1f')} % | "
          f"{f(r['counterflow_share_error'], '+.3f')} | {r['onsets_matched']}/{r['onsets_expected']} | {r['max_onset_error_s']} s | "
          f"{r['unmatched_events'] or 'n/a'} | {r['flagged_frames']} | {r['processing_fps']} |")
PY
cat "$out/table.md"

# Processing speed and memory on a 5-minute clip (7,500 frames at 25 fps)
# against the 30-s clip: frames per second of processing, peak memory.
sed 's/"duration_s": 30/"duration_s": 300/' "$here/studies/footage-study/footage-study.json" |
  sed "s#\"venue\": \"../../venues/madrid-arena/hallway-periodic.json\"#\"venue\": \"$here/venues/madrid-arena/hallway-periodic.json\"#; s#\"reference\": \"../../venues/bodies/thorax-18.json\"#\"reference\": \"$here/venues/bodies/thorax-18.json\"#" > "$work/long.json"
"$crowdrecon" simulate "$work/long.json" -o "$work/long.sqlite" -q > /dev/null
"$crowdrecon" observe synthesize "$work/long.sqlite" -o "$work/long.avi" --homography-out "$work/long.h.json" > /dev/null
echo "clip,flow,frames,seconds,frames_per_second,max_rss_mb" > "$out/speed.csv"
for clip in clean long; do
  for flow in dis-medium dis-fast; do
    /usr/bin/time -f "%e %M" -o "$work/time.txt" "$crowdrecon" observe footage "$work/$clip.avi" --homography "$work/$clip.h.json" \
      --spec "$spec" -o "$work/speed-$clip-$flow.json" --flow "$flow" > "$work/speed.txt"
    read -r seconds rss < "$work/time.txt"
    frames=$(grep -o '[0-9]* frames read' "$work/speed.txt" | cut -d' ' -f1)
    echo "$clip,$flow,$frames,$seconds,$(python3 -c "print(round($frames/$seconds,1))"),$((rss / 1024))" >> "$out/speed.csv"
  done
done
cat "$out/speed.csv"
