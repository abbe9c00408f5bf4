#!/usr/bin/env bash
# bench/time_cli.sh: issue 2's timing: the built CLI's `hfvis horizon` on an N x N fractal
# terrain (data/make_data.py, default N = 1024) with K directions (default 64), --method
# sweep against --method naive on the same device. Each is the wall clock of the whole
# command (read the field, compute, write the K-channel EXR), after one warm-up run per
# method on a 64 x 64 field (PoCL compiles and caches the kernels there). When the CLI does
# not build, it says so and times the same library call through `hfvis_bench run` instead
# (K angle planes downloaded; no file written).
#
#   bench/time_cli.sh [--size N] [-k K] [--reps R]     (R runs per method, default 1)
#   BUILD_DIR=... selects the build (default build/); outputs go to bench/out/time_cli/.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
size=1024
k=64
reps=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --size) size=$2; shift ;;
    -k) k=$2; shift ;;
    --reps) reps=$2; shift ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) echo "time_cli.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
build_dir=${BUILD_DIR:-$root/build}
# PoCL's kernel cache of the benchmark's own (see bench/README.md, PoCL notes).
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
cli=$build_dir/hfvis
bench=$build_dir/bench/hfvis_bench
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release > /dev/null
use_cli=1
if ! cmake --build "$build_dir" -j "$(nproc)" --target hfvis_cli > "$root/bench/out/time_cli_build.log" 2>&1; then
  use_cli=0
  echo "the CLI does not build (see bench/out/time_cli_build.log); timing the same library call" \
    "(computeHorizons, K angle planes to the host, no EXR written) through hfvis_bench run instead"
  cmake --build "$build_dir" -j "$(nproc)" --target hfvis_bench > /dev/null
fi
out=$root/bench/out/time_cli
data=$root/bench/out/data
mkdir -p "$out" "$data"
for n in 64 "$size"; do
  [[ -f "$data/fractal_$n.exr" ]] || /usr/bin/python3 "$root/data/make_data.py" --size "$n" --out "$data" \
    --no-dem --fields fractal > /dev/null
done

echo "device: $("$bench" run "$data/fractal_64.exr" -k 1 --reps 1 | sed -n 's/.* on \(.*\) (\([0-9]*\) compute units)$/\1, \2 compute units/p')"
echo "commit: $(git -C "$root" rev-parse --short HEAD 2> /dev/null || echo unknown), $(date -u +%Y-%m-%dT%H:%M:%SZ)," \
  "load average $(cut -d' ' -f1-3 /proc/loadavg)"
# Start-up alone (the dynamic loader, no OpenCL): the min of 5 runs of `hfvis --help`.
if [[ $use_cli == 1 ]]; then
  startup=9999
  for ((i = 0; i < 5; ++i)); do
    start=$(date +%s.%N)
    "$cli" --help > /dev/null
    end=$(date +%s.%N)
    startup=$(echo "t = $end - $start; if (t < $startup) t else $startup" | bc -l)
  done
  printf 'start-up: hfvis --help takes %.3f s (min of 5 runs)\n' "$startup"
fi
declare -A best
for method in sweep naive; do
  if [[ $use_cli == 1 ]]; then
    "$cli" horizon "$data/fractal_64.exr" -o "$out/warmup.exr" -k "$k" --method "$method" -q
  else
    "$bench" run "$data/fractal_64.exr" --method "$method" -k "$k" --reps 1 > /dev/null
  fi
  times=()
  for ((i = 0; i < reps; ++i)); do
    start=$(date +%s.%N)
    if [[ $use_cli == 1 ]]; then
      "$cli" horizon "$data/fractal_$size.exr" -o "$out/horizon_$method.exr" -k "$k" --method "$method" -q
    else
      "$bench" run "$data/fractal_$size.exr" --method "$method" -k "$k" --reps 1 > /dev/null
    fi
    end=$(date +%s.%N)
    times+=("$(echo "$end - $start" | bc -l)")
  done
  sorted=$(printf '%s\n' "${times[@]}" | sort -g)
  best[$method]=$(echo "$sorted" | head -1)
  median=$(echo "$sorted" | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}')
  what="hfvis horizon"
  [[ $use_cli == 1 ]] || what="hfvis_bench run (library call)"
  printf '%s %dx%d -k %d --method %-5s: min %.2f s, median %.2f s over %d run(s)\n' "$what" "$size" "$size" "$k" \
    "$method" "${best[$method]}" "$median" "$reps"
  rm -f "$out/horizon_$method.exr"
done
rm -f "$out/warmup.exr"
printf 'naive / sweep = %.1f (whole commands, min over runs)\n' "$(echo "${best[naive]} / ${best[sweep]}" | bc -l)"
