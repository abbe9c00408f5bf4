#!/usr/bin/env bash
# bench/viewshed_culling.sh: Stewart's culling pyramid (issue 12, item 3): on data/make_data.py's
# fractal at N = 256, 512 and 1024 and on the bundled DEM, the pyramid's preprocessing time and
# memory for each finest level kept, and for a valley, a ground-level and a high observer the
# share of the points it culls and an exact viewshed's time against a culled one's
# (`hfvis_bench viewshed-culling`: library calls, interleaved, the fastest of --reps).
# Writes bench/report/viewshed_culling.md (or --out FILE).
#
#   bench/viewshed_culling.sh [--sizes 256,512,1024] [--levels 1,2,3,4] [--reps 3] [--out FILE]
#   BUILD_DIR=... selects the build (default build/); inputs go to bench/out/data/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sizes=256,512,1024
levels=1,2,3,4
reps=3
out=$root/bench/report/viewshed_culling.md
while [[ $# -gt 0 ]]; do
  case "$1" in
    --sizes) sizes=$2; shift ;;
    --levels) levels=$2; shift ;;
    --reps) reps=$2; shift ;;
    --out) out=$2; shift ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) echo "viewshed_culling.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
build=${BUILD_DIR:-$root/build}
bench=$build/bench/hfvis_bench
[[ -x $bench ]] || { echo "viewshed_culling.sh: no hfvis_bench in $build (build it first)" >&2; exit 1; }
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
data=$root/bench/out/data
mkdir -p "$data" "$(dirname "$out")"
fields=()
for size in ${sizes//,/ }; do
  [[ -f $data/fractal_$size.exr ]] ||
    /usr/bin/python3 "$root/data/make_data.py" --size "$size" --out "$data" --no-dem --no-env --fields fractal > /dev/null
  fields+=("$data/fractal_$size.exr")
done
fields+=("$root/data/jacksboro_fault_dem.exr")
commit=$(git -C "$root" rev-parse --short HEAD 2> /dev/null || echo unknown)
git -C "$root" diff --quiet HEAD 2> /dev/null || commit="$commit (with uncommitted changes)"
{
  echo "# Viewsheds: Stewart's culling pyramid"
  echo
  echo "Made by \`bench/viewshed_culling.sh\` at $commit on $(date -u +%Y-%m-%d), on $(nproc) cores of"
  echo "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')."
  echo
  echo "Per field: one build of the pyramid (\`buildViewshedPyramid\`, default options: 16 sectors of 8"
  echo "horizon directions, targets on the surface) at the finest level listed, its memory when only"
  echo "the levels from each finest level up are kept, and per observer the hidden share of the"
  echo "points, the share the pyramid culls, and the exact viewshed's time against the culled one's"
  echo "(library calls without reading or writing files, interleaved, the fastest of $reps; the culled"
  echo "time includes the query). A culled viewshed equals the exact one bit for bit (checked here"
  echo "too: a difference would be printed)."
  "$bench" viewshed-culling --levels "$levels" --reps "$reps" "${fields[@]}" | sed "s|$root/||"
} > "$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
