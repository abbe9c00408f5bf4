#!/usr/bin/env bash
# bench/startup.sh: issue 27 item 5's timing: whole `hfvis svf` runs on an 8 x 8 field, where the
# process's start-up (loading libraries, PoCL, reading and writing the files) is nearly all of
# the time: the field as an EXR and as a GeoTIFF, each written to a GeoTIFF, and the EXR to an
# EXR too, plus `hfvis --help` (the start alone). The commands take turns, round after round, so
# a drift of the machine's speed touches them alike; each is timed from outside (wall clock, and
# the user + system CPU time the kernel accounts to the finished process). Prints, per command,
# the min and median wall and CPU seconds, and the median of the round-by-round ratios to the
# GeoTIFF run (target: the EXR run's ratio not above 1).
#
#   bench/startup.sh [--runs N]     (N counted rounds, default 21, after one warm-up round)
#   BUILD_DIR=... selects the build (default build/); its files go to bench/out/startup/.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
runs=21
while [[ $# -gt 0 ]]; do
  case "$1" in
    --runs) runs=$2; shift ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "startup.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
build_dir=${BUILD_DIR:-$root/build}
cli=$build_dir/hfvis
bench=$build_dir/bench/hfvis_bench
for program in "$cli" "$bench"; do
  [[ -x $program ]] || { echo "startup.sh: no $program; build first (cmake --build $build_dir)" >&2; exit 1; }
done
# PoCL's kernel cache of the benchmark's own (see bench/README.md, PoCL notes).
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
work=$root/bench/out/startup
mkdir -p "$work"
"$bench" field city 8 "$work/c8.exr" > /dev/null
"$bench" field city 8 "$work/c8.tif" > /dev/null
echo "hfvis at $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?'), $(nproc) cores," \
  "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $runs rounds"
/usr/bin/python3 - "$runs" "$cli" "$work" << 'PY'
import os, statistics, subprocess, sys, time

runs, cli, work = int(sys.argv[1]), sys.argv[2], sys.argv[3]
commands = {
    "exr -> tif": [cli, "svf", f"{work}/c8.exr", "-o", f"{work}/o_exr.tif", "-q"],
    "tif -> tif": [cli, "svf", f"{work}/c8.tif", "-o", f"{work}/o_tif.tif", "-q"],
    "exr -> exr": [cli, "svf", f"{work}/c8.exr", "-o", f"{work}/o_exr.exr", "-q"],
    "--help": [cli, "--help"],
}

def once(argv):
    start = time.perf_counter()
    child = subprocess.Popen(argv, stdout=subprocess.DEVNULL)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    if status != 0:
        sys.exit(f"startup.sh: {' '.join(argv)} failed ({status})")
    return wall, usage.ru_utime + usage.ru_stime

times = {name: [] for name in commands}
for round_ in range(runs + 1):
    for name, argv in commands.items():
        t = once(argv)
        if round_ > 0:  # round 0 warms the page cache and PoCL's kernel cache
            times[name].append(t)

print(f"{'command':<12} {'wall min':>9} {'wall med':>9} {'cpu min':>9} {'cpu med':>9}"
      f" {'wall/tif':>9} {'cpu/tif':>9}")
reference = times["tif -> tif"]
for name, samples in times.items():
    walls = [w for w, _ in samples]
    cpus = [c for _, c in samples]
    wall_ratio = statistics.median(w / r[0] for (w, _), r in zip(samples, reference))
    cpu_ratio = statistics.median(c / r[1] for (_, c), r in zip(samples, reference))
    print(f"{name:<12} {min(walls):9.3f} {statistics.median(walls):9.3f} {min(cpus):9.3f}"
          f" {statistics.median(cpus):9.3f} {wall_ratio:9.3f} {cpu_ratio:9.3f}")
PY
