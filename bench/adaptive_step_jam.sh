#!/usr/bin/env bash
# The adaptive step in a jam (issue 42): the periodic Madrid Arena hallway at
# 9 /m2 with 40 % counter-flow (seed 3) is run to 95 s with each step (the
# jam forms and freezes), then its last 55 s are timed, resumed from the
# checkpoint at 95 s, REPEAT times, the two steps in turn (interleaved on a
# machine whose speed drifts). Prints per step the median wall time of the
# 55 s, its steps by length, and the ratio fixed / adaptive (bench/jam_modes.sh).
# usage: bench/adaptive_step_jam.sh CROWDRECON [REPEAT=3] [THREADS=1]
set -euo pipefail
exec "$(dirname "$0")/jam_modes.sh" "$1" "${2:-3}" "${3:-1}" "" "adaptive step" \
  fixed '{"time_step_mode": "fixed"}' adaptive '{"time_step_mode": "adaptive"}'
