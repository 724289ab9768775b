#!/usr/bin/env bash
# Sleeping in a jam (issue 66, point 3): the periodic Madrid Arena hallway at
# 9 /m2 with 40 % counter-flow (seed 3), PROFILE's model (paper by default),
# is run to 95 s with sleeping off and on (2 mm/s over 1 s, wake at 20 N:
# studies/sleeping/) (the jam forms and freezes), then its last 55 s are
# timed, resumed from the checkpoint at 95 s, REPEAT times, the two in turn
# (interleaved on a machine whose speed drifts). Prints per mode the median
# wall time of the 55 s, the share of steps asleep, and the ratio off / on
# (bench/jam_modes.sh).
# usage: bench/sleeping_jam.sh CROWDRECON [REPEAT=3] [THREADS=1] [PROFILE=paper]
set -euo pipefail
exec "$(dirname "$0")/jam_modes.sh" "$1" "${2:-3}" "${3:-1}" "${4:-paper}" "sleeping" \
  off '{"sleep_speed_m_per_s": 0}' \
  on '{"sleep_speed_m_per_s": 0.002, "sleep_time_s": 1.0, "sleep_wake_force_n": 20.0}'
