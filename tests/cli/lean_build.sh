#!/usr/bin/env bash
# The lean simulation build (issue 42): crowdrecon-simulate gives the same run
# as crowdrecon (the tables' digest), and its bundle (scripts/lean-bundle.sh:
# the program, every shared library it loads and the loader) runs on its own
# loader and libraries, within the 64 MiB a device machine takes.
# usage: lean_build.sh CROWDRECON CROWDRECON_SIMULATE SOURCE_DIR BUILD_DIR SCENARIO
set -euo pipefail
full=$1; lean=$2; src=$3; build=$4; scenario=$5
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
"$full" simulate "$scenario" -o "$tmp/full.sqlite" -q >/dev/null
"$lean" simulate "$scenario" -o "$tmp/lean.sqlite" -q >/dev/null
d_full=$("$full" analyze "$tmp/full.sqlite" --digest); d_lean=$("$full" analyze "$tmp/lean.sqlite" --digest)
[[ "$d_full" == "$d_lean" ]] || { echo "FAIL: the lean build's run differs: $d_lean / $d_full"; exit 1; }
if ldd "$lean" | grep -q "libstdc++"; then
  direct=$(readelf -d "$lean" | grep -c "libstdc++" || true)
  [[ $direct -eq 0 ]] || { echo "FAIL: the lean program needs libstdc++ itself (it should be linked in)"; exit 1; }
fi
out=$(bash "$src/scripts/lean-bundle.sh" "$build" "$tmp/bundle")
echo "$out"
[[ "$out" == *"MiB in all"* ]] || { echo "FAIL: no size"; exit 1; }
[[ -x "$tmp/bundle/lib/ld-linux-x86-64.so.2" ]] || { echo "FAIL: no loader in the bundle"; exit 1; }
"$tmp/bundle/crowdrecon-simulate" simulate "$scenario" -o "$tmp/bundled.sqlite" -q >/dev/null
d_bundled=$("$full" analyze "$tmp/bundled.sqlite" --digest)
[[ "$d_bundled" == "$d_full" ]] || { echo "FAIL: the bundle's run differs"; exit 1; }
# Only the simulate command is in it.
set +e
"$lean" render x.sqlite >/dev/null 2>&1; rc=$?
set -e
[[ $rc -eq 2 ]] || { echo "FAIL: the lean build answered another command with $rc"; exit 1; }
echo "lean build: OK"
