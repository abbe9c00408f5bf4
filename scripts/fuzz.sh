#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with Clang (AddressSanitizer, UndefinedBehaviorSanitizer,
# coverage over the library too) into build-fuzz/, replays every input in fuzz/regressions/
# (each once crashed something; all must pass now), then fuzzes each target for a bounded time
# (HFVIS_FUZZ_SECONDS, default 60) from its seed corpus in fuzz/corpus/. A crash fails the run
# and leaves its input in build-fuzz/: fix the bug, then add the input to fuzz/regressions/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${HFVIS_FUZZ_SECONDS:-60}
command -v clang++ > /dev/null || { echo "fuzz.sh: needs clang++ (scripts/install-deps.sh installs it)" >&2; exit 1; }
CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHFVIS_BUILD_FUZZERS=ON \
  -DHFVIS_BUILD_TESTS=OFF -DHFVIS_BUILD_BENCH=OFF -DHFVIS_BUILD_CLI=OFF -DHFVIS_INSTALL=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined" > /dev/null
cmake --build build-fuzz -j "$(nproc)" --target height_field_fuzzer arguments_fuzzer observers_fuzzer \
  environment_fuzzer
# fast_unwind_on_malloc=0: leaks inside uninstrumented libraries get full stacks, which the
# suppressions (fuzz/lsan.supp, each with its reason) match.
export ASAN_OPTIONS=detect_leaks=1:fast_unwind_on_malloc=0
export LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp
for target in height_field arguments observers environment; do
  fuzzer=build-fuzz/fuzz/${target}_fuzzer
  regressions=(fuzz/regressions/$target/*)
  if [[ -e ${regressions[0]} ]]; then
    echo "== $target: replaying ${#regressions[@]} regression input(s)"
    "$fuzzer" "${regressions[@]}" > "build-fuzz/$target-regressions.log" 2>&1 ||
      { tail -30 "build-fuzz/$target-regressions.log"; exit 1; }
  fi
  echo "== $target: fuzzing for $seconds s"
  mkdir -p "build-fuzz/corpus/$target"  # new inputs go here; the repository's seeds stay as they are
  # -rss_limit_mb bounds the memory a run touches. -malloc_limit_mb (by default the same) would
  # also fail a single large reservation that is never touched: OpenEXR reserves a chunk's rows
  # as a header claims them (up to the readers' 64 GiB claim limit) and fills only what the file
  # holds, so the single-allocation limit is the readers' own claim limit.
  "$fuzzer" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=4096 -malloc_limit_mb=65536 -print_final_stats=1 \
    -artifact_prefix="build-fuzz/$target-" "build-fuzz/corpus/$target" "fuzz/corpus/$target" \
    > "build-fuzz/$target.log" 2>&1 || { tail -40 "build-fuzz/$target.log"; exit 1; }
  grep -E "stat::number_of_executed_units|stat::new_units_added" "build-fuzz/$target.log" | tr '\n' ' '
  echo
done
