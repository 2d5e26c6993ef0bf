#!/usr/bin/env bash
# The test command (CI runs it): installs what is missing, builds, and runs
# the tests.
#
#   scripts/test.sh           one build, clang with AddressSanitizer and
#                             UndefinedBehaviorSanitizer at -O1 (every
#                             programmer-error assert on; the UBSan checks
#                             below left out): every test but the Release-only
#                             ones (label release_only: the simulator's own
#                             tests, the bench smoke runs), and each fuzz
#                             target's seeds replayed
#   scripts/test.sh --full    that with every UBSan check, then the Release
#                             build that scripts/demo.sh makes (GCC, with the
#                             benches and their PCL peers) with every test,
#                             then each fuzz target fuzzed for FUZZ_SECONDS
#                             (default 10) in its coverage build
#                             (scripts/fuzz.sh, every UBSan check)
#   scripts/test.sh --fast    the Release pass only
#
# One build keeps CI short on two cores: a cold build takes about 6 minutes
# for the sanitizer tree, 13 for Release (docs/CONTRIBUTING.md).
#
# The UBSan checks the default pass leaves out: alignment, null,
# pointer-overflow, object-size and vptr cost that tree a fifth of its compile
# time and two thirds of the registration tests' run time, for what
# AddressSanitizer already reports (a null or out-of-bounds access), casts
# the code does not make (no dynamic_cast or typeid) and pointer arithmetic
# that wraps. The full pass and the fuzz tree keep them.
ubsan_skip=alignment,null,pointer-overflow,object-size,vptr
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
mode=default
case "${1:-}" in
  --full) mode=full ;;
  --fast) mode=fast ;;
  "") ;;
  *) echo "usage: scripts/test.sh [--full | --fast]" >&2; exit 2 ;;
esac

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

sanitizer_pass() {
  local skip=$1
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  BUILD_TYPE=RelWithDebInfo run_pass "asan+ubsan" "$root/build-asan-clang" "-LE release_only" \
    -DCMAKE_CXX_COMPILER=clang++ -DSCANBENCH_SANITIZE=ON -DSCANBENCH_BENCH=OFF \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" "-DSCANBENCH_UBSAN_SKIP=$skip"
}

release_pass() {
  run_pass release "$root/build" "" -DSCANBENCH_SANITIZE=OFF
}

"$root/scripts/install-deps.sh" --tests
case $mode in
  fast) release_pass ;;
  default) sanitizer_pass "$ubsan_skip" ;;
  full)
    sanitizer_pass ""
    release_pass
    echo "== fuzz =="
    start=$SECONDS
    "$root/scripts/fuzz.sh" "${FUZZ_SECONDS:-10}"
    echo "== fuzz: built and run in $((SECONDS - start)) s =="
    ;;
esac
