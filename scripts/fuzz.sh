#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, with AddressSanitizer and
# UndefinedBehaviorSanitizer) and runs each for a while on its seed corpus.
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     (default 60 s, all targets)
# With FUZZ_RUNS=N in the environment each target instead runs until it has
# executed N inputs, however long that takes (SECONDS_PER_TARGET is ignored).
# Corpora grow in build-fuzz/corpus/<target> across runs; a finding leaves its
# input in build-fuzz/findings/ and makes the script fail. Each target's line
# "fuzz: <target>: N executions in S s, no finding" is what docs/reliability.md
# records.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_ptx fuzz_pcd fuzz_triplet fuzz_e57 fuzz_ply fuzz_las
  fuzz_project fuzz_view fuzz_script fuzz_replay)
build=${FUZZ_BUILD_DIR:-$root/build-fuzz}

"$root/scripts/install-deps.sh"
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" -DSCANBENCH_FUZZ=ON -DSCANBENCH_TESTS=OFF \
  -DSCANBENCH_BENCH=OFF >/dev/null
cmake --build "$build" --target fuzz_targets --parallel "$(nproc)"

max_len() {  # projects hold compressed layers; the text readers' inputs are small
  case $1 in fuzz_project) echo 1048576 ;; *) echo 65536 ;; esac
}
dictionary() {
  case $1 in
    fuzz_ptx) echo ptx ;; fuzz_pcd) echo pcd ;; fuzz_triplet) echo triplet ;; fuzz_e57) echo e57 ;;
    fuzz_ply) echo ply ;; fuzz_las) echo las ;;
    fuzz_project) echo project ;; fuzz_view) echo view ;; fuzz_script) echo script ;;
    fuzz_replay) echo replay ;;
  esac
}

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
mkdir -p "$build/findings"
status=0
for target in "${targets[@]}"; do
  corpus=$build/corpus/$target
  mkdir -p "$corpus"
  # The seeds fuzz/CMakeLists.txt names for the target.
  while read -r file; do cp -n "$file" "$corpus/" 2>/dev/null || true; done <"$build/fuzz/$target.seeds"
  log=$build/$target.log
  if [ -n "${FUZZ_RUNS:-}" ]; then limit=(-runs="$FUZZ_RUNS"); else limit=(-max_total_time="$seconds"); fi
  started=$(date +%s)
  set +e
  "$build/bin/$target" "$corpus" -dict="$root/fuzz/dict/$(dictionary "$target").dict" \
    "${limit[@]}" -max_len="$(max_len "$target")" -timeout=10 -rss_limit_mb=4096 \
    -artifact_prefix="$build/findings/$target-" -print_final_stats=1 >"$log" 2>&1
  code=$?
  set -e
  elapsed=$(($(date +%s) - started))
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  if [ $code -eq 0 ]; then
    echo "fuzz: $target: $runs executions in $elapsed s, no finding"
  else
    echo "fuzz: $target: FINDING after $runs executions (exit $code); see $log and $build/findings/"
    tail -30 "$log"
    status=1
  fi
done
exit $status
