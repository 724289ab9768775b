#!/usr/bin/env bash
# Installs what `make fuzz` needs beyond scripts/install-deps.sh, and only what
# is missing (docs/fuzzing.md): Debian 12's clang (14) with its OpenMP runtime,
# and compiler-rt, whose libclang_rt.fuzzer-x86_64.a is libFuzzer itself
# (with the sanitizer runtimes). Idempotent; works as root or through sudo.
#
#   scripts/install-fuzz-deps.sh            # install what is missing
#   scripts/install-fuzz-deps.sh --check    # list what is missing (exit 1 if any)
set -euo pipefail

packages=(clang libclang-rt-dev libomp-dev)

source "$(dirname "${BASH_SOURCE[0]}")/apt-install.sh"
apt_install_missing install-fuzz-deps "${1:-}"
