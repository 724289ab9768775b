#!/usr/bin/env bash
# Runs every libFuzzer harness of build/fuzz for a while (`make fuzz`,
# docs/fuzzing.md) and prints a table: executions, seconds, coverage, and
# what was found. Exits 1 if any harness found a crash, a hang or runaway
# memory (the reproducers are listed; copy each into fuzz/regressions/HARNESS/
# once it is fixed, so that ctest replays it).
#
#   scripts/fuzz.sh BUILD_DIR SECONDS [HARNESS...]
#
# Each harness runs in libFuzzer's fork mode with one job (-fork=1), so that
# one crash does not end the run (-ignore_crashes, -ignore_timeouts,
# -ignore_ooms): the fuzzer goes on and every finding is kept. Its seed corpus
# fuzz/corpus/HARNESS is copied to a scratch corpus under BUILD_DIR/fuzz-run/,
# where what the fuzzer adds stays (a later run goes on from it) and the
# repository's seeds stay small. A hang is an input slower than
# FUZZ_TIMEOUT_S (10 s); runaway memory one above FUZZ_RSS_MB (2048 MB).
set -euo pipefail

build=$(cd "${1:?usage: scripts/fuzz.sh BUILD_DIR SECONDS [HARNESS...]}" && pwd)
seconds=${2:?usage: scripts/fuzz.sh BUILD_DIR SECONDS [HARNESS...]}
shift 2
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
timeout_s=${FUZZ_TIMEOUT_S:-10}
rss_mb=${FUZZ_RSS_MB:-2048}
harnesses=("$@")
if [[ ${#harnesses[@]} -eq 0 ]]; then
  for dir in "$root"/fuzz/corpus/*/; do harnesses+=("$(basename "$dir")"); done
fi

# A dictionary from the seeds: every quoted string and every word of three
# or more letters of the text seeds (JSON keys, WKT and DXF keywords), so the
# fuzzer need not guess "counter_flow_fraction" a byte at a time.
make_dictionary() {
  python3 - "$1" "$2" <<'PY'
import pathlib, re, sys
tokens = set()
for f in sorted(pathlib.Path(sys.argv[1]).iterdir()):
    data = f.read_bytes()
    if b"\0" in data or data[:4] == b"\x89PNG":
        continue
    text = data.decode("latin-1")
    tokens.update(s for s in re.findall(r'"[^"\\\n]{1,40}"', text))
    tokens.update(re.findall(r"[A-Za-z_$][A-Za-z0-9_$]{2,39}", text))
with open(sys.argv[2], "w") as out:
    for t in sorted(tokens):
        out.write('"' + "".join(c if 32 <= ord(c) < 127 and c not in '"\\' else "\\x%02x" % ord(c) for c in t) + '"\n')
PY
}

summary=$build/fuzz-run/summary.txt
mkdir -p "$build/fuzz-run"
rm -f "$build/fuzz-run/findings.txt"
printf '%-20s %10s %6s %7s %6s %6s %5s %5s %5s\n' harness executions exec/s seconds cov ft crash hang oom | tee "$summary"
found=0
for h in "${harnesses[@]}"; do
  exe=$build/fuzz/$h
  [[ -x $exe ]] || { echo "$h: $exe not built" >&2; exit 2; }
  work=$build/fuzz-run/$h
  mkdir -p "$work/corpus" "$work/artifacts"
  rm -f "$work"/artifacts/*
  cp -n "$root/fuzz/corpus/$h"/* "$work/corpus/"
  make_dictionary "$root/fuzz/corpus/$h" "$work/seeds.dict"
  dict=()
  [[ -s $work/seeds.dict ]] && dict=(-dict="$work/seeds.dict")
  # Inputs up to 16 KiB, or the largest seed's size (run files, images).
  largest=$(find "$root/fuzz/corpus/$h" -type f -printf '%s\n' | sort -n | tail -1)
  max_len=$(( largest > 16384 ? largest : 16384 ))
  start=$(date +%s)
  (cd "$work" && "$exe" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
      -max_total_time="$seconds" -timeout="$timeout_s" -rss_limit_mb="$rss_mb" -max_len="$max_len" \
      -artifact_prefix="$work/artifacts/" "${dict[@]}" corpus >"$work/log" 2>&1) || true
  elapsed=$(( $(date +%s) - start ))
  # Fork mode's status lines: "#RUNS: cov: C ft: F corp: N exec/s E oom/timeout/crash: O/T/X time: Ss ..."
  stats=$(grep -E '^#[0-9]+: cov:' "$work/log" | tail -1 || true)
  runs=$(sed -nE 's/^#([0-9]+):.*/\1/p' <<<"$stats")
  cov=$(sed -nE 's/.* cov: ([0-9]+).*/\1/p' <<<"$stats")
  ft=$(sed -nE 's/.* ft: ([0-9]+).*/\1/p' <<<"$stats")
  crashes=$(find "$work/artifacts" -name 'crash-*' | wc -l)
  hangs=$(find "$work/artifacts" -name 'timeout-*' -o -name 'slow-unit-*' | wc -l)
  ooms=$(find "$work/artifacts" -name 'oom-*' -o -name 'leak-*' | wc -l)
  rate=$(( ${runs:-0} / (elapsed > 0 ? elapsed : 1) ))
  printf '%-20s %10s %6s %7s %6s %6s %5s %5s %5s\n' "$h" "${runs:-?}" "$rate" "$elapsed" "${cov:-?}" "${ft:-?}" \
    "$crashes" "$hangs" "$ooms" | tee -a "$summary"
  if (( crashes + hangs + ooms > 0 )); then
    found=1
    ls "$work"/artifacts/* >>"$build/fuzz-run/findings.txt"
  fi
done
echo "table: $summary; logs: $build/fuzz-run/HARNESS/log"
if (( found )); then
  echo "findings (reproduce with $build/fuzz/HARNESS FILE):"
  sort -u "$build/fuzz-run/findings.txt"
  rm -f "$build/fuzz-run/findings.txt"
  exit 1
fi
