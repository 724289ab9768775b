#!/usr/bin/env bash
# Installs the Debian 12 packages crowdrecon needs, and only those that are missing.
# Idempotent: a second run installs nothing. Works as root or through sudo.
#
#   scripts/install-deps.sh            # build + test dependencies
#   scripts/install-deps.sh --check    # list what is missing, install nothing (exit 1 if any)
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git python3 ccache
  # numerics and geometry
  libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  # calibration
  libceres-dev
  # images, video, floor-plan rasters
  libopencv-dev
  # vector drawing (SVG, PNG, PDF pictures and reports)
  libcairo2-dev
  # configuration, command line, floor plans, run files
  nlohmann-json3-dev libcli11-dev libdxflib-dev libsqlite3-dev sqlite3 libzstd-dev
  # sweeps spread over several machines (crowdrecon sweep under mpirun)
  libopenmpi-dev openmpi-bin
  # reports: report.pdf printed by headless Chromium; its pages checked as pictures (pdftoppm)
  chromium poppler-utils
  # tests and benchmarks (GNU time: peak memory in bench/run_benchmarks.py)
  libgtest-dev libgmock-dev libbenchmark-dev time
  # the MPI interruption check finds rank 0 with pgrep
  procps
)

source "$(dirname "${BASH_SOURCE[0]}")/apt-install.sh"
apt_install_missing install-deps "${1:-}"
