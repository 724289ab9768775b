#!/usr/bin/env bash
# Runs a command and checks its exit status and its combined output.
#   expect.sh ok|fail REGEX -- COMMAND [ARGS...]
# "fail" means a non-zero exit status; REGEX (extended) must match the output.
set -u
status=$1; regex=$2; shift 2
[[ "$1" == "--" ]] && shift
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export CLI_TMP=$tmp
# Arguments may mention $CLI_TMP for scratch outputs.
args=()
for a in "$@"; do args+=("${a//@TMP@/$tmp}"); done
"${args[@]}" >"$tmp/out.txt" 2>&1
rc=$?
cat "$tmp/out.txt"
if [[ $status == ok && $rc -ne 0 ]]; then echo "expect.sh: expected success, got exit $rc"; exit 1; fi
if [[ $status == fail && $rc -eq 0 ]]; then echo "expect.sh: expected failure, got exit 0"; exit 1; fi
if ! grep -Eq -- "$regex" "$tmp/out.txt"; then echo "expect.sh: output does not match /$regex/"; exit 1; fi
echo "expect.sh: exit $rc as expected, output matches"
