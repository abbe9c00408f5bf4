#!/usr/bin/env bash
# Installs the Debian packages hfvis needs, only those that are missing, then the Python
# package's build and test dependencies from PyPI into a virtual environment, build/python-venv
# (Debian 12's own Python takes no pip installs), again only those that are missing.
# Runs as root (or through sudo when it is available).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake pkg-config
  ocl-icd-opencl-dev opencl-clhpp-headers opencl-c-headers pocl-opencl-icd clinfo
  libopenimageio-dev openimageio-tools libopenexr-dev libglm-dev libgdal-dev
  googletest libgtest-dev
  clang libclang-rt-14-dev
  python3 python3-numpy python3-matplotlib python-matplotlib-data
  python3-dev python3-venv
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
else
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
    sudo=sudo
  fi
  echo "install-deps: installing ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  echo "install-deps: done"
fi

# The Python package: what pip builds it with (nanobind, scikit-build-core; --no-build-isolation
# then needs no download per build) and what its tests import.
venv=build/python-venv
python_packages=(nanobind scikit-build-core numpy xarray rioxarray dask distributed pytest)
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
if "$venv/bin/python" -c "import nanobind, scikit_build_core, numpy, xarray, rioxarray, dask, distributed, pytest" \
  2>/dev/null; then
  echo "install-deps: Python packages present in $venv"
else
  echo "install-deps: installing ${python_packages[*]} into $venv"
  "$venv/bin/pip" install -q "${python_packages[@]}"
fi
