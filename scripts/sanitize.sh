#!/usr/bin/env bash
# The sanitizer part of CI (docs/fuzzing.md): builds the "sanitize" preset (clang, AddressSanitizer
# + UndefinedBehaviorSanitizer with float-cast-overflow, libFuzzer targets), runs the tests not
# labelled "slow" under it, then each fuzz target for a bounded time on a seed corpus made from
# scenes/, tests/ and the repository's OBJ files. Exits non-zero if a test fails or a fuzzer finds
# anything; a fuzzer's failing input is kept in the build folder (path printed, and its base64
# when it is small).
#
# Usage: scripts/sanitize.sh
# Environment: CLOTHSIM_SANITIZE_DIR   build folder (default build/sanitize)
#              CLOTHSIM_FUZZ_SECONDS   time per fuzz target [s] (default 60; 0 skips fuzzing)
#              CLOTHSIM_SANITIZE_TESTS 0 skips the tests
set -uo pipefail
cd "$(dirname "$0")/.."
source_dir=$(pwd)
build=${CLOTHSIM_SANITIZE_DIR:-build/sanitize}
fuzz_seconds=${CLOTHSIM_FUZZ_SECONDS:-60}
run_tests=${CLOTHSIM_SANITIZE_TESTS:-1}

# The sanitizers' run-time options, as the "sanitize" test preset sets them for the tests.
# LeakSanitizer's suppressions are for an uninstrumented system library only (fuzz/lsan.supp).
# The fuzzers also detect the use of a function's locals after it returned (too slow for the
# tests).
export ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:strict_init_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$source_dir/fuzz/lsan.supp:print_suppressions=0"

now() { date +%s; }
elapsed() { echo "$(( $(now) - $1 )) s"; }
failures=()

scripts/install_deps.sh || exit 1

start=$(now)
cmake --preset sanitize -B "$build" >/dev/null || exit 1
cmake --build "$build" -j2 || exit 1
echo "sanitize: build $(elapsed "$start")"

if [ "$run_tests" != 0 ]; then
  start=$(now)
  # The "sanitize" test preset: tests not labelled slow, -j2, the sanitizer options below.
  if ! ctest --preset sanitize --test-dir "$build"; then
    failures+=("tests")
  fi
  echo "sanitize: tests not labelled slow $(elapsed "$start")"
fi

# Each fuzz target: its seeds (read only), a fresh working corpus, its artifacts. The scene
# target keeps a scene's mesh to 10 000 vertices (fuzz/fuzz_inputs.hpp), which load in well under
# a second; -timeout=30 is then a hang. -rss_limit_mb=2048 (also the largest single allocation)
# would even hold a scene at the default limit of a million vertices (1.2 GB under ASan).
fuzz_root="$build/fuzz-run"
if [ "$fuzz_seconds" != 0 ]; then
  rm -rf "$fuzz_root"
  mkdir -p "$fuzz_root"
  python3 fuzz/make_corpus.py "$source_dir" "$fuzz_root/seeds" || exit 1
  for target in scene obj; do
    work="$fuzz_root/$target"
    mkdir -p "$work/corpus" "$work/artifacts"
    case $target in
      scene) dict="$fuzz_root/seeds/scene.dict"; max_len=16384 ;;
      obj) dict="fuzz/obj.dict"; max_len=16384 ;;
    esac
    start=$(now)
    ASAN_OPTIONS="$ASAN_OPTIONS:detect_stack_use_after_return=1" \
    "$build/fuzz/fuzz_$target" -max_total_time="$fuzz_seconds" -timeout=30 -rss_limit_mb=2048 \
      -max_len=$max_len -dict="$dict" -print_final_stats=1 -artifact_prefix="$work/artifacts/" \
      "$work/corpus" "$fuzz_root/seeds/$target" >"$work/log" 2>&1
    status=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log")
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$work/log")
    added=$(sed -n 's/^stat::new_units_added: *//p' "$work/log")
    rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$work/log")
    cov=$(grep -o 'cov: [0-9]*' "$work/log" | tail -1)
    echo "sanitize: fuzz_$target $(elapsed "$start"): ${runs:-?} inputs, ${rate:-?} exec/s, ${added:-?} new corpus units, $cov, peak RSS ${rss:-?} MB, exit $status (log $work/log)"
    artifacts=("$work"/artifacts/*)
    if [ "$status" != 0 ] || [ -e "${artifacts[0]}" ]; then
      failures+=("fuzz_$target")
      grep -E '^(==[0-9]+==ERROR|SUMMARY|.*runtime error|.*terminate called|.*what\(\))' "$work/log" | head -20
      tail -40 "$work/log"
      for a in "${artifacts[@]}"; do
        [ -e "$a" ] || continue
        size=$(stat -c %s "$a")
        echo "sanitize: fuzz_$target failing input kept: $a ($size bytes; replay: $build/fuzz/fuzz_$target $a)"
        if [ "$size" -le 4096 ]; then
          echo "sanitize: base64 of $a:"
          base64 "$a"
        fi
      done
    fi
  done
fi

if [ ${#failures[@]} -ne 0 ]; then
  echo "sanitize: FAILED: ${failures[*]}"
  exit 1
fi
echo "sanitize: passed"
