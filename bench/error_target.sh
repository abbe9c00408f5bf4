#!/usr/bin/env bash
# bench/error_target.sh: "ask for an error, not a direction count" (issue 31): for each content
# (data/'s fractal, bricks, sine and blocks, the city DSM hard case, the bundled DEM, and a field
# half city, half terrain), and each asked error E of the sky-view factor and of ambient
# occlusion, the K that --max-error chose, its error estimate, the error it achieved against the
# same sweep at a dense K, and its time against the cheapest fixed K (multiples of 8) meeting E on
# that field, timed interleaved (`hfvis_bench error-target`, library calls).
# Writes bench/report/error_target.md (or --out FILE), and redraws its plot beside it
# (error_target.png: bench/error_target_plot.py, every mode that writes the report).
#
#   bench/error_target.sh [--size 128] [--errors 0.001,...,0.05] [--reference-k 2048] [--reps 3] [--tile 64]
#                         [--contents fractal,...,mixed] [--out FILE]
#     (--reps 0: no timing, the load-free work ratio alone; --tile: the refined runs' tiles,
#     HorizonOptions::error_tile, beside the whole field at one K)
#   bench/error_target.sh --curve KMAX [--size 128] [--reference-k 2048] [--out FILE]
#     instead: per content, the error and the estimate at each fixed K up to KMAX (the estimate's
#     calibration against the dense reference), to bench/report/error_curve.md (or --out FILE).
#   bench/error_target.sh --viewcount [--size 64] [--errors ...] [--reference-k 1024] [--reps 0] [--out FILE]
#     instead: the same for intervisibility's visible count (its error relative to the dense run's
#     mean count), written as the section "Intervisibility" at the end of bench/report/error_target.md
#     (or --out FILE), replacing the one there.
#   bench/error_target.sh --horizon [--size 128] [--errors 0.1,...,2] [--reference-k 2048] [--reps 3]
#                         [--contents ...] [--out FILE]
#     instead: the same for the horizon angles (horizon --max-error, E in degrees: the mean error of
#     the K channels interpolated in azimuth against the sweep at K = 2048 and an azimuth tolerance
#     of 0.02 degrees), written as the section "Horizon angles" at the end of
#     bench/report/error_target.md (or --out FILE), replacing the one there; with --curve KMAX
#     instead the error and the estimate at each fixed K, to bench/report/error_curve_horizon.md.
#   BUILD_DIR=... selects the build (default build/).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
size=128
errors=0.001,0.002,0.005,0.01,0.02,0.05
reference=2048
reps=3
tile=64
contents=fractal,bricks,sine,blocks,city_dsm,dem,mixed
out=$root/bench/report/error_target.md
curve=0
viewcount=0
horizon=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --size) size=$2; shift ;;
    --errors) errors=$2; shift ;;
    --reference-k) reference=$2; shift ;;
    --reps) reps=$2; shift ;;
    --tile) tile=$2; shift ;;
    --contents) contents=$2; shift ;;
    --out) out=$2; shift ;;
    --curve) curve=$2; shift ;;
    --viewcount) viewcount=1 ;;
    --horizon) horizon=1 ;;
    -h|--help) sed -n '2,29p' "$0"; exit 0 ;;
    *) echo "error_target.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
