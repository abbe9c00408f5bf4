#!/usr/bin/env bash
# scripts/compare_outputs.sh: behaviour unchanged? Runs 24 cases of horizon, svf, ao, viewcount,
# horizons, bounce, shade, insolation, viewshed and sunpos (every output kind, EXR and GeoTIFF in
# and out, the options that take other code paths; not arealight, region, pvs or devices) on the
# bundled data with a base commit's build and this checkout's, and compares the outputs bit for bit
# or pixel for pixel (idiff: metadata aside). A change that alters one explains it in its commit.
#
#   scripts/compare_outputs.sh [--base COMMIT] [--keep]
#     --base: default HEAD (then it checks the working tree's uncommitted changes)
#     --keep: keep both sets of outputs in build/compare_outputs/{base,current}
#   BUILD_DIR=... this checkout's build (default build/, built here); the base is built in
#   bench/out/base-COMMIT/build (a git worktree, git-ignored), as bench/cost_against.sh does.
# Exit status: 0 every output identical (bytes or pixels), 1 some differ, 2 a command failed in
# one build and not the other (its message is printed).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
base=HEAD
keep=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --base) base=$2; shift ;;
    --keep) keep=1 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "compare_outputs.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
command -v idiff > /dev/null || { echo "compare_outputs.sh: needs idiff (openimageio-tools)" >&2; exit 2; }
build_dir=${BUILD_DIR:-$root/build}
base_sha=$(git -C "$root" rev-parse --short "$base")
base_dir=$root/bench/out/base-$base_sha
[[ -d $base_dir ]] || git -C "$root" worktree add --detach "$base_dir" "$base_sha" > /dev/null
echo "== building $base_sha in $base_dir/build and this checkout in $build_dir"
for b in "$base_dir/build" "$build_dir"; do
  src=$root
  [[ $b == "$base_dir/build" ]] && src=$base_dir
  cmake -S "$src" -B "$b" -DCMAKE_BUILD_TYPE=Release > /dev/null
  cmake --build "$b" -j "$(nproc)" --target hfvis_cli > /dev/null
done
out=$root/build/compare_outputs
rm -rf "$out"
mkdir -p "$out/base" "$out/current" "$out/in"
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}

data=$root/data
dem=$data/jacksboro_fault_dem.exr
fractal=$data/fractal_256.exr
bathy=$data/topobathy.exr
env=$data/clear_sky.exr
# A GeoTIFF input with nodata (the DEM's heights below 300 m), written by the base build once.
"$base_dir/build/hfvis" svf "$dem" -o "$out/in/dem.tif" -k 4 -q
# An exit radiance for bounce (the DEM's sky-view factor: finite, >= 0).
"$base_dir/build/hfvis" svf "$dem" -o "$out/in/radiance.exr" -k 4 -q
printf 'col,row\n10,10\n200,150\n350,300\n' > "$out/in/observers.csv"

