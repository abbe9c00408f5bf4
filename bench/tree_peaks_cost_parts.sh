#!/usr/bin/env bash
# bench/tree_peaks_cost_parts.sh: where the hull tree's peaks between samples spend their time.
# Runs `hfvis viewcount` (default options) with seven programs in turn on each input, R rounds:
#   base        a build of bad9286 (before the peaks), as given by --base-build
#   host        this build with both kernels returning at once (reading, planning, writing)
#   prepass     the sweep's kernel without receivers (the host and the peaks' prepass alone)
#   structure   this build with the peaks' code in place but no interval evaluated (two tree
#               slots per step, the peak branches; no piece read, no peak inserted)
#   pieces      every interval's pieces evaluated and the peak's test made, none inserted
#   no-count    the peaks inserted, but no receiver reads its visible runs (step 3 of the sweep)
#   current     this build as it is (the peaks evaluated and inserted)
# So the prepass costs prepass - host, the counting current - no-count, and the tree's walk the
# rest of current. Since the peaks' prepass (3ae7129) structure and pieces edit the prepass's
# peak function (and the sweep's, for strips and latitude / longitude grids), so they include
# the prepass's own pass (the samples' heights and an 8-byte write a slot), which the 1311f46
# table in bench/report/tree_peaks.md did not have.
# All but base and current are the kernel of this checkout edited into bench/out/ (loaded
# through HFVIS_KERNEL_DIR; their results differ from the current one's by design, and the script
# stops if the lines it edits have changed). Prints the median CPU (user + system) seconds of
# each and its ratio to the base, and writes the table to bench/out/tree_peaks_cost_parts.md.
#
#   bench/tree_peaks_cost_parts.sh --base-build DIR [--size N] [-k K] [--rounds R] [--contents "fractal city"]
#     defaults: N = 512, K = 64, R = 3
# Inputs as bench/cost_against.sh makes them (bench/out/data/{fractal,city}_N.exr).
set -euo pipefail
source "$(dirname "$0")/cost_inputs.sh"

root=$(cd "$(dirname "$0")/.." && pwd)
size=512
k=64
rounds=3
contents="fractal city"
base_build=
while [[ $# -gt 0 ]]; do
  case "$1" in
    --base-build) base_build=$2; shift ;;
    --size) size=$2; shift ;;
    -k) k=$2; shift ;;
    --rounds) rounds=$2; shift ;;
    --contents) contents=$2; shift ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) echo "tree_peaks_cost_parts.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
[[ -x $base_build/hfvis ]] || { echo "tree_peaks_cost_parts.sh: --base-build DIR must hold a build of bad9286 (DIR/hfvis)" >&2; exit 2; }
build_dir=${BUILD_DIR:-$root/build}
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
out=$root/bench/out/tree_peaks_cost_parts
data=$root/bench/out/data
mkdir -p "$out" "$data"

# The variants' kernels: the peak's branch never taken (structure), or its result never inserted (pieces).
edit() {  # VARIANT FROM TO [FROM TO ...]
  local name=$1
  shift
  rm -rf "$out/$name"
  cp -r "$root/kernels" "$out/$name"
  /usr/bin/python3 - "$out/$name/intervisibility.cl" "$@" <<'EOF'
import sys
path, edits = sys.argv[1], sys.argv[2:]
text = open(path).read()
for old, new in zip(edits[::2], edits[1::2]):
    if text.count(old) != 1:
        sys.exit("tree_peaks_cost_parts.sh: kernels/intervisibility.cl no longer has the line: " + old)
    text = text.replace(old, new)
open(path, "w").write(text)
EOF
}
# Each edit in both peak functions: tree_interval_peak_lanes (the prepass intervisibility_peaks on
# these inputs) and tree_interval_peak (the sweep, in strips and on latitude / longitude grids).
edit structure "if (!(step > 0 && step_scale > 1)) return (lane_float)(NAN);" \
  "if (1) return (lane_float)(NAN);" \
  "if (!(step > 0 && step_scale > 1 && !isnan(h_sample_prev) && !isnan(h_sample))) return NAN;" \
  "if (1) return NAN;"
# (the test's result kept alive, so that the compiler cannot drop the evaluation: no peak is
# that high)
edit pieces "return select((lane_float)(NAN), best_h, live);" \
  "return select((lane_float)(NAN), best_h, live & (best_h > 1e30f));" \
  "return tree_peak_inserted(h_sample_prev, best_h, h_sample, offset, step_scale) ? best_h : NAN;" \
  "return tree_peak_inserted(h_sample_prev, best_h, h_sample, offset, step_scale) && best_h > 1e30f ? best_h : NAN;"

edit prepass "  const int i_begin = 0, i_end = line.z;" "  const int i_begin = 0, i_end = 0;"
edit host "  const int i_begin = 0, i_end = line.z;" "  const int i_begin = 0, i_end = 0;" \
  "  if (j0 >= n_lines) return;" "  if (j0 >= n_lines || 1) return;"
edit no-count "        if (receiver || HFVIS_ALL_HORIZONS) {" "        if (0) {"

cmake --build "$build_dir" -j "$(nproc)" --target hfvis_cli hfvis_bench > /dev/null
inputs=()
for content in $contents; do inputs+=("$(cost_input "$content" "$size" "$build_dir" "$data")"); done

header="commit $(git -C "$root" rev-parse --short HEAD), $(date -u +%Y-%m-%dT%H:%M:%SZ), $(nproc) cores,\
 $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), load average $(cut -d' ' -f1-3 /proc/loadavg);\
 ${size}x${size}, K = $k, median CPU seconds of $rounds rounds"
echo "$header"
variants=(base host prepass structure pieces no-count current)
cpu() {  # VARIANT INPUT: CPU seconds of one run
  local v=$1 input=$2 bin=$build_dir/hfvis env=()
  [[ $v == base ]] && bin=$base_build/hfvis
  [[ $v != base && $v != current ]] && env=(HFVIS_KERNEL_DIR="$out/$v")
  env "${env[@]}" /usr/bin/time -f '%U %S' -o "$out/time.txt" "$bin" viewcount "$input" -o "$out/out.exr" -k "$k" -q
  awk '{printf "%.3f\n", $1 + $2}' "$out/time.txt"
}

table=$out/../tree_peaks_cost_parts.md
{
  echo "$header"
  echo
  echo "| input | base CPU (s) | host | prepass | structure | pieces | no-count | current |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
} > "$table"
for input in "${inputs[@]}"; do
  for v in "${variants[@]}"; do cpu "$v" "$input" > /dev/null; done  # warm-up: PoCL compiles and caches
  declare -A times=()
  for ((i = 0; i < rounds; ++i)); do
    # Each round in another order, so that a drift of the machine's speed falls on all alike.
    for ((j = 0; j < ${#variants[@]}; ++j)); do
      v=${variants[$(((i + j) % ${#variants[@]}))]}
      times[$v]+="$(cpu "$v" "$input") "
    done
  done
  declare -A med=()
  for v in "${variants[@]}"; do med[$v]=$(tr ' ' '\n' <<< "${times[$v]}" | sed '/^$/d' | median); done
  row="| $(basename "$input" .exr) | ${med[base]}"
  for v in "${variants[@]:1}"; do
    row+=" | ${med[$v]} ($(printf '%.2f' "$(echo "${med[$v]} / ${med[base]}" | bc -l)") x)"
  done
  echo "$row |" | tee -a "$table"
  unset times med
done
echo "table: $table"
