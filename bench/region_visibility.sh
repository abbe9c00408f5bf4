#!/usr/bin/env bash
# bench/region_visibility.sh: region visibility's backends (issue 28) on data/make_data.py's
# fractal at N = 1024: area lights (viewsheds against the culled march, S = 32 and 128; the culled
# march at S = 256 against the light's size and height), region pairs of 32 x 32 samples each
# (exact against culled, against the squares' size and distance) and the visible fraction's error
# against a Monte-Carlo reference of 16384 samples (`hfvis_bench region`: library calls, the
# backends interleaved, the fastest of --reps). Writes the tables to bench/out/region_visibility.md
# (or --out FILE); bench/report/region_visibility.md quotes a run.
#
#   bench/region_visibility.sh [--size 1024] [--sections pair,arealight,error] [--reps 2] [--out FILE]
#                              [--base-build DIR | --base-kernels DIR] [--rounds 2] [--field FILE]
#   BUILD_DIR=... selects the build (default build/); inputs go to bench/out/data/.
#   --base-build DIR: an existing build of an earlier commit (DIR/bench/hfvis_bench); its run and
#   this build's alternate, --rounds times each (base, current, base, ...), so that both meet the
#   same load; each run's tables go to the output under a heading naming its build.
#   --base-kernels DIR: the same, but the base is this build with an earlier commit's kernels/
#   (HFVIS_KERNEL_DIR=DIR; e.g. `git archive COMMIT kernels | tar -x -C OUT`, DIR = OUT/kernels): the
#   kernels' change alone, the host code the same.
#   --field FILE: that field instead of the fractal (e.g. `hfvis_bench field city 1024 FILE`).
#   (arealight-quick: S = 32 interleaved and the culled march at S = 1024, in minutes; pair-quick:
#   the pairs by the culled march alone, for profiling; bitmask: the bitmask scatter against the
#   culled march and the viewsheds at S = 32 and 1024, and its table's size; crossover: culled
#   against bitmask against S and the light's size and height, the default's choice.)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
size=1024
sections=pair,arealight,error
reps=2
out=$root/bench/out/region_visibility.md
base_build=
base_kernels=
field=
rounds=2
while [[ $# -gt 0 ]]; do
  case "$1" in
    --size) size=$2; shift ;;
    --sections) sections=$2; shift ;;
    --reps) reps=$2; shift ;;
    --out) out=$2; shift ;;
    --base-build) base_build=$2; shift ;;
    --rounds) rounds=$2; shift ;;
    --base-kernels) base_kernels=$2; shift ;;
    --field) field=$2; shift ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) echo "region_visibility.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
[[ -n $base_build && -n $base_kernels ]] &&
  { echo "region_visibility.sh: --base-build and --base-kernels name two different bases: give one" >&2; exit 2; }
build=${BUILD_DIR:-$root/build}
bench=$build/bench/hfvis_bench
[[ -x $bench ]] || { echo "region_visibility.sh: no hfvis_bench in $build (build it first)" >&2; exit 1; }
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
data=$root/bench/out/data
mkdir -p "$data" "$(dirname "$out")"
[[ -n $field || -f $data/fractal_$size.exr ]] ||
  /usr/bin/python3 "$root/data/make_data.py" --size "$size" --out "$data" --no-dem --no-env --fields fractal > /dev/null
field=${field:-$data/fractal_$size.exr}
if [[ -z $base_build && -z $base_kernels ]]; then
  "$bench" region --sections "$sections" --reps "$reps" "$field" | tee "$out"
  exit 0
fi
base_bench=$bench
if [[ -n $base_build ]]; then
  base_bench=$base_build/bench/hfvis_bench
  [[ -x $base_bench ]] || { echo "region_visibility.sh: no hfvis_bench in $base_build" >&2; exit 1; }
else
  [[ -f $base_kernels/region_visibility.cl ]] ||
    { echo "region_visibility.sh: no region_visibility.cl in $base_kernels" >&2; exit 1; }
fi
: > "$out"
for ((round = 1; round <= rounds; ++round)); do
  for which in base current; do
    b=$bench
    kernels=
    [[ $which == base ]] && b=$base_bench && kernels=$base_kernels
    echo -e "\n## round $round, $which build ($b${kernels:+, kernels $kernels}), load $(cut -d' ' -f1-3 /proc/loadavg)" |
      tee -a "$out"
    HFVIS_KERNEL_DIR=$kernels "$b" region --sections "$sections" --reps "$reps" "$field" | tee -a "$out"
  done
done