# name|arguments (IN and OUT are replaced; OUT's extension decides the format)
cases=(
  "horizon_exr|horizon $dem -o OUT.exr -k 16 --distance-out OUT_distance.exr --preview OUT.png"
  "horizon_tif|horizon $dem -o OUT.tif -k 8"
  "horizon_naive|horizon $fractal -o OUT.exr -k 8 --method naive"
  "horizon_maxdist_curv|horizon $dem -o OUT.exr -k 8 --max-distance 5000 --curvature"
  "svf_exr|svf $dem -o OUT.exr -k 32 --preview OUT.png"
  "svf_tif|svf $fractal -o OUT.tif -k 16 --nodata nan"
  "svf_bathy|svf $bathy -o OUT.exr -k 16"
  "svf_spu|svf $fractal -o OUT.exr -k 16 --method naive --samples-per-unit 2"
  "ao_exr|ao $dem -o OUT.exr -k 16 --preview OUT.png"
  "viewcount_tree|viewcount $fractal -o OUT.exr -k 8 --stats"
  "viewcount_naive|viewcount $fractal -o OUT.exr -k 4 --method naive"
  "viewcount_tif|viewcount $dem -o OUT.tif -k 8 --max-distance 8000"
  "horizons_json|horizons $dem --at 10,10 --at 200,150 -o OUT.json -k 16"
  "horizons_csv|horizons $fractal --at 128,128 -o OUT.csv -k 8"
  "bounce|bounce $dem --radiance $out/in/radiance.exr -o OUT.exr -k 8"
  "shade_env|shade $dem -o OUT.exr --env $env -k 16 --preview OUT.png"
  "shade_sun|shade $dem -o OUT.exr --sun 135,20 --preview OUT.png"
  "shade_time|shade $dem -o OUT.tif --at 2024-06-21T15:00:00Z --lat 33.2 --lon -98.2 --albedo 0.3"
  "insolation|insolation $dem -o OUT.exr --lat 33.2 --lon -98.2 --from 2024-06-21T00:00:00Z --to 2024-06-22T00:00:00Z --step 60"
  "viewshed_one|viewshed $dem -o OUT.exr --observer 200,150 --observer-height 2"
  "viewshed_many|viewshed $dem -o OUT.tif --observers $out/in/observers.csv --target-height 1"
  "viewshed_geotiff_in|viewshed $out/in/dem.tif -o OUT.tif --observer 100,100"
  "svf_geotiff_in|svf $out/in/dem.tif -o OUT.tif -k 16"
  "sunpos|sunpos --lat 33.2 --lon -98.2 --at 2024-06-21T15:00:00Z"
)

status=0
identical=0
same_pixels=0
for entry in "${cases[@]}"; do
  name=${entry%%|*}
  args=${entry#*|}
  for side in base current; do
    program=$build_dir/hfvis
    [[ $side == base ]] && program=$base_dir/build/hfvis
    dir=$out/$side
    # shellcheck disable=SC2086  # the arguments are words
    set +e
    quiet=-q
    [[ $name == sunpos ]] && quiet=
    $program ${args//OUT/$dir/$name} $quiet > "$dir/$name.stdout" 2> "$dir/$name.stderr"
    echo $? > "$dir/$name.rc"
    set -e
  done
  if [[ $(cat "$out/base/$name.rc") != 0 ]]; then
    echo "BROKEN CASE $name: the base build fails it too (fix the case): $(head -1 "$out/base/$name.stderr")"
    status=2
    continue
  fi
  if ! cmp -s "$out/base/$name.rc" "$out/current/$name.rc"; then
    echo "FAILED $name: exit $(cat "$out/base/$name.rc") (base) vs $(cat "$out/current/$name.rc") (current)"
    tail -3 "$out/base/$name.stderr" "$out/current/$name.stderr"
    status=2
    continue
  fi
  for file in "$out/base/$name"*; do
    f=$(basename "$file")
    [[ $f == *.rc || $f == *.stderr ]] && continue
    other=$out/current/$f
    if cmp -s "$file" "$other"; then
      identical=$((identical + 1))
    elif [[ $f == *.exr || $f == *.tif || $f == *.png ]] && idiff -q -fail 0 -warn 0 "$file" "$other" > /dev/null 2>&1; then
      identical=$((identical + 1))  # the same pixels; the files differ in metadata (an EXR's DateTime)
      same_pixels=$((same_pixels + 1))
    else
      echo "DIFFERS $f"
      [[ $f == *.exr || $f == *.tif || $f == *.png ]] && idiff -fail 0 -warn 0 "$file" "$other" 2>&1 | grep -E "Mean error|Max error" | sed 's/^/    /'
      [[ $f == *.stdout || $f == *.json || $f == *.csv ]] && diff "$file" "$other" | head -6 | sed 's/^/    /'
      [[ $status == 0 ]] && status=1
    fi
  done
done
echo "$identical outputs identical ($same_pixels of them in their pixels, not their bytes) across ${#cases[@]} runs ($base_sha against $(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet HEAD -- src include cli kernels || echo ' with uncommitted changes'))"
[[ $keep == 1 ]] || rm -rf "$out"
exit $status
