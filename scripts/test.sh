#!/usr/bin/env bash
# The test command: installs what is missing, builds, and runs the whole test
# suite twice, as CI does: a Release build, then a build under AddressSanitizer
# and UndefinedBehaviorSanitizer. `--fast` runs the Release pass only.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
fast=0
[ "${1:-}" = "--fast" ] && fast=1

run_pass() {
  local name=$1 dir=$2
  shift 2
  echo "== tests: $name =="
  BUILD_DIR=$dir "$root/scripts/build.sh" "$@"
  (cd "$dir" && ctest --output-on-failure --timeout 900 -j "$(nproc)")
}

run_pass release "$root/build" -DSCANBENCH_SANITIZE=OFF
if [ $fast -eq 0 ]; then
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  BUILD_TYPE=RelWithDebInfo run_pass "asan+ubsan" "$root/build-asan" -DSCANBENCH_SANITIZE=ON
fi
