#!/usr/bin/env bash
# Runs `crowdrecon simulate SCENARIO -o RUN -q` in a scratch folder and checks
# its exit status, its output, the run file and that the scenario is unchanged:
#   engine_run_check.sh EXE SCENARIO RC REGEX [CHECK]...
# RC: the exact exit status expected (0, or 2 for a user's mistake or a run
# that went wrong). REGEX (extended) must match stdout + stderr. Each CHECK is
#   exists:SUFFIX      RUN.SUFFIX must exist (e.g. .failed-state)
#   absent:SUFFIX      RUN.SUFFIX must not exist
#   sql:QUERY=>REGEX   the rows of QUERY on the run file (one per line, columns
#                      joined by |) must match REGEX
set -u
exe=$1; scenario=$2; want_rc=$3; regex=$4; shift 4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
run=$tmp/run.sqlite
before=$(sha256sum "$scenario" | cut -d' ' -f1)
"$exe" simulate "$scenario" -o "$run" -q >"$tmp/out.txt" 2>&1
rc=$?
cat "$tmp/out.txt"
fail() { echo "engine_run_check.sh: $*"; exit 1; }
[[ $rc -eq $want_rc ]] || fail "expected exit $want_rc, got $rc"
grep -Eq -- "$regex" "$tmp/out.txt" || fail "output does not match /$regex/"
[[ $(sha256sum "$scenario" | cut -d' ' -f1) == "$before" ]] || fail "the scenario file changed"
for check in "$@"; do
  case $check in
    exists:*) [[ -e $run${check#exists:} ]] || fail "$run${check#exists:} is missing" ;;
    absent:*) [[ ! -e $run${check#absent:} ]] || fail "$run${check#absent:} should not exist" ;;
    sql:*)
      spec=${check#sql:}; query=${spec%%=>*}; want=${spec#*=>}
      rows=$(python3 -c 'import sqlite3, sys
for row in sqlite3.connect(sys.argv[1]).execute(sys.argv[2]): print("|".join(str(v) for v in row))' "$run" "$query") ||
        fail "query failed: $query"
      echo "$query -> $rows"
      grep -Eq -- "$want" <<<"$rows" || fail "rows of '$query' do not match /$want/" ;;
    *) fail "unknown check $check" ;;
  esac
done
echo "engine_run_check.sh: exit $rc as expected, output, files and run file as expected"