build=${BUILD_DIR:-$root/build}
bench=$build/bench/hfvis_bench
[[ -x $bench ]] || { echo "error_target.sh: no hfvis_bench in $build (build it first)" >&2; exit 1; }
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
mkdir -p "$(dirname "$out")"
# The report's sections after the svf / ao tables, each written by its own mode: `replace_section
# MARKER SECTION` puts SECTION in place of the one from line MARKER to the next "## " line (or at
# the end), keeping the others; the default mode keeps them all after its own tables.
kept_sections=("## Intervisibility (viewcount --max-error)" "## Horizon angles (horizon --max-error)")
replace_section() {
  local marker=$1 section=$2
  [[ -f $out ]] || { echo "error_target.sh: $out does not exist (run without --horizon or --viewcount first)" >&2; exit 1; }
  awk -v m="$marker" -v s="$section" '
    $0 == m { skip = 1; done = 1; print s; print ""; next }
    skip && /^## / { skip = 0 }
    !skip { print }
    END { if (!done) { print ""; print s } }' "$out" | cat -s > "$out.tmp" && mv "$out.tmp" "$out"
}
# What follows the first of kept_sections in $out (nothing when there is none).
later_sections() {
  [[ -f $out ]] || return 0
  awk -v a="${kept_sections[0]}" -v b="${kept_sections[1]}" '$0 == a || $0 == b { on = 1 } on { print }' "$out"
}
commit=$(git -C "$root" rev-parse --short HEAD)  # before the run: the build it times
# The report's plot beside it (bench/error_target_plot.py), where Debian's python3 has matplotlib.
plot() {
  if /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
    /usr/bin/python3 "$root/bench/error_target_plot.py" "$out" -o "${out%.md}.png"
  else
    echo "error_target.sh: no matplotlib for /usr/bin/python3: the plot was not redrawn" >&2
  fi
}
if [[ $horizon -eq 1 && $curve -gt 0 ]]; then
  [[ $out == $root/bench/report/error_target.md ]] && out=$root/bench/report/error_curve_horizon.md
  table=$(cd "$root" && "$bench" error-target --output horizon --size "$size" --reference-k "$reference" \
    --curve "$curve" --contents "$contents")
  {
    echo "# The horizon angles' error estimate against their error, at fixed K"
    echo
    echo "Generated by \`bench/error_target.sh --horizon --curve $curve --size $size --reference-k $reference --contents $contents\`"
    echo "at $commit on $(date -u +%Y-%m-%d), on $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
    echo "($(nproc) cores, PoCL; times are single runs on a shared machine). Contents: the top-left ${size}x${size}"
    echo "of each 256^2 content. Degrees. achieved mean: the mean over the pixels and azimuth of |the K"
    echo "channels interpolated in azimuth - the sweep at K = $reference, 0.02 degree tolerance|; estimate:"
    echo "the run's own (HorizonResult::estimated_error); skip-one and skip-two: the means of each"
    echo "direction's error against the interpolation of its neighbours one and two places away in"
    echo "azimuth; order p: log2 of their ratio over the field (clamped 0.3 .. 2; the estimate takes it"
    echo "per pixel); samples: the run's work per receiver."
    echo "$table"
  } > "$out"
  echo "wrote $out"
  exit 0
fi
if [[ $curve -gt 0 ]]; then
  [[ $out == $root/bench/report/error_target.md ]] && out=$root/bench/report/error_curve.md
  table=$(cd "$root" && "$bench" error-target --size "$size" --reference-k "$reference" --curve "$curve" \
    --contents "$contents")
  {
    echo "# The error estimate against the error, at fixed K"
    echo
    echo "Generated by \`bench/error_target.sh --curve $curve --size $size --reference-k $reference\`"
    echo "at $commit on $(date -u +%Y-%m-%d), on $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
    echo "($(nproc) cores, PoCL; times are single runs on a shared machine). Contents: the top-left ${size}x${size}"
    echo "of each 256^2 content. achieved p99: the 99th percentile over the pixels of |result at K - the same"
    echo "sweep at K = $reference|; estimate: the error estimate's 99th percentile (half the even and odd"
    echo "directions' difference); samples: the work of the run per receiver (its directions' samples"
    echo "per period summed); \"p99 of r(K/2) - r(K)\": the 99th percentile of |result at K/2 - result at K|"
    echo "(-1: K/2 not in the ladder)."
    echo "$table"
  } > "$out"
  echo "wrote $out"
  exit 0
fi
if [[ $horizon -eq 1 ]]; then
  [[ $errors == 0.001,0.002,0.005,0.01,0.02,0.05 ]] && errors=0.1,0.2,0.5,1,2
  table=$(cd "$root" && "$bench" error-target --output horizon --size "$size" --errors "$errors" \
    --reference-k "$reference" --reps "$reps" --contents "$contents")
  marker="## Horizon angles (horizon --max-error)"
  section=$(
    echo "$marker"
    echo
    echo "Generated by \`bench/error_target.sh --horizon --size $size --errors $errors --reference-k $reference --reps $reps --contents $contents\`"
    echo "at $commit on $(date -u +%Y-%m-%d), on $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
    echo "($(nproc) cores, PoCL; load average $(cut -d' ' -f1-3 /proc/loadavg) at the start). Contents: the top-left ${size}x${size}"
    echo "of each 256^2 content. E in degrees. The error is the mean over the pixels and over azimuth"
    echo "of |the K channels interpolated linearly in azimuth between the directions' real azimuths - the"
    echo "same sweep at K = $reference with an azimuth tolerance of 0.02 degrees| (at the reference's"
    echo "azimuths, each weighted by its half gaps); the estimate the mean of the run's own. Cheapest fixed"
    echo "K: the least multiple of 8 meeting E (bisection), or, of the multiples of 8 up to twice it, one of"
    echo "less work that meets E too. Work: samples per receiver (the directions' samples per period"
    echo "summed), of all the runs --max-error made and of the last alone, over the cheapest fixed K's."
    [[ $reps -gt 0 ]] && echo "Times: median of $reps runs, the chosen run (all its runs) and the fixed K alternately." || echo "Not timed (--reps 0)."
    echo "$table"
  )
  replace_section "$marker" "$section"
  echo "wrote $out"
  plot
  exit 0
