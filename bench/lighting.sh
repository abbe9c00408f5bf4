#!/usr/bin/env bash
# bench/lighting.sh: environment lighting (issue 11). Time per frame of `computeHorizons` with an
# environment (irradiance only; program built; the fastest of --reps runs) on the fractal field
# at N = 512, 1024, 2048 and K = 16, 64, 256, under data/clear_sky.exr; then the error against a
# Monte-Carlo ray-traced reference (bench/lighting.cpp) on a 64 x 64 fractal, against K and the
# table's bands. Writes bench/report/lighting.md (or --out FILE).
#
#   bench/lighting.sh [--sizes 512,1024,2048] [-k 16,64,256] [--reps 2] [--samples 4096] [--out FILE]
#   BUILD_DIR=... selects the build (default build/); inputs go to bench/out/data/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sizes=512,1024,2048
k=16,64,256
reps=2
samples=4096
out=$root/bench/report/lighting.md
while [[ $# -gt 0 ]]; do
  case "$1" in
    --sizes) sizes=$2; shift ;;
    -k) k=$2; shift ;;
    --reps) reps=$2; shift ;;
    --samples) samples=$2; shift ;;
    --out) out=$2; shift ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) echo "lighting.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
bench=${BUILD_DIR:-$root/build}/bench/hfvis_bench
[[ -x $bench ]] || { echo "lighting.sh: no hfvis_bench at $bench (build it first)" >&2; exit 1; }
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
data=$root/bench/out/data
mkdir -p "$data" "$(dirname "$out")"
fields=()
for n in ${sizes//,/ } 64; do
  [[ -f $data/fractal_$n.exr ]] || /usr/bin/python3 "$root/data/make_data.py" --size "$n" --out "$data" --no-dem --no-env --fields fractal > /dev/null
  [[ $n == 64 ]] || fields+=("$data/fractal_$n.exr")
done
commit=$(git -C "$root" rev-parse --short HEAD 2> /dev/null || echo unknown)
git -C "$root" diff --quiet HEAD 2> /dev/null || commit="$commit (with uncommitted changes)"
{
  echo "# Environment lighting"
  echo
  echo "Made by \`bench/lighting.sh\` at $commit on $(date -u +%Y-%m-%d)."
  echo
  echo "## Time per frame"
  echo
  echo "Irradiance from data/clear_sky.exr through the horizons (\`computeHorizons\` with an environment"
  echo "only: the sweep, the tables built on the device and the reduction), fractal fields of"
  echo "data/make_data.py. Times are whole library calls, uploads and downloads included."
  echo
  "$bench" lighting-time --env "$root/data/clear_sky.exr" -k "$k" --reps "$reps" "${fields[@]}"
  echo
  echo "## Error against a Monte-Carlo reference"
  echo
  echo "Per pixel, stratified cosine-weighted directions about the normal, each marched on the"
  echo "bilinear surface in steps of 1/20 pixel (1/4 left 0.3 % of error in the reference); the map's sun"
  echo "pixel on a 16 x 16 grid of directions (bench/lighting.cpp). Relative error per pixel and channel."
  echo
  "$bench" lighting-error "$data/fractal_64.exr" --env "$root/data/clear_sky.exr" --samples "$samples" \
    -k 4,8,16,32,64,128,256 --rows 8,16,32,64
} | sed "s|$root/||g" > "$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
