#!/usr/bin/env bash
# A bad input is refused cleanly: the exit status, the message, nothing written,
# nothing changed.
#   expect_refused.sh STATUS REGEX [SETUP...] -- COMMAND [ARGS...]
# STATUS: "2" (crowdrecon: error ...) or "option" (an option's value refused
#   by the command-line parser: status 2 too, and the parser's "Run with
#   --help" line).
# SETUP, done in a scratch folder before the command:
#   --nested N NAME     NAME: a scenario whose "name" is N nested arrays
#   --long-key N NAME   NAME: an outline (points) with an unknown key of N characters
#   --corrupt RUN SQL   run.sqlite: a copy of RUN with SQL applied (sqlite3)
# Arguments may use @TMP@ (the scratch folder) and @OUT@ (a folder for the
# command's outputs, which must still be empty afterwards).
# Checks: the status; REGEX (extended) matches the output; no "internal
# error"; @OUT@ empty; every file named in the arguments unchanged.
set -u
status=$1; regex=$2; shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/out"
scenario_head='{"format": "crowdrecon-scenario", "version": 1, '
while [[ $# -gt 0 && "$1" != "--" ]]; do
  case "$1" in
    --nested)
      { printf '%s"name": ' "$scenario_head"; printf '%*s' "$2" '' | tr ' ' '['; printf '%*s' "$2" '' | tr ' ' ']'; printf '}\n'; } >"$tmp/$3"
      shift 3 ;;
    --long-key)
      { printf '{"points": [[0, 0], [0.3, 0], [0.3, 0.2], [0, 0.2]], "'; printf '%*s' "$2" '' | tr ' ' 'k'; printf '": 1}\n'; } >"$tmp/$3"
      shift 3 ;;
    --corrupt)
      cp "$2" "$tmp/run.sqlite" && sqlite3 "$tmp/run.sqlite" "$3" || { echo "expect_refused.sh: cannot corrupt $2"; exit 1; }
      shift 3 ;;
    *) echo "expect_refused.sh: unknown setup $1"; exit 1 ;;
  esac
done
[[ "${1:-}" == "--" ]] && shift
args=()
for a in "$@"; do a="${a//@TMP@/$tmp}"; args+=("${a//@OUT@/$tmp/out}"); done
# Checksums of the files the command is given (inputs), before.
inputs=()
for a in "${args[@]}"; do [[ -f "$a" ]] && inputs+=("$a"); done
before=$( ((${#inputs[@]})) && md5sum "${inputs[@]}")
"${args[@]}" >"$tmp/log.txt" 2>&1
rc=$?
head -c 4000 "$tmp/log.txt"
fail() { echo "expect_refused.sh: $*"; exit 1; }
case "$status" in
  2) [[ $rc -eq 2 ]] || fail "expected exit status 2, got $rc" ;;
  option) [[ $rc -eq 2 ]] && grep -q "Run with --help for more information" "$tmp/log.txt" ||
            fail "expected an option error (status 2 and the parser's \"Run with --help\"), got $rc" ;;
  *) fail "unknown STATUS $status" ;;
esac
grep -q "internal error" "$tmp/log.txt" && fail "the message says \"internal error\""
grep -Eq -- "$regex" "$tmp/log.txt" || fail "output does not match /$regex/"
[[ -z "$(ls -A "$tmp/out")" ]] || fail "something was written: $(ls -A "$tmp/out" | head -5 | tr '\n' ' ')"
after=$( ((${#inputs[@]})) && md5sum "${inputs[@]}")
[[ "$before" == "$after" ]] || fail "an input file changed"
echo "expect_refused.sh: exit $rc as expected, output matches, nothing written or changed"
