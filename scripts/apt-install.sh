# Shared by scripts/install-deps.sh and scripts/install-bench-deps.sh (sourced,
# not run): installs the Debian packages of the array `packages` that are
# missing, and only those. Idempotent; works as root or through sudo.
#
#   apt_install_missing NAME [--check]
# NAME prefixes the messages; --check lists what is missing, installs nothing,
# and returns 1 if anything is.
apt_install_missing() {
  local name=$1 mode=${2:-}
  local missing=() p
  for p in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$p")
    fi
  done
  if [[ ${#missing[@]} -eq 0 ]]; then
    echo "$name: all ${#packages[@]} packages present"
    return 0
  fi
  if [[ "$mode" == "--check" ]]; then
    echo "$name: missing: ${missing[*]}"
    return 1
  fi
  echo "$name: installing ${missing[*]}"
  local sudo_cmd=()
  if [[ $(id -u) -ne 0 ]]; then
    if command -v sudo >/dev/null 2>&1; then
      sudo_cmd=(sudo)
    else
      echo "$name: not root and no sudo; install these packages: ${missing[*]}" >&2
      return 1
    fi
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -q
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
}
