#!/usr/bin/env bash
# bench/pvs.sh: potentially visible sets (issue 29): the ray caster's rays per second on 1024^2
# fields, and recall against the dense reference and the pixel error (estimated and measured)
# against samples for AGVS, SGVS and per-cell sampling on a city, a rough terrain and the
# bundled DEM (`hfvis_bench pvs-rays`, `hfvis_bench pvs-recall`). Writes bench/report/pvs_tables.md (or
# --out FILE), the tables after a line saying how and when they ran.
#
#   bench/pvs.sh [--size 128] [--samples 10000,30000,100000,300000,1000000] [--rays 1000000] [--out FILE]
#   BUILD_DIR=... selects the build (default build/).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
size=128
samples=10000,30000,100000,300000,1000000
rays=1000000
out=$root/bench/report/pvs_tables.md
while [[ $# -gt 0 ]]; do
  case "$1" in
    --size) size=$2; shift ;;
    --samples) samples=$2; shift ;;
    --rays) rays=$2; shift ;;
    --out) out=$2; shift ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
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
{
  echo "## The ray caster"
  echo
  "$bench" pvs-rays --size 1024 --rays "$rays" --reps 2 --dem "$dem" city noise
  echo
  echo "## Recall and pixel error against samples ($size x $size fields)"
  "$bench" pvs-recall --size "$size" --view-cell 16 --tile 8 --samples "$samples" --dem "$dem" city noise dem
} > "$tmp"
{
  echo "<!-- bench/pvs.sh --size $size --samples $samples --rays $rays; $(date -u +%Y-%m-%dT%H:%MZ), commit $(git -C "$root" rev-parse --short HEAD) -->"
  cat "$tmp"
} > "$out"
echo "pvs.sh: wrote $out (bench/report/pvs.md discusses it)"
