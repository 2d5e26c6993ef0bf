#!/usr/bin/env bash
# The test command: installs what is missing, builds, and runs the whole test
# suite twice, as CI does: a Release build, then a build under AddressSanitizer
# and UndefinedBehaviorSanitizer at -O1 with clang (GCC's sanitizer build
# took 22 minutes cold on two cores, clang's about half), without the
# benches and the tests labelled release_only (the simulator's own tests,
# the bench smoke runs), then every fuzz target for a short while
# (scripts/fuzz.sh; FUZZ_SECONDS, default 10, per target). `--fast` runs
# the Release pass only.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
fast=0
[ "${1:-}" = "--fast" ] && fast=1

run_pass() {
  local name=$1 dir=$2 ctest_args=$3
  shift 3
  echo "== tests: $name =="
  local start=$SECONDS
  BUILD_DIR=$dir "$root/scripts/build.sh" "$@"
  echo "== $name: built in $((SECONDS - start)) s =="
  # shellcheck disable=SC2086
  (cd "$dir" && ctest --output-on-failure --timeout 900 -j "$(nproc)" $ctest_args)
  echo "== $name: built and tested in $((SECONDS - start)) s =="
}

"$root/scripts/install-deps.sh" --tests
run_pass release "$root/build" "" -DSCANBENCH_SANITIZE=OFF
if [ $fast -eq 0 ]; then
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  BUILD_TYPE=RelWithDebInfo run_pass "asan+ubsan" "$root/build-asan-clang" "-LE release_only" \
    -DCMAKE_CXX_COMPILER=clang++ -DSCANBENCH_SANITIZE=ON -DSCANBENCH_BENCH=OFF "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1"
  echo "== fuzz =="
  start=$SECONDS
  "$root/scripts/fuzz.sh" "${FUZZ_SECONDS:-10}"
  echo "== fuzz: built and run in $((SECONDS - start)) s =="
fi
