#!/usr/bin/env bash
# Builds the Python package as a user would (pip install . into build/python-venv, which
# scripts/install-deps.sh makes) and runs its tests (python/tests, pytest). Needs build/hfvis and
# build/bench/hfvis_bench (scripts/build.sh): the tests compare with the CLI. Extra arguments go
# to pytest. The build directory (build/python/) persists, so a rebuild is incremental.
set -euo pipefail
cd "$(dirname "$0")/.."
export POCL_CACHE_DIR="${POCL_CACHE_DIR:-$PWD/bench/out/pocl-cache}"
venv=build/python-venv
start=$(date +%s)
"$venv/bin/pip" install -q --no-build-isolation .
echo "python: pip install . took $(( $(date +%s) - start )) s"
start=$(date +%s)
# From build/, so that the source tree's python/hfvis (without its compiled _core) is not imported.
(cd build && python-venv/bin/python -m pytest -q -p no:cacheprovider ../python/tests "$@")
echo "python: pytest took $(( $(date +%s) - start )) s"
