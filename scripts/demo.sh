#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job on bundled data: horizons,
# sky-view factor and ambient occlusion of the Jacksboro fault DEM (data/), 64 directions.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
out=build/demo
mkdir -p "$out"
dem=data/jacksboro_fault_dem.exr
echo "demo: $dem (403 x 344, 3 arc-second cells of 74.6 x 92.5 m, read from the file)"
build/hfvis horizon "$dem" -o "$out/horizon.exr" -k 64 --distance-out "$out/horizon_distance.exr" \
  --preview "$out/horizon.png"
build/hfvis svf "$dem" -o "$out/svf.exr" -k 64 --preview "$out/svf.png"
build/hfvis ao "$dem" -o "$out/ao.exr" -k 64 --preview "$out/ao.png"
echo "demo: outputs in $(cd "$out" && pwd): horizon.exr (64 channels h000..h063, radians), horizon_distance.exr, svf.exr, ao.exr and PNG previews"
