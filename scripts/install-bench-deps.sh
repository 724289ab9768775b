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

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-bench-deps: all ${#packages[@]} packages present"
  exit 0
fi

if [[ "${1:-}" == "--check" ]]; then
  echo "install-bench-deps: missing: ${missing[*]}"
  exit 1
fi

echo "install-bench-deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
  else
    echo "install-bench-deps: not root and no sudo; install these packages: ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
