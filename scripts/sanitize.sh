#!/usr/bin/env bash
# The sanitizer and fuzzing check (issue 19): builds granmem's libraries, their unit tests
# and the fuzz harnesses with clang, AddressSanitizer and UndefinedBehaviorSanitizer (and
# libFuzzer's coverage) in build-asan/ (SANITIZE_BUILD), runs the unit tests that take seconds under it
# (core, tracking, rotation, sim, calibration; the end-to-end and long tests run in the
# normal build),
# then each fuzz harness for FUZZ_SECONDS (default 60) from its seed corpus in
# fuzz/corpus/. Any sanitizer report, test failure or fuzz crash fails it; a crashing input
# is left in build-asan/fuzz/ (crash-*), to add to fuzz/corpus/<harness> with a test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh clang libclang-rt-dev
jobs=$(nproc 2>/dev/null || echo 2)
seconds=${FUZZ_SECONDS:-60}
build=${SANITIZE_BUILD:-build-asan}
harnesses=(fuzz_tiff fuzz_import_csv fuzz_option_values)
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DGRANMEM_PYTHON=OFF -DGRANMEM_FUZZ=ON \
  -DCMAKE_CXX_FLAGS="$flags -fsanitize=fuzzer-no-link" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined"
cmake --build "$build" -j"$jobs" --target granmem_core_tests granmem_tracking_tests \
  granmem_rotation_tests granmem_sim_tests granmem_calibration_tests "${harnesses[@]}"

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Left out: tests of minutes under the sanitizers (whole protocols, read-out sweeps, large
# renders) and the memory measurements (the sanitizers' shadow memory is in the RSS).
# Under the sanitizers these take 10 s to 4 min each (~40 min in all). What runs: ~4 min,
# plus ~2.5 min each for the three other PlacedPacking tests (a 300-grain pour each). The
# settle left out asserts physics the normal build checks (its bounds measured under clang
# ASan too, once).
slow="ReadoutSweep\.|Locate\.|SettledPile\.|HoleAxis\.NoTiltUnderABlurWiderAlongZ"
slow+="|CyclicSamples\.|Illumination\.|Restart\.(AKept|Resumed|Stopped)"
slow+="|Render\.(SameSeed|HoleLies)|StackMemoryTest\."
slow+="|FrictionFit\.(Realization|PerCycle)|FrictionSeriesTest\.EachRun"
slow+="|PlacedPacking\.APackingAtRest"
ctest --test-dir "$build" --output-on-failure -j"$jobs" -L "core|tracking|rotation|sim|calibration" -E "$slow"

mkdir -p "$build/fuzz/work"
for harness in "${harnesses[@]}"; do
  corpus=$build/fuzz/work/$harness
  mkdir -p "$corpus"
  echo "== $harness, ${seconds} s"
  "$build/fuzz/$harness" -max_total_time="$seconds" -rss_limit_mb=2048 -max_len=65536 \
    -print_final_stats=1 -artifact_prefix="$build/fuzz/" "$corpus" "fuzz/corpus/$harness"
done
echo "sanitizers and fuzzing: clean"
