#!/usr/bin/env bash
# bench/pvs.sh: potentially visible sets (issue 29): the ray caster's rays per second on 1024^2
# fields (`hfvis_bench pvs-rays`, into bench/report/pvs_tables.md), and recall against the dense
# reference and the pixel error (estimated and measured) against samples for AGVS, SGVS and
# per-cell sampling on a city, a rough terrain and the bundled DEM (`hfvis_bench pvs-recall`, into
# bench/report/pvs_recall_tables.md): at --size with the dense reference, then at --estimate-size
# with the issue's grid (view cells of 32 x 32 cells, tiles of 16 x 16; the DEM at 320 x 320,
# within its 403 x 344) without it (the dense reference is out of reach there), for the estimate.
# The part `limits` (not run by default; about 7 minutes) runs past the recall part's budgets, into
# bench/report/pvs_limits_tables.md: AGVS up to 30M samples at 128^2 with the dense reference, SGVS
# and per-cell sampling at 3, 9 and 30M on the rough terrain, and AGVS's estimate at the end of ten
# 1M-sample runs (seeds 1 .. 10) on the DEM at 320^2, where few missing entries are left to count.
# Runs settle their estimate (PvsOptions::estimate_entries, the default 20; the tables' column
# "settling the estimate" gives the samples that took) except where the samplers' recall is
# compared at equal samples (the limits part's first two sections: --estimate-entries 0). The
# limits part's first section also gives recall against the dense reference inside the tiles
# (DenseTargets::InsideTiles: without the entries seen only at a tile's border).
# Each file starts with a line saying how and when it ran.
#
#   bench/pvs.sh [--parts rays,recall,limits] [--size 128] [--estimate-size 1024]
#                [--samples 10000,30000,100000,300000,1000000] [--rays 1000000]
#   BUILD_DIR=... selects the build (default build/).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
parts=rays,recall
size=128
estimate_size=1024
samples=10000,30000,100000,300000,1000000
rays=1000000
while [[ $# -gt 0 ]]; do
  case "$1" in
    --parts) parts=$2; shift ;;
    --size) size=$2; shift ;;
    --estimate-size) estimate_size=$2; shift ;;
    --samples) samples=$2; shift ;;
    --rays) rays=$2; shift ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "pvs.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
build=${BUILD_DIR:-$root/build}
bench=$build/bench/hfvis_bench
[[ -x $bench ]] || { echo "pvs.sh: no hfvis_bench in $build (build it first)" >&2; exit 1; }
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
dem=$root/data/jacksboro_fault_dem.exr
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
# Runs the rest of the line into $tmp, then writes it to $1 after a line saying how and when.
write() {
  local out=$1
  shift
  "$@" > "$tmp"
  {
    echo "<!-- bench/pvs.sh --parts $parts --size $size --estimate-size $estimate_size --samples $samples --rays $rays; $(date -u +%Y-%m-%dT%H:%MZ), commit $(git -C "$root" rev-parse --short HEAD) -->"
    cat "$tmp"
  } > "$out"
  echo "pvs.sh: wrote $out (bench/report/pvs.md discusses it)"
}
rays_part() {
  echo "## The ray caster"
  echo
  "$bench" pvs-rays --size 1024 --rays "$rays" --reps 2 --dem "$dem" city noise
}
recall_part() {
  echo "## Recall and pixel error against samples ($size x $size fields)"
  "$bench" pvs-recall --check-rays 4000000 --size "$size" --view-cell 16 --tile 8 --samples "$samples" --dem "$dem" city noise dem
  echo
  echo "## The pixel error against samples ($estimate_size x $estimate_size fields, no dense reference)"
  "$bench" pvs-recall --check-rays 4000000 --size "$estimate_size" --view-cell 32 --tile 16 --samples "$samples" --reference no \
    --dem "$dem" city noise
  echo
  echo "## The pixel error against samples (the DEM at 320 x 320, within its 403 x 344; no dense reference)"
  "$bench" pvs-recall --check-rays 4000000 --size 320 --view-cell 32 --tile 16 --samples "$samples" --reference no --dem "$dem" dem
}
limits_part() {
  echo "## Recall past 1M samples ($size x $size fields, view cells 16 x 16, tiles 8 x 8; each run ends at its budget, --estimate-entries 0)"
  "$bench" pvs-recall --check-rays 1000000 --size "$size" --view-cell 16 --tile 8 --estimate-entries 0 \
    --inside yes --samples 1000000,3000000,10000000,30000000 --methods agvs --dem "$dem" city noise dem
  echo
  echo "## SGVS and per-cell sampling at 1x, 3x and 10x the samples AGVS took to 0.99 on the rough terrain (--estimate-entries 0)"
  "$bench" pvs-recall --check-rays 1000000 --size "$size" --view-cell 16 --tile 8 --estimate-entries 0 \
    --samples 3000000,9000000,30000000 --methods sgvs,per-cell --dem "$dem" noise
  echo
  echo "## AGVS's estimate at the end of ten 1M-sample runs (the DEM at 320 x 320, seeds 1 .. 10; the estimate settled on 20 entries found once)"
  "$bench" pvs-recall --check-rays 4000000 --size 320 --view-cell 32 --tile 16 --samples 1000000 \
    --reference no --methods agvs --seeds 1,2,3,4,5,6,7,8,9,10 --dem "$dem" dem
}
for part in ${parts//,/ }; do
  case "$part" in
    rays) write "$root/bench/report/pvs_tables.md" rays_part ;;
    recall) write "$root/bench/report/pvs_recall_tables.md" recall_part ;;
    limits) write "$root/bench/report/pvs_limits_tables.md" limits_part ;;
    *) echo "pvs.sh: unknown part '$part' (rays, recall, limits)" >&2; exit 2 ;;
  esac
done
