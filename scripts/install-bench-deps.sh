#!/usr/bin/env bash
# Installs what the benchmarks need beyond scripts/install-deps.sh, and only
# what is missing: LAMMPS with its BODY package and Open MPI for the comparison
# of bench/lammps_compare.py, GNU time for bench/run_benchmarks.py. CI does not
# need these. Idempotent; works as root or through sudo.
#
#   scripts/install-bench-deps.sh            # install what is missing
#   scripts/install-bench-deps.sh --check    # list what is missing, install nothing (exit 1 if any)
set -euo pipefail

packages=(
  # LAMMPS (Debian 12: stable 29 Sep 2021 update 2, with the BODY package:
  # atom_style body rounded/polygon, pair_style body/rounded/polygon, fix nve/body)
  lammps
  # its MPI launcher (mpirun); lammps depends on mpi-default-bin, named here
  # so that a missing launcher is reported by --check
  openmpi-bin
  # GNU time: peak resident memory of whole runs
  time
  python3
)

source "$(dirname "${BASH_SOURCE[0]}")/apt-install.sh"
apt_install_missing install-bench-deps "${1:-}"
