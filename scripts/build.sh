#!/usr/bin/env bash
# Configures and builds scanbench into BUILD_DIR (default: build/, Release).
# Extra arguments go to CMake's configure step, e.g. -DSCANBENCH_SANITIZE=ON.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=${BUILD_DIR:-$root/build}
build_type=${BUILD_TYPE:-Release}
# PCL only for a tree with the benches (SCANBENCH_BENCH, on unless turned off).
deps=(--bench)
for arg in "$@"; do
  case $arg in -DSCANBENCH_BENCH=OFF | -DSCANBENCH_BENCH:BOOL=OFF) deps=() ;; esac
done
"$root/scripts/install-deps.sh" "${deps[@]}"
cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="$build_type" "$@" >/dev/null
cmake --build "$build_dir" --parallel "$(nproc)"
