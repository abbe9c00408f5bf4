#!/usr/bin/env bash
# bench/large_fields.sh: the whole `hfvis` command on large fields with default settings (the
# memory budget, batching and chunking as a user gets them): wall time and peak resident host
# memory (/usr/bin/time -v) of `hfvis svf` and `hfvis ao` at K directions on data/make_data.py's
# sine field at each size N, svf also within a maximum distance (--max-distance D ground
# units; cell size 1) and under a memory budget of 2 N^2 bytes (a device half the size of the
# field's heights: the field runs in strips; svf with and without the maximum distance, whose
# strips get room for their taller halo besides), at least N / 128 MiB (room for the hull stacks
# carried from strip to strip: on this smooth field about 200 entries of 8 bytes per line at
# N = 4096 and 850 at 16384). Device memory where the device reports it: on an NVIDIA GPU
# (nvidia-smi on the PATH) the peak of memory.used sampled every 0.2 s during the job, less
# its value before; PoCL on a CPU reports none (its buffers are host memory, in the peak
# resident memory). Prints a Markdown table; inputs go to bench/out/data/ (the 16384^2 EXR is
# 139 MB), outputs to bench/out/large/.
#
#   bench/large_fields.sh [--sizes 1024,4096,16384] [-k K] [--max-distance D] [--field NAME]
#   BUILD_DIR=... selects the build (default build/).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sizes=1024,4096,16384
k=16
max_distance=256
field=sine
while [[ $# -gt 0 ]]; do
  case "$1" in
    --sizes) sizes=$2; shift ;;
    -k) k=$2; shift ;;
    --max-distance) max_distance=$2; shift ;;
    --field) field=$2; shift ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "large_fields.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
[[ $sizes =~ ^[0-9]+(,[0-9]+)*$ ]] || { echo "large_fields.sh: --sizes takes N[,N...]" >&2; exit 2; }
cli=${BUILD_DIR:-$root/build}/hfvis
[[ -x $cli ]] || { echo "large_fields.sh: no hfvis at $cli (build it first)" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "large_fields.sh: needs /usr/bin/time (Debian package time)" >&2; exit 1; }
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
data=$root/bench/out/data
out=$root/bench/out/large
mkdir -p "$data" "$out"

# Device memory in use (MiB) appended to $1, where the device reports it (nvidia-smi: the
# first GPU); nothing otherwise. With --every, every 0.2 s until killed.
sample_device_memory() {
  command -v nvidia-smi > /dev/null || return 0
  while :; do
    nvidia-smi --query-gpu=memory.used --format=csv,noheader,nounits 2> /dev/null | head -1 >> "$1"
    [[ ${2:-} == --every ]] || return 0
    sleep 0.2
  done
}

commit=$(git -C "$root" rev-parse --short HEAD 2> /dev/null || echo unknown)
git -C "$root" diff --quiet HEAD 2> /dev/null || commit="$commit (with uncommitted changes)"
echo "\`hfvis\` with default settings, K = $k, data/make_data.py's $field field; commit" \
  "$commit, $("$cli" devices | sed -n 's/^\* [0-9]* *CPU *//p;s/^\* [0-9]* *GPU *//p' | head -1 | sed 's/  .*//'), $(nproc) cores, $(awk '/MemTotal/ {printf "%.1f GiB", $2 / 1048576}' /proc/meminfo) of host memory."
echo
echo "| N | command | wall (s) | peak resident memory (GiB) | peak device memory (GiB) |"
echo "| ---: | --- | ---: | ---: | ---: |"
# Every program variant once on a small field first, so that no timed run compiles kernels.
warm=$data/${field}_64.exr
[[ -f $warm ]] || /usr/bin/python3 "$root/data/make_data.py" --size 64 --out "$data" --no-dem --fields "$field" > /dev/null
# (The strips' programs too: budgets below the 64 x 64 field's needs, a short window for its halo.)
for job in "svf" "svf --max-distance $max_distance" "ao" "svf --memory-budget 0.03" \
  "svf --max-distance 4 --memory-budget 0.06"; do
  read -r -a words <<< "$job"
  "$cli" "${words[@]}" "$warm" -o "$out/warm.exr" -k "$k" -q
done
IFS=, read -r -a size_list <<< "$sizes"
for n in "${size_list[@]}"; do
  exr=$data/${field}_$n.exr
  [[ -f $exr ]] || /usr/bin/python3 "$root/data/make_data.py" --size "$n" --out "$data" --no-dem --fields "$field" > /dev/null
  budget=$(awk -v n="$n" 'BEGIN { b = n * n / 524288; printf "%g", b < n / 128 ? n / 128 : b }')  # MiB
  # Within the maximum distance a strip's heights take up to 2 D + a period more rows on each
  # side (at most 4 D + 8 rows for K = 16): the budget adds room for them in its half for strips.
  window_budget=$(awk -v n="$n" -v b="$budget" -v d="$max_distance" 'BEGIN { printf "%g", b + 2 * (4 * d + 8) * n * 4 / 1048576 }')
  jobs=("svf" "svf --max-distance $max_distance" "ao" "svf --memory-budget $budget")
  # (Below N = 4096 that budget holds the whole field: no strips to measure.)
  ((n >= 4096)) && jobs+=("svf --max-distance $max_distance --memory-budget $window_budget")
  for job in "${jobs[@]}"; do
    read -r -a words <<< "$job"
    log=$out/time_${n}_${words[0]}.log
    samples=$out/device_${n}_${words[0]}.log
    : > "$samples"
    sample_device_memory "$samples"  # before the job
    sample_device_memory "$samples" --every &
    sampler=$!
    /usr/bin/time -v "$cli" "${words[@]}" "$exr" -o "$out/${words[0]}_$n.exr" -k "$k" -q 2> "$log" \
      || { kill "$sampler" 2> /dev/null; echo "large_fields.sh: hfvis $job failed on $exr:" >&2; cat "$log" >&2; exit 1; }
    kill "$sampler" 2> /dev/null || true  # (it has ended where nothing reports)
    wait "$sampler" 2> /dev/null || true
    wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, t, ":"); s = 0; for (i = 1; i <= n; ++i) s = s * 60 + t[i]; print s}' "$log")
    rss=$(awk -F': ' '/Maximum resident set size/ {printf "%.2f", $2 / 1048576}' "$log")
    # The first sample is the device's use before the job (MiB); none: not reported.
    device=$(awk 'NR == 1 { base = $1 } { if ($1 > peak) peak = $1 } END { if (NR) printf "%.2f", (peak - base) / 1024; else print "not reported" }' "$samples")
    echo "| $n | \`hfvis $job -k $k\` | $wall | $rss | $device |"
  done
done
