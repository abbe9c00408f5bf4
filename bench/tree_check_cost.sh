#!/usr/bin/env bash
# bench/tree_check_cost.sh: what one convexity check of the hull tree costs, in this checkout's
# build and in a baseline build (issue 25's viewcount cost): `hfvis viewcount --stats` gives the
# checks per line sample (t_a, Timonen 2013's Table 2) and the line samples; the same command
# without statistics, timed in turn with the baseline's (base, current, current, base, ...), gives
# the CPU seconds; their quotient is the CPU time per check, everything else of the command
# included (the peaks' prepass, the counts, the start). If that time stays the same while the
# checks double, the cost is the number of checks, not what each costs.
#
#   bench/tree_check_cost.sh --base-build DIR [--sizes "256 512"] [--contents "fractal city"]
#                            [-k K] [--rounds R]
#     DIR: an existing build of the baseline (its hfvis, run as it is); defaults: sizes 256 512,
#     both contents, K = 64, R = 3. BUILD_DIR=... this checkout's build (default build/).
# Prints one line per (content, size, build) and writes the table to bench/out/tree_check_cost.md.
set -euo pipefail
source "$(dirname "$0")/cost_inputs.sh"

root=$(cd "$(dirname "$0")/.." && pwd)
base_build=
sizes="256 512"
contents="fractal city"
k=64
rounds=3
while [[ $# -gt 0 ]]; do
  case "$1" in
    --base-build) base_build=$2; shift ;;
    --sizes) sizes=$2; shift ;;
    --contents) contents=$2; shift ;;
    -k) k=$2; shift ;;
    --rounds) rounds=$2; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "tree_check_cost.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
[[ -n $base_build && -x $base_build/hfvis ]] || { echo "tree_check_cost.sh: --base-build DIR with an hfvis" >&2; exit 2; }
build_dir=${BUILD_DIR:-$root/build}
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
out=$root/bench/out/tree_check_cost
data=$root/bench/out/data
mkdir -p "$out" "$data"
bins=("$base_build/hfvis" "$build_dir/hfvis")
names=(base current)

# CPU seconds (user + system) of one command without statistics.
cpu() {
  /usr/bin/time -f '%U %S' -o "$out/time.txt" "$@" -q > /dev/null
  awk '{printf "%.3f\n", $1 + $2}' "$out/time.txt"
}

table=$root/bench/out/tree_check_cost.md
{
  echo "# The hull tree's cost per convexity check: $(git -C "$root" rev-parse --short HEAD) against $base_build"
  echo
  echo "K = $k, default options; CPU seconds the median of $rounds runs in turn. Written by bench/tree_check_cost.sh on"
  echo "$(uname -n), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'),"
  echo "$(date -u +%Y-%m-%dT%H:%M:%SZ), load average $(cut -d' ' -f1-3 /proc/loadavg)."
  echo
  echo "| input | build | t_a (checks per line sample) | line samples | checks (M) | CPU (s) | CPU per check (ns) |"
  echo "| --- | --- | --- | --- | --- | --- | --- |"
} > "$table"
for content in $contents; do
  for size in $sizes; do
    input=$(cost_input "$content" "$size" "$build_dir" "$data")
    name=$(basename "$input" .exr)
    declare -A t_a samples times
    for b in 0 1; do
      # "statistics per point and direction (...): m_a M, t_a T (...), ... (N line samples, ...)"
      stats=$("${bins[$b]}" viewcount "$input" -o "$out/stats.exr" -k "$k" --stats 2>&1 | grep 't_a')
      t_a[$b]=$(sed -E 's/.*t_a ([0-9.]+).*/\1/' <<< "$stats")
      samples[$b]=$(sed -E 's/.*\(([0-9]+) line samples.*/\1/' <<< "$stats")
      times[$b]=
    done
    for ((i = 0; i < rounds; ++i)); do
      for b in $( ((i % 2 == 0)) && echo 0 1 || echo 1 0); do
        times[$b]+="$(cpu "${bins[$b]}" viewcount "$input" -o "$out/out.tif" -k "$k") "
      done
    done
    for b in 0 1; do
      c=$(tr ' ' '\n' <<< "${times[$b]}" | grep . | median)
      checks=$(echo "${t_a[$b]} * ${samples[$b]}" | bc -l)
      ns=$(echo "$c * 1000000000 / $checks" | bc -l)
      printf '%-14s %-8s t_a %6.3f  samples %10d  checks %8.1f M  CPU %7.2f s  %5.1f ns a check\n' "$name" \
        "${names[$b]}" "${t_a[$b]}" "${samples[$b]}" "$(echo "$checks / 1000000" | bc -l)" "$c" "$ns"
      printf '| %s | %s | %.3f | %d | %.1f | %.2f | %.1f |\n' "$name" "${names[$b]}" "${t_a[$b]}" "${samples[$b]}" \
        "$(echo "$checks / 1000000" | bc -l)" "$c" "$ns" >> "$table"
    done
    unset t_a samples times
  done
done
rm -f "$out"/*.tif "$out"/*.exr
echo "table: $table"
