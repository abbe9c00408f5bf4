#!/usr/bin/env bash
# Builds the library, the CLI and the tests with AddressSanitizer and UndefinedBehaviorSanitizer
# into build-asan/ and runs the whole test suite there (the CLI tests run the instrumented CLI).
# Any report fails the run: ASan aborts on the first error, LeakSanitizer fails the process at
# exit on a leak, and UBSan is built with -fno-sanitize-recover. No suppressions are needed
# today (PoCL and OpenImageIO included). The benchmark is not built (its smoke tests are
# skipped, with their reason).
set -euo pipefail
cd "$(dirname "$0")/.."
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHFVIS_BUILD_BENCH=OFF \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" > /dev/null
cmake --build build-asan -j "$(nproc)"
# A build that lost its flags would pass without checking anything.
for binary in build-asan/hfvis build-asan/tests/hfvis_tests; do
  symbols=$(nm "$binary")  # (grep -q on a pipe would end nm early: a SIGPIPE under pipefail)
  grep -q "__asan_init" <<< "$symbols" || { echo "sanitize.sh: $binary is not instrumented" >&2; exit 1; }
  grep -q "__ubsan_handle" <<< "$symbols" || { echo "sanitize.sh: $binary has no UBSan checks" >&2; exit 1; }
done
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cd build-asan
ctest --output-on-failure -j "$(nproc)"
