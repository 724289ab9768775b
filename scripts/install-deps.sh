#!/usr/bin/env bash
# Installs the Debian 12 packages crowdrecon needs, and only those that are missing.
# Idempotent: a second run installs nothing. Works as root or through sudo.
#
#   scripts/install-deps.sh            # build + test dependencies
#   scripts/install-deps.sh --check    # list what is missing, install nothing (exit 1 if any)
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git python3
  # numerics and geometry
  libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  # calibration
  libceres-dev
  # images, video, floor-plan rasters
  libopencv-dev
  # vector drawing (SVG, PNG, PDF pictures and reports)
  libcairo2-dev
  # configuration, command line, floor plans, run files
  nlohmann-json3-dev libcli11-dev libdxflib-dev libsqlite3-dev sqlite3
  # sweeps spread over several machines (crowdrecon sweep under mpirun)
  libopenmpi-dev openmpi-bin
  # tests and benchmarks (GNU time: peak memory in bench/run_benchmarks.py)
  libgtest-dev libgmock-dev libbenchmark-dev time
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

if [[ "${1:-}" == "--check" ]]; then
  echo "install-deps: missing: ${missing[*]}"
  exit 1
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
  else
    echo "install-deps: not root and no sudo; install these packages: ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
