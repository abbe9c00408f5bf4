#!/usr/bin/env bash
# Installs what is missing, builds, runs the whole test suite (CTest + GoogleTest), builds the
# Python package and runs its tests (scripts/python_test.sh), then
# installs hfvis into build/install and builds and runs examples/ against that package, as a
# downstream project would (find_package(hfvis CONFIG), no source tree), runs the suite again
# built with AddressSanitizer and UndefinedBehaviorSanitizer (scripts/sanitize.sh), and
# finally replays the fuzz regressions and fuzzes the height-field loader and the CLI's
# argument parser for a minute each (scripts/fuzz.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
(cd build && ctest --output-on-failure -j "$(nproc)")
echo "== the Python package: pip install . into build/python-venv, then its tests (pytest)"
bash scripts/python_test.sh
echo "== examples/ against the installed package (build/install)"
rm -rf build/install build/examples
cmake --install build --prefix "$PWD/build/install" > /dev/null
cmake -S examples -B build/examples -DCMAKE_PREFIX_PATH="$PWD/build/install" > /dev/null
cmake --build build/examples -j "$(nproc)" > /dev/null
build/examples/sky_view_factor
echo "== the test suite under AddressSanitizer and UndefinedBehaviorSanitizer (build-asan)"
bash scripts/sanitize.sh
echo "== fuzzing (libFuzzer, Clang): the height-field loader and the CLI argument parser (build-fuzz)"
bash scripts/fuzz.sh
