#!/usr/bin/env bash
# scripts/make_pictures.sh: the pictures README.md and docs/ show, made by the CLI from the bundled data
# into docs/pictures/ (or DIR): the Jacksboro DEM lit by the clear sky (environment and sun,
# tonemapped), a hillshade with cast shadows, the sky-view factor and ambient occlusion with a
# contrast stretch, a winter day's direct sunlight, the fractal field under the sky, the PVS size
# per view cell and one view cell's set, and an area light's soft shadows and a site's visual
# impact (arealight).
#
#   scripts/make_pictures.sh [DIR]      (BUILD_DIR=... selects the build, default build/)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
hfvis=${BUILD_DIR:-$root/build}/hfvis
out=${1:-$root/docs/pictures}
[[ -x $hfvis ]] || { echo "make_pictures.sh: no hfvis at $hfvis (build it first)" >&2; exit 1; }
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
dem=$root/data/jacksboro_fault_dem.exr
sky=$root/data/clear_sky.exr
run() { echo "hfvis $*"; "$hfvis" "$@"; }
run shade "$dem" -o "$tmp/sky.exr" --env "$sky" --albedo 0.5 -k 128 --preview "$out/jacksboro_clear_sky.png"
run shade "$dem" -o "$tmp/hill.exr" --sun 240,15 --preview "$out/jacksboro_hillshade.png"
run svf "$dem" -o "$tmp/svf.exr" --preview "$out/jacksboro_svf.png"
run ao "$dem" -o "$tmp/ao.exr" --preview "$out/jacksboro_ao.png"
run insolation "$dem" -o "$tmp/sun.exr" --lat 36.4 --lon -84.2 --from 2026-12-21T00:00:00-05:00 \
  --to 2026-12-22T00:00:00-05:00 --step 10 --preview "$out/jacksboro_december_sun.png"
run shade "$root/data/fractal_256.exr" -o "$tmp/fractal.exr" --z-scale 2 --env "$sky" --albedo 0.6 -k 128 \
  --preview "$out/fractal_clear_sky.png"
run pvs "$dem" -o "$tmp/pvs.json" --samples 1000000 --view-cell 32 --tile 16 --preview "$out/jacksboro_pvs_size.png"
run pvs "$dem" -o "$tmp/pvs.json" --samples 1000000 --view-cell 32 --tile 16 --preview-view-cell 200,170 \
  --preview "$out/jacksboro_pvs_view_cell.png"
# A light of 31 x 141 grid points over the west edge, in a plane 1400 m up (the DEM tops out at
# 1076 m): soft shadows cast eastward (about a minute: 256 samples for every pixel).
run arealight "$dem" -o "$tmp/light.exr" --light 0,100,30,240 --light-height 1400 --absolute --samples 256 \
  --preview "$out/jacksboro_area_light.png"
# The share of a 21 x 21-pixel site on the ridge, 120 m above the ground, that an eye 1.7 m up
# sees from each pixel.
run arealight "$dem" -o "$tmp/site.exr" --light 240,80,260,100 --light-height 120 --target-height 1.7 \
  --samples 64 --preview "$out/jacksboro_visual_impact.png"
