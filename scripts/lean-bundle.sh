#!/usr/bin/env bash
# The lean simulation build in one folder that runs on a machine without the
# project's packages (issue 42: the GPU machine takes 64 MiB of build outputs):
#
#   BUNDLE/crowdrecon-simulate        runs bin/crowdrecon-simulate with the
#                                     bundled loader and libraries
#   BUNDLE/bin/crowdrecon-simulate    crowdrecon's simulate command alone
#                                     (cli/simulate_main.cpp; C++ runtime linked
#                                     in; the CUDA runtime too where built with CUDA)
#   BUNDLE/lib/                       every shared library it loads (ldd), and
#                                     this machine's dynamic loader, so that the
#                                     host's own C library does not matter
#
# The GPU driver (libcuda.so.1) is not bundled: it must be the host's, and the
# loader finds it in the host's usual places.
# usage: scripts/lean-bundle.sh [BUILD_DIR] [BUNDLE]   (default build/release, build/lean-bundle)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/release}; bundle=${2:-build/lean-bundle}
cmake --build "$build" --target crowdrecon-simulate >/dev/null
exe="$build/cli/crowdrecon-simulate"
rm -rf "$bundle.partial"; mkdir -p "$bundle.partial/bin" "$bundle.partial/lib"
cp "$exe" "$bundle.partial/bin/"
strip --strip-unneeded "$bundle.partial/bin/crowdrecon-simulate"
loader=""
while read -r name arrow path rest; do
  if [[ "$name" == /* ]]; then loader=$name; continue; fi   # the dynamic loader's own line
  [[ "$arrow" == "=>" && "$path" == /* ]] || continue       # linux-vdso and the like
  cp -L "$path" "$bundle.partial/lib/$name"
done < <(ldd "$exe")
[[ -n "$loader" ]] || { echo "lean-bundle: no dynamic loader in ldd's answer for $exe" >&2; exit 1; }
cp -L "$loader" "$bundle.partial/lib/$(basename "$loader")"
cat > "$bundle.partial/crowdrecon-simulate" <<'WRAPPER'
#!/bin/sh
here=$(cd "$(dirname "$0")" && pwd)
exec "$here/lib/ld-linux-x86-64.so.2" --library-path "$here/lib" "$here/bin/crowdrecon-simulate" "$@"
WRAPPER
chmod +x "$bundle.partial/crowdrecon-simulate"
rm -rf "$bundle"; mv "$bundle.partial" "$bundle"
size=$(du -sb "$bundle" | cut -f1)
echo "$bundle: $(ls "$bundle/lib" | wc -l) libraries, $(awk -v s="$size" 'BEGIN {printf "%.1f MiB", s / 1048576}') in all"
(( size <= 64 * 1048576 )) || { echo "lean-bundle: over the 64 MiB a device machine takes" >&2; exit 1; }
