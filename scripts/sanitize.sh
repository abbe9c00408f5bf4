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
# intercept_tls_get_addr=0: PoCL dlopens one shared object per built kernel program, and once a
# test process has built a few dozen (BounceAnalytic.VValleyInManyDirections is where it
# tips), LeakSanitizer's dynamic-TLS bookkeeping hands its tracer a garbage range and the
# tracer crashes at exit ("Tracer caught signal 11 ... DTLS 36 at 0x2909"). Without the
# interception LSan skips the dynamic TLS of dlopened objects only; leaks are still reported.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cd build-asan
ctest --output-on-failure -j "$(nproc)"
