#!/usr/bin/env bash
# bench/max_distance.sh: what a maximum distance costs. One `computeHorizons` call per run
# (`hfvis_bench run`, sky-view factor only, on a context that has built its program), on a
# data/make_data.py field: the sweep without a limit, then for each distance D (pixels of a
# unit cell) the windowed sweep and the naive march limited to D, runs interleaved (every
# configuration once per round). Prints a Markdown table of the minimum times and ratios.
#
#   bench/max_distance.sh [--size N] [-k K] [--distances 8,16,64,256] [--rounds R] [--field NAME]
#   BUILD_DIR=... selects the build (default build/); inputs go to bench/out/data/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
size=1024
k=16
distances=8,16,64,256
rounds=3
field=fractal
while [[ $# -gt 0 ]]; do
  case "$1" in
    --size) size=$2; shift ;;
    -k) k=$2; shift ;;
    --distances) distances=$2; shift ;;
    --rounds) rounds=$2; shift ;;
    --field) field=$2; shift ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "max_distance.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
[[ $distances =~ ^[0-9.]+(,[0-9.]+)*$ ]] || { echo "max_distance.sh: --distances takes D[,D...]" >&2; exit 2; }
bench=${BUILD_DIR:-$root/build}/bench/hfvis_bench
[[ -x $bench ]] || { echo "max_distance.sh: no hfvis_bench at $bench (build it first)" >&2; exit 1; }
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
data=$root/bench/out/data
mkdir -p "$data"
exr=$data/${field}_$size.exr
[[ -f $exr ]] || /usr/bin/python3 "$root/data/make_data.py" --size "$size" --out "$data" --no-dem --fields "$field" > /dev/null

commit=$(git -C "$root" rev-parse --short HEAD 2> /dev/null || echo unknown)
git -C "$root" diff --quiet HEAD 2> /dev/null || commit="$commit (with uncommitted changes)"
/usr/bin/python3 - "$bench" "$exr" "$k" "$distances" "$rounds" "$commit" << 'PY'
import re, subprocess, sys
bench, exr, k, distances, rounds, commit = sys.argv[1:]
distances = [float(d) for d in distances.split(",")]
configs = [("sweep", 0.0)] + [(m, d) for d in distances for m in ("sweep", "naive")]
best, device = {}, ""
for method, d in configs[:3]:  # compile every program variant before timing
    subprocess.run([bench, "run", exr, "--method", method, "-k", "1", "--outputs", "svf", "--reps", "1"] +
                   (["--max-distance", repr(d)] if d > 0 else []), check=True, capture_output=True)
for r in range(int(rounds)):
    for method, d in configs:
        cmd = [bench, "run", exr, "--method", method, "-k", k, "--outputs", "svf", "--reps", "1"]
        if d > 0:
            cmd += ["--max-distance", repr(d)]
        text = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
        m = re.search(r"min ([0-9.]+) s, .* on (.*) \(", text)
        best[(method, d)] = min(best.get((method, d), float("inf")), float(m.group(1)))
        device = m.group(2)
        print("  round %d %s D=%g: %.3f s" % (r + 1, method, d, float(m.group(1))), file=sys.stderr, flush=True)
unlimited = best[("sweep", 0.0)]
print("Sky-view factor, %s, K = %s, one library call per run (program built), minimum of %s interleaved "
      "rounds; commit %s, %s. Unlimited sweep: %.3f s." % (exr.split("/")[-1], k, rounds, commit, device, unlimited))
print()
print("| D (pixels) | windowed sweep (s) | sweep / unlimited sweep | naive march within D (s) | naive / sweep |")
print("| ---: | ---: | ---: | ---: | ---: |")
for d in distances:
    s, n = best[("sweep", d)], best[("naive", d)]
    print("| %g | %.3f | %.2f | %.3f | %.2f |" % (d, s, s / unlimited, n, n / s))
PY
