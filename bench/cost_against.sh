#!/usr/bin/env bash
# bench/cost_against.sh: what a change costs, as a user pays it: the whole `hfvis svf` and
# `hfvis viewcount` commands (default options: the sweep and the hull tree at their default
# sampling) of this checkout's build against a baseline commit's, on the same N x N inputs,
# run in turn (base, current, current, base, ...) so that a drift of the machine's speed
# falls on both alike. Prints each command's median wall and CPU (user + system) seconds over
# the rounds and the ratios of the medians, and writes the table to bench/out/cost_against.md.
# On a machine shared with other work the CPU time is the steadier figure.
#
#   bench/cost_against.sh [--base COMMIT] [--base-build DIR] [--size N] [-k K] [--rounds R]
#                         [--contents "fractal city"] [--ops "svf viewcount"]
#     defaults: --base bad9286 (before the segment peaks), N = 1024, K = 64, R = 5, both contents,
#     both commands
#   BUILD_DIR=... this checkout's build (default build/); the baseline is built in
#   bench/out/base-COMMIT/ (a git worktree, git-ignored), or --base-build names an existing build
#   of COMMIT (its hfvis), which is only run, never rebuilt.
# Contents: "fractal" (data/make_data.py's terrain) and "city" (the city DSM hard case, written
# by hfvis_bench field).
set -euo pipefail
source "$(dirname "$0")/cost_inputs.sh"

root=$(cd "$(dirname "$0")/.." && pwd)
base=bad9286
size=1024
k=64
rounds=5
contents="fractal city"
ops="svf viewcount"
base_build=
while [[ $# -gt 0 ]]; do
  case "$1" in
    --base) base=$2; shift ;;
    --base-build) base_build=$2; shift ;;
    --size) size=$2; shift ;;
    -k) k=$2; shift ;;
    --rounds) rounds=$2; shift ;;
    --contents) contents=$2; shift ;;
    --ops) ops=$2; shift ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) echo "cost_against.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
build_dir=${BUILD_DIR:-$root/build}
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
out=$root/bench/out/cost_against
data=$root/bench/out/data
mkdir -p "$out" "$data"

base_sha=$(git -C "$root" rev-parse --short "$base")
if [[ -n $base_build ]]; then
  base_bin=$base_build/hfvis
  [[ -x $base_bin ]] || { echo "cost_against.sh: no hfvis in $base_build" >&2; exit 2; }
  echo "== building this checkout in $build_dir (the base: $base_bin as it is)"
  dirs=("$root")
else
  base_dir=$root/bench/out/base-$base_sha
  if [[ ! -d $base_dir ]]; then
    git -C "$root" worktree add --detach "$base_dir" "$base_sha" > /dev/null
  fi
  base_bin=$base_dir/build/hfvis
  echo "== building $base_sha in $base_dir/build and this checkout in $build_dir"
  dirs=("$base_dir" "$root")
fi
for dir in "${dirs[@]}"; do
  b=$dir/build
  [[ $dir == "$root" ]] && b=$build_dir
  cmake -S "$dir" -B "$b" -DCMAKE_BUILD_TYPE=Release > /dev/null
  cmake --build "$b" -j "$(nproc)" --target hfvis_cli hfvis_bench > /dev/null
done

inputs=()
for content in $contents; do inputs+=("$(cost_input "$content" "$size" "$build_dir" "$data")"); done

current=$(git -C "$root" rev-parse --short HEAD)
git -C "$root" diff --quiet HEAD -- kernels src include cli || current="$current (with uncommitted changes)"
echo "commit: $current against $base_sha, $(date -u +%Y-%m-%dT%H:%M:%SZ), load average $(cut -d' ' -f1-3 /proc/loadavg)"

# "wall cpu" seconds of one whole command (cpu: user + system, of the command and its threads)
run() {
  /usr/bin/time -f '%e %U %S' -o "$out/time.txt" "$@" -q > /dev/null
  awk '{printf "%s %.3f\n", $1, $2 + $3}' "$out/time.txt"
}

table=$out/../cost_against.md
{
  echo "# Whole-command cost: $current against $base_sha"
  echo
  echo "${size}x${size}, K = $k, default options, $rounds rounds in turn (base and current alternate which runs first);"
  echo "median seconds of each. Written by bench/cost_against.sh on $(uname -n), $(nproc) cores,"
  echo "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')."
  echo
  echo "| command | input | base wall (s) | current wall (s) | wall current / base | base CPU (s) | current CPU (s) | CPU current / base |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
} > "$table"
for op in $ops; do
  for input in "${inputs[@]}"; do
    name=$(basename "$input" .exr)
    for bin in "$base_bin" "$build_dir/hfvis"; do  # warm-up: PoCL compiles and caches the kernels
      "$bin" "$op" "$input" -o "$out/warm.tif" -k "$k" -q > /dev/null
    done
    base_times=() current_times=()
    for ((i = 0; i < rounds; ++i)); do
      if ((i % 2 == 0)); then
        base_times+=("$(run "$base_bin" "$op" "$input" -o "$out/base.tif" -k "$k")")
        current_times+=("$(run "$build_dir/hfvis" "$op" "$input" -o "$out/current.tif" -k "$k")")
      else
        current_times+=("$(run "$build_dir/hfvis" "$op" "$input" -o "$out/current.tif" -k "$k")")
        base_times+=("$(run "$base_bin" "$op" "$input" -o "$out/base.tif" -k "$k")")
      fi
    done
    tb=$(printf '%s\n' "${base_times[@]}" | cut -d' ' -f1 | median)
    tc=$(printf '%s\n' "${current_times[@]}" | cut -d' ' -f1 | median)
    cb=$(printf '%s\n' "${base_times[@]}" | cut -d' ' -f2 | median)
    cc=$(printf '%s\n' "${current_times[@]}" | cut -d' ' -f2 | median)
    ratio=$(echo "$tc / $tb" | bc -l)
    cpu_ratio=$(echo "$cc / $cb" | bc -l)
    printf 'hfvis %-9s %-14s wall: base %.2f s, current %.2f s (%.3f x); cpu: base %.2f s, current %.2f s (%.3f x)\n' \
      "$op" "$name" "$tb" "$tc" "$ratio" "$cb" "$cc" "$cpu_ratio"
    printf '| hfvis %s | %s | %.2f | %.2f | %.3f | %.2f | %.2f | %.3f |\n' "$op" "$name" "$tb" "$tc" "$ratio" "$cb" "$cc" \
      "$cpu_ratio" >> "$table"
  done
done
rm -f "$out"/*.tif
echo "table: $table"
