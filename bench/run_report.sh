#!/usr/bin/env bash
# bench/run_report.sh: the one command behind the benchmark report. Builds hfvis_bench
# (Release) if needed, generates the input fields into bench/out/ (git-ignored), runs the
# two suites and writes the report: results.csv and environment.txt (horizons),
# visibility.csv and visibility_environment.txt (intervisibility), REPORT.md and the PNG
# plots.
#
#   bench/run_report.sh            both suites, full size (about 40 minutes on the 2-core test
#                                  machine) -> bench/report/
#   bench/run_report.sh --quick    smaller sizes (under 3 minutes) -> bench/out/report-quick/
#   options: --out DIR (report directory), BUILD_DIR=... (default build/),
#            --only horizon|visibility  run one suite; REPORT.md keeps the other suite's
#                                       results already in the report directory
#            HEMAN_DIR=...  a heman built by hand (see bench/README.md): also runs
#                           bench/heman_compare.sh (quick: 1024 only, 3 rounds) into
#                           bench/out/heman-<mode>/ and copies its tables to REPORT_DIR
#                           (heman.md, heman_timings.csv) for the `hfvis ao` vs heman target
#
# Needs the build dependencies (scripts/install-deps.sh) and Debian's python3 with numpy and
# matplotlib (python3-numpy, python3-matplotlib); nothing from pip.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
mode=full
report_dir=""
only=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --quick) mode=quick ;;
    --out) report_dir=$2; shift ;;
    --only)
      only=$2; shift
      [[ $only == horizon || $only == visibility ]] || { echo "run_report.sh: --only horizon or visibility" >&2; exit 2; } ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "run_report.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
if [[ -z "$report_dir" ]]; then
  if [[ $mode == full ]]; then report_dir=$root/bench/report; else report_dir=$root/bench/out/report-quick; fi
fi
build_dir=${BUILD_DIR:-$root/build}
python=/usr/bin/python3  # Debian's, for its matplotlib and numpy
# PoCL's compiled-kernel cache of its own: other processes compiling the same kernels into the
# shared cache at the same moment have made PoCL abort ("Final linking of kernel ... failed").
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
start=$(date +%s)

echo "== building hfvis_bench in $build_dir"
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release > /dev/null
targets=(hfvis_bench)
[[ -n ${HEMAN_DIR:-} && $only != visibility ]] && targets+=(hfvis_cli)
cmake --build "$build_dir" -j "$(nproc)" --target "${targets[@]}"
bench=$build_dir/bench/hfvis_bench

echo "== generating inputs into bench/out/data"
data_dir=$root/bench/out/data
mkdir -p "$data_dir"
flag=""
[[ $mode == quick ]] && flag=--quick
# data/make_data.py is deterministic, so fields already there are reused.
"$bench" inputs $flag | while read -r content size; do
  if [[ ! -f "$data_dir/${content}_${size}.exr" ]]; then
    "$python" "$root/data/make_data.py" --size "$size" --out "$data_dir" --no-dem --fields "$content"
  fi
done

commit=$(git -C "$root" rev-parse --short HEAD 2> /dev/null || echo unknown)
if ! git -C "$root" diff --quiet HEAD 2> /dev/null; then commit="$commit (with uncommitted changes)"; fi

mkdir -p "$report_dir"
if [[ $only != visibility ]]; then
  echo "== running the $mode horizon suite (log: bench/out/suite-$mode.log)"
  "$bench" suite $flag --data "$data_dir" --dem "$root/data/jacksboro_fault_dem.exr" --out "$report_dir" \
    --cache "$root/bench/out/truth" --commit "$commit" | tee "$root/bench/out/suite-$mode.log"
fi
if [[ -n ${HEMAN_DIR:-} && $only != visibility ]]; then
  echo "== timing hfvis ao against heman (log: bench/out/heman-$mode.log)"
  heman_sizes=()
  [[ $mode == quick ]] && heman_sizes=(--sizes 1024 --rounds 3)
  # Its outputs (EXRs of both programs) stay in bench/out/; the report directory gets the tables.
  "$root/bench/heman_compare.sh" --heman-dir "$HEMAN_DIR" --hfvis "$build_dir/hfvis" --bench "$bench" \
    --out "$root/bench/out/heman-$mode" "${heman_sizes[@]}" | tee "$root/bench/out/heman-$mode.log"
  cp "$root/bench/out/heman-$mode/results.md" "$report_dir/heman.md"
  cp "$root/bench/out/heman-$mode/timings.csv" "$report_dir/heman_timings.csv"
fi
if [[ $only != horizon ]]; then
  echo "== running the $mode intervisibility suite (log: bench/out/visibility-$mode.log)"
  "$bench" visibility $flag --data "$data_dir" --dem "$root/data/jacksboro_fault_dem.exr" --out "$report_dir" \
    --commit "$commit" | tee "$root/bench/out/visibility-$mode.log"
fi

echo "== writing the report"
# The whole command's time, recorded beside each suite it ran (REPORT.md reads it from there).
elapsed=$(( $(date +%s) - start ))
[[ $only != visibility ]] && echo "command_seconds = $elapsed" >> "$report_dir/environment.txt"
[[ $only != horizon ]] && echo "command_seconds = $elapsed" >> "$report_dir/visibility_environment.txt"
"$python" "$root/bench/make_report.py" "$report_dir"
echo "report: $report_dir/REPORT.md ($(( $(date +%s) - start )) s in all)"