fi
if [[ $viewcount -eq 1 ]]; then
  table=$(cd "$root" && "$bench" error-target --output viewcount --size "$size" --errors "$errors" \
    --reference-k "$reference" --reps "$reps")
  marker="## Intervisibility (viewcount --max-error)"
  section=$(
    echo "$marker"
    echo
    echo "Generated by \`bench/error_target.sh --viewcount --size $size --errors $errors --reference-k $reference --reps $reps\`"
    echo "at $commit on $(date -u +%Y-%m-%d), on $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
    echo "($(nproc) cores, PoCL). Contents: the top-left ${size}x${size} of each 256^2 content. The error is the"
    echo "99th percentile over the pixels of |count / K - the hull tree's count / $reference at K = $reference|,"
    echo "relative to that reference's mean count over the field (as the estimate is). Work: the tree's"
    echo "samples per receiver (its directions' samples per period summed), of all the runs and of the"
    echo "last, over the cheapest fixed K's (which runs without the estimate's parity split)."
    [[ $reps -gt 0 ]] && echo "Times: median of $reps runs, interleaved." || echo "Not timed (--reps 0)."
    echo "$table"
  )
  replace_section "$marker" "$section"
  echo "wrote $out"
  plot
  exit 0
fi
later=$(later_sections)
tables=$(cd "$root" && "$bench" error-target --size "$size" --errors "$errors" --reference-k "$reference" \
  --reps "$reps" --tile "$tile" --contents "$contents")
{
  echo "# Asking for an error: --max-error against the cheapest fixed K"
  echo
  echo "Generated by \`bench/error_target.sh --size $size --errors $errors --reference-k $reference --reps $reps --tile $tile --contents $contents\`"
  echo "at $commit on $(date -u +%Y-%m-%d), on $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
  echo "($(nproc) cores, PoCL). Contents: the top-left ${size}x${size} of each 256^2 content (mixed: the city DSM's"
  echo "left half beside the fractal's right half times 40; city_plain: the city DSM with its right half,"
  echo "town: all but its top-left quarter, levelled at its lowest height). The error is the"
  echo "99th percentile over the pixels of |result - the same sweep at K = $reference| (the azimuthal"
  echo "integral the output approximates). Whole field: --max-error with one K for the whole field"
  echo "(error_tile 0); tiles of $tile: refined where the estimate asks for it (each tile of $tile x $tile"
  echo "pixels run again at its own K over the lines that reach it; K (runs): the least and most K a"
  echo "pixel took, and the number of runs). Work: samples per receiver (each direction's samples per"
  echo "period times the receivers on the lines it swept, over the field's; the sweep's cost is linear in"
  echo "them, free of the machine's load), of all the runs --max-error made (and, whole field, of its last"
  echo "run alone), over the cheapest fixed K's."
  if [[ $reps -gt 0 ]]; then
    echo "Times: median of $reps runs, the chosen run (all its runs) and the fixed K alternately, so the"
    echo "ratio holds on a loaded machine."
  else
    echo "Not timed (--reps 0): the work ratio stands for the time ratio."
  fi
  echo "The plot of every section's tables: [$(basename "${out%.md}").png]($(basename "${out%.md}").png)"
  echo "(bench/error_target_plot.py, redrawn by each run of this script)."
  echo "$tables"
  # (an if, not `[[ ]] &&`: the block's status is its last command's, and the move needs 0)
  if [[ -n $later ]]; then printf '\n%s\n' "$later"; fi
} > "$out.tmp" && mv "$out.tmp" "$out"
echo "wrote $out"
plot
