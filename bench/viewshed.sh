#!/usr/bin/env bash
# bench/viewshed.sh: viewsheds (issue 12) against gdal_viewshed (Debian's gdal-bin). On
# data/make_data.py's fractal at N = 4096 (a float32 GeoTIFF, uncompressed, so both read the
# same file as fast as they can), for a ground-level observer at the centre (eye 2 above the
# surface), a high one there (100) and one near a corner (2): the whole command's wall time of
# `hfvis viewshed` and of `gdal_viewshed -cc 0` (no curvature in either), interleaved, --rounds
# times each; then how far each visible set is from the exact sight-line test on the bilinear
# surface, on --samples random targets (`hfvis_bench viewshed-agreement`). Last, a cumulative
# viewshed of 1000 random observers on the fractal at N = 1024, against 1000 runs of
# gdal_viewshed one after another (GDAL has no cumulative viewshed; its rasters are not summed).
# Writes bench/report/viewshed.md (or --out FILE).
#
#   bench/viewshed.sh [--size 4096] [--rounds 3] [--samples 20000] [--observers 1000] [--out FILE]
#   BUILD_DIR=... selects the build (default build/); inputs go to bench/out/data/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
n=4096
rounds=3
samples=20000
observers=1000
out=$root/bench/report/viewshed.md
while [[ $# -gt 0 ]]; do
  case "$1" in
    --size) n=$2; shift ;;
    --rounds) rounds=$2; shift ;;
    --samples) samples=$2; shift ;;
    --observers) observers=$2; shift ;;
    --out) out=$2; shift ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "viewshed.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
build=${BUILD_DIR:-$root/build}
cli=$build/hfvis
bench=$build/bench/hfvis_bench
[[ -x $cli && -x $bench ]] || { echo "viewshed.sh: no hfvis or hfvis_bench in $build (build them first)" >&2; exit 1; }
for tool in gdal_viewshed gdal_translate oiiotool; do
  command -v $tool > /dev/null || { echo "viewshed.sh: needs $tool (Debian packages gdal-bin, openimageio-tools)" >&2; exit 1; }
done
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
data=$root/bench/out/data
work=$root/bench/out/viewshed
mkdir -p "$data" "$work" "$(dirname "$out")"

# A float32 GeoTIFF of the fractal at size $1, uncompressed.
tiff() {
  local size=$1 tif=$data/fractal_$1.tif
  if [[ ! -f $tif ]]; then
    [[ -f $data/fractal_$size.exr ]] || /usr/bin/python3 "$root/data/make_data.py" --size "$size" --out "$data" --no-dem --no-env --fields fractal > /dev/null
    oiiotool "$data/fractal_$size.exr" -d float -o "$work/tmp.tif"
    gdal_translate -q -co COMPRESS=NONE "$work/tmp.tif" "$tif"
    rm -f "$work/tmp.tif"
  fi
  echo "$tif"
}

# Wall seconds of a command (its output discarded).
seconds() {
  local start end
  start=$(date +%s.%N)
  "$@" > /dev/null
  end=$(date +%s.%N)
  echo "$end - $start" | bc -l
}
stats() {  # min and median of the numbers on stdin
  sort -g | awk '{ v[NR] = $1 } END { printf "%.2f | %.2f", v[1], (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'
}

