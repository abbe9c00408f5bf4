#!/usr/bin/env bash
# Sets up build/bench-venv (hfvis's wheel, rvt-py, xarray-spatial from PyPI; RVT without its
# GDAL and notebook dependencies, which rvt.vis does not import) and runs
# python/bench/compare_python_tools.py. Needs scripts/build.sh and build/python-venv
# (scripts/install-deps.sh). Not part of the tests.
set -euo pipefail
cd "$(dirname "$0")/.."
export POCL_CACHE_DIR="${POCL_CACHE_DIR:-$PWD/bench/out/pocl-cache}"
venv=build/bench-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install -q numpy scipy xarray xarray-spatial
"$venv/bin/pip" install -q --no-deps rvt-py
rm -rf build/wheels
build/python-venv/bin/pip wheel -q --no-build-isolation --no-deps -w build/wheels .
"$venv/bin/pip" install -q --force-reinstall --no-deps build/wheels/hfvis-*.whl
"$venv/bin/python" python/bench/compare_python_tools.py "$@"
