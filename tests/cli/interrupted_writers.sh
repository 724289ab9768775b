#!/usr/bin/env bash
# Interruptions of `export` and `observe footage` (issue 40), each at
# two moments by SIGINT, SIGTERM and SIGKILL to its process group, as a
# terminal's Ctrl-C would send it. Whether the signal lands while the
# command works or after it is done, it must hold: the exit status is 0 or
# 128 + the signal; no process of it is left; after SIGINT or SIGTERM
# nothing is left beside the output (after SIGKILL a hidden partial file
# may be, which the rerun removes and says so); the output, if there, is the
# complete one; and the same command run again ends with the output of an
# uninterrupted run, byte for byte (export: its SQLite dump).
#   interrupted_writers.sh CROWDRECON RUN_FILE SPEC
set -uo pipefail
exe=$1; run=$2; spec=$3
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail() { echo "interrupted_writers.sh: $*"; exit 1; }
dump() { python3 -c 'import hashlib, sqlite3, sys; print(hashlib.sha256("\n".join(sqlite3.connect(sys.argv[1]).iterdump()).encode()).hexdigest())' "$1"; }
"$exe" observe synthesize "$run" -o "$d/clip.avi" --homography-out "$d/h.json" --width 320 --height 180 > /dev/null ||
  fail "could not make the footage"
export_cmd=(export "$run")
footage_cmd=(observe footage "$d/clip.avi" --homography "$d/h.json" --spec "$spec" -q)
"$exe" "${export_cmd[@]}" -o "$d/whole.sqlite" > /dev/null || fail "export failed"
"$exe" "${footage_cmd[@]}" -o "$d/whole.json" > /dev/null || fail "observe footage failed"
export_ref=$(dump "$d/whole.sqlite")
footage_ref=$(sed "s#whole\.csv#out.csv#" "$d/whole.json" | sha256sum | cut -c1-64)$(sha256sum < "$d/whole.csv" | cut -c1-64)
result() {  # result KIND OUTPUT: the output's fingerprint ("" if absent)
  if [[ $1 == export ]]; then [[ -e $2 ]] && dump "$2"
  else [[ -e $2 ]] && echo "$(sha256sum < "$2" | cut -c1-64)$(sha256sum < "${2%.json}.csv" | cut -c1-64)"; fi
}
set -m
cases=0
for kind in export footage; do
  if [[ $kind == export ]]; then out=$d/out.sqlite; cmd=("${export_cmd[@]}" -o "$out"); ref=$export_ref
  else out=$d/out.json; cmd=("${footage_cmd[@]}" -o "$out"); ref=$footage_ref; fi
  for signal in INT TERM KILL; do
    for at in 0.05 0.3; do
      rm -rf "$d/out".* "$d"/.out.*
      "$exe" "${cmd[@]}" > "$d/first.txt" 2>&1 &
      pid=$!
      sleep "$at"
      kill -s "$signal" -- "-$pid" 2>/dev/null
      wait "$pid"; rc=$?
      case $signal in INT) sig=2 ;; TERM) sig=15 ;; KILL) sig=9 ;; esac
      [[ $rc -eq 0 || $rc -eq $((128 + sig)) ]] || { cat "$d/first.txt"; fail "$kind SIG$signal at $at s: exit $rc"; }
      sleep 0.1
      pgrep -f -- "-o $out" > /dev/null && fail "$kind SIG$signal at $at s: still running"
      left=$(ls -A "$d" | grep -E '^\.out|^out\.(sqlite-|json\.|csv\.)' || true)
      if [[ $signal != KILL && -n $left ]]; then fail "$kind SIG$signal at $at s: left $left"; fi
      now=$(result "$kind" "$out")
      [[ -z $now || $now == "$ref" ]] || fail "$kind SIG$signal at $at s: an output that is not the complete one"
      "$exe" "${cmd[@]}" > "$d/rerun.txt" 2>&1 || { cat "$d/rerun.txt"; fail "$kind SIG$signal at $at s: the rerun failed"; }
      for p in $left; do
        grep -qF "$d/$p" "$d/rerun.txt" || { cat "$d/rerun.txt"; fail "$kind SIG$signal at $at s: the rerun did not say it removed $p"; }
        [[ ! -e $d/$p ]] || fail "$kind SIG$signal at $at s: the rerun left $p"
      done
      [[ $(result "$kind" "$out") == "$ref" ]] || fail "$kind SIG$signal at $at s: the rerun's output differs"
      echo "$kind SIG$signal at $at s: exit $rc, left '${left}', rerun identical"
      cases=$((cases + 1))
    done
  done
done
echo "$cases interruptions: no process left, nothing left but what the rerun removed, every rerun identical"