dem=$(tiff "$n")
c=$((n / 2))
commit=$(git -C "$root" rev-parse --short HEAD 2> /dev/null || echo unknown)
git -C "$root" diff --quiet HEAD 2> /dev/null || commit="$commit (with uncommitted changes)"
"$cli" viewshed "$dem" -o "$work/warm.tif" --observer "$c,$c" -q  # the program built once, as a user's second run finds it
{
  echo "# Viewsheds"
  echo
  echo "Made by \`bench/viewshed.sh\` at $commit on $(date -u +%Y-%m-%d), on $(nproc) cores of"
  echo "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //') (OpenCL device: $("$cli" devices | awk '/^\* [0-9]/ {print $4}'))."
  echo
  echo "## One viewshed: time and agreement with the exact test"
  echo
  echo "data/make_data.py's fractal at $n x $n as an uncompressed float32 GeoTIFF; targets on the"
  echo "surface (target height 0), no curvature. Whole commands, reading the DEM and writing a GeoTIFF:"
  echo "\`hfvis viewshed DEM -o OUT.tif --observer C,R --observer-height H\` against"
  echo "\`gdal_viewshed -cc 0 -ox C -oy R -oz H DEM OUT.tif\`, interleaved, $rounds rounds, seconds. The"
  echo "agreement is with the exact sight-line test on the bilinear surface (\`hfvis_bench"
  echo "viewshed-agreement\`, double precision) on $samples random targets: the Jaccard index of the"
  echo "visible sets, and how many disagreements graze (the exact test itself turns with the eye"
  echo "1e-4 higher or lower)."
  echo
  echo "| observer | hfvis min | hfvis median | gdal_viewshed min | gdal_viewshed median | hfvis / gdal (min) |"
  echo "|---|---|---|---|---|---|"
} > "$out.tmp"
agreements=""
for spec in "centre,$c,$c,2" "high,$c,$c,100" "corner,64,64,2"; do
  IFS=, read -r name col row height <<< "$spec"
  : > "$work/h.txt"
  : > "$work/g.txt"
  for ((r = 0; r < rounds; ++r)); do
    seconds "$cli" viewshed "$dem" -o "$work/hfvis_$name.tif" --observer "$col,$row" --observer-height "$height" -q >> "$work/h.txt"
    seconds gdal_viewshed -q -cc 0 -ox "$col" -oy "$row" -oz "$height" "$dem" "$work/gdal_$name.tif" >> "$work/g.txt"
  done
  hmin=$(sort -g "$work/h.txt" | head -1)
  gmin=$(sort -g "$work/g.txt" | head -1)
  echo "| $name ($col,$row, eye $height) | $(stats < "$work/h.txt") | $(stats < "$work/g.txt") | $(echo "$hmin / $gmin" | bc -l | xargs printf '%.1f') |" >> "$out.tmp"
  agreements+=$'\n'"Observer $name ($col,$row, eye $height):"$'\n\n'
  agreements+=$("$bench" viewshed-agreement "$dem" --observer "$col,$row" --observer-height "$height" --samples "$samples" \
    "$work/hfvis_$name.tif" "$work/gdal_$name.tif" | sed "s|$work/||")
  agreements+=$'\n'
done
echo "$agreements" >> "$out.tmp"

# The floor of a whole command: a process that starts and stops (the dynamic loader, no OpenCL).
floor() {
  for _ in 1 2 3 4 5; do seconds "$@"; done | sort -g | head -1
}
{
  echo "Start-up alone, the fastest of 5: \`hfvis --help\` $(printf '%.3f' "$(floor "$cli" --help)") s,"
  echo "\`gdalinfo --version\` $(printf '%.3f' "$(floor gdalinfo --version)") s. The centre's command with"
  echo "\`--max-distance 1\` (no rays, a few targets marched; the slope bounds and the maximum pyramid"
  echo "of the whole field, the classification of every point, reading and writing all still run),"
  echo "the fastest of 5: $(printf '%.2f' "$(floor "$cli" viewshed "$dem" -o "$work/floor.tif" --observer "$c,$c" --max-distance 1 -q)") s."
} >> "$out.tmp"

# Cumulative viewshed.
small=$(tiff 1024)
/usr/bin/python3 - "$observers" > "$work/observers.csv" <<'EOF'
import random, sys
random.seed(12)
print("col,row,height")
for _ in range(int(sys.argv[1])):
    print("%d,%d,2" % (random.randrange(1024), random.randrange(1024)))
EOF
hc=$(seconds "$cli" viewshed "$small" -o "$work/count.tif" --observers "$work/observers.csv" -q)
start=$(date +%s.%N)
tail -n +2 "$work/observers.csv" | while IFS=, read -r col row height; do
  gdal_viewshed -q -cc 0 -ox "$col" -oy "$row" -oz "$height" "$small" "$work/one.tif" > /dev/null
done
gc=$(echo "$(date +%s.%N) - $start" | bc -l)
{
  echo
  echo "## Cumulative viewshed"
  echo
  echo "$observers observers at random grid points of the fractal at 1024 x 1024 (eye 2), whole commands:"
  echo "\`hfvis viewshed DEM -o COUNT.tif --observers FILE.csv\` (channel count) took $(printf '%.1f' "$hc") s; $observers"
  echo "runs of gdal_viewshed one after another took $(printf '%.1f' "$gc") s (without summing their rasters)."
} >> "$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
