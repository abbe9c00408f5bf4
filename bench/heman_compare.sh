#!/usr/bin/env bash
# bench/heman_compare.sh: `hfvis ao -k 16` against heman's heman_lighting_compute_occlusion
# (github.com/prideout/heman: the same hull-stack horizon sweep, 16 lattice directions, OpenMP
# on the CPU cores) on the same generated terrain (data/make_data.py; default: fractal,
# 1024 x 1024 and 2048 x 2048), both on every core, runs interleaved (hfvis, heman, hfvis,
# heman, ...). Prints a Markdown table of min / median wall time of each and heman / hfvis,
# for the whole process and for the computation alone, and writes it with the raw timings.
#
#   bench/heman_compare.sh --heman-dir DIR [--hfvis PATH] [--bench PATH] [--sizes 1024,2048] [--rounds 5]
#                          [--warmup 1] [--field fractal] [--threads N] [--out DIR]
#
#   --heman-dir DIR       a heman you built yourself (also: env HEMAN_DIR): DIR/include/heman.h
#                         (or DIR/heman.h) and DIR/libheman.a (or DIR/lib/, DIR/build/); or give
#                         --heman-include DIR and --heman-lib FILE. Build it with OpenMP on for its
#                         C files and optimisation on (see bench/README.md); this script never
#                         builds heman, and none of heman's code belongs in this repository.
#   --hfvis PATH          the hfvis CLI to time (default build/hfvis)
#   --bench PATH          hfvis_bench, for the library-call row: `hfvis_bench run FIELD -k 16
#                         --outputs ao --reps 1` times one computeHorizons call on a context
#                         that has built its program and buffers, as a renderer calling the
#                         library repeatedly sees it (default build/bench/hfvis_bench;
#                         the row is left out when there is none)
#   --sizes N[,N...]      square field sizes (default 1024,2048)
#   --rounds R            timed runs of each program per size, interleaved (default 5)
#   --warmup W            untimed runs of each first, per size (default 1; fills PoCL's cache)
#   --field NAME          data/make_data.py field: fractal, bricks, sine, blocks, random
#   --threads N           OMP_NUM_THREADS for heman, POCL_MAX_PTHREAD_COUNT /
#                         POCL_CPU_MAX_CU_NUM for hfvis (default: every core, nproc)
#   --out DIR             results.md, timings.csv, both programs' last outputs
#                         (default bench/out/heman/, git-ignored)
#   env: CC (default cc) compiles bench/heman_driver.c; HEMAN_CFLAGS / HEMAN_LIBS add flags
#        (HEMAN_FLOAT's size is probed and -DUSE_DOUBLE_PRECISION added when heman uses double).
#
# Same job for both: the heights of the generated field in pixel units, cell size 1 (hfvis's
# default; heman gets heman_lighting_set_occlusion_scale(max(W, H)), which makes its cells 1
# unit wide). Inputs go to bench/out/data/ (the EXR for hfvis, the same heights as raw float32
# for heman; their pixel hashes are compared when oiiotool is installed).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
python=/usr/bin/python3  # Debian's, for its numpy
hfvis=$root/build/hfvis
bench=$root/build/bench/hfvis_bench
heman_dir=${HEMAN_DIR:-}
heman_include=""
heman_lib=""
sizes=1024,2048
rounds=5
warmup=1
field=fractal
threads=$(nproc)
out=$root/bench/out/heman

usage() { sed -n '2,31p' "$0"; }
die() { echo "heman_compare.sh: $*" >&2; exit 1; }
need_value() { [[ $# -ge 2 && -n $2 ]] || { echo "heman_compare.sh: $1 needs a value (try --help)" >&2; exit 2; }; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --heman-dir) need_value "$@"; heman_dir=$2; shift ;;
    --heman-include) need_value "$@"; heman_include=$2; shift ;;
    --heman-lib) need_value "$@"; heman_lib=$2; shift ;;
    --hfvis) need_value "$@"; hfvis=$2; shift ;;
    --bench) need_value "$@"; bench=$2; shift ;;
    --sizes) need_value "$@"; sizes=$2; shift ;;
    --rounds) need_value "$@"; rounds=$2; shift ;;
    --warmup) need_value "$@"; warmup=$2; shift ;;
    --field) need_value "$@"; field=$2; shift ;;
    --threads) need_value "$@"; threads=$2; shift ;;
    --out) need_value "$@"; out=$2; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "heman_compare.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
[[ $sizes =~ ^[0-9]+(,[0-9]+)*$ ]] || { echo "heman_compare.sh: --sizes takes N[,N...]" >&2; exit 2; }
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "heman_compare.sh: --rounds must be >= 1" >&2; exit 2; }
[[ $warmup =~ ^[0-9]+$ ]] || { echo "heman_compare.sh: --warmup must be >= 0" >&2; exit 2; }
[[ $threads =~ ^[1-9][0-9]*$ ]] || { echo "heman_compare.sh: --threads must be >= 1" >&2; exit 2; }
case "$field" in fractal|bricks|sine|blocks|random) ;; *) echo "heman_compare.sh: unknown --field '$field'" >&2; exit 2 ;; esac

# --- heman: the user's own build ------------------------------------------------------------
how_to_build="heman is not part of this repository and this script does not build it: build it
yourself from https://github.com/prideout/heman, optimised and with OpenMP reaching its C sources
(its stock configuration gives neither, so its sweeps would run unoptimised on one core), then
pass --heman-dir DIR
(DIR holding include/heman.h and libheman.a) or --heman-include DIR --heman-lib FILE (see
bench/README.md)."
if [[ -z $heman_include && -n $heman_dir ]]; then
  for d in "$heman_dir/include" "$heman_dir"; do [[ -f $d/heman.h ]] && { heman_include=$d; break; }; done
fi
if [[ -z $heman_lib && -n $heman_dir ]]; then
  for f in "$heman_dir/libheman.a" "$heman_dir/lib/libheman.a" "$heman_dir/build/libheman.a"; do
    [[ -f $f ]] && { heman_lib=$f; break; }
  done
fi
if [[ -z $heman_dir && ( -z $heman_include || -z $heman_lib ) ]]; then
  die "no heman given (--heman-dir DIR or env HEMAN_DIR).
$how_to_build"
fi
[[ -n $heman_include && -f $heman_include/heman.h ]] || die "heman.h not found (looked in ${heman_dir:-?}/include, ${heman_dir:-?}, --heman-include).
$how_to_build"
[[ -n $heman_lib && -f $heman_lib ]] || die "libheman.a not found (looked in ${heman_dir:-?}, ${heman_dir:-?}/lib, ${heman_dir:-?}/build, --heman-lib).
$how_to_build"
heman_include=$(cd "$heman_include" && pwd)
heman_lib=$(cd "$(dirname "$heman_lib")" && pwd)/$(basename "$heman_lib")
if command -v nm > /dev/null; then
  symbols=$(nm "$heman_lib" 2> /dev/null || true)
  grep -q 'T heman_lighting_compute_occlusion' <<< "$symbols" || die "$heman_lib has no heman_lighting_compute_occlusion: not a heman library?"
  # heman's OpenMP loops become GOMP_parallel (GCC) or __kmpc_fork_call (Clang) calls.
  grep -Eq 'U (GOMP_parallel|__kmpc_fork_call)' <<< "$symbols" || die "$heman_lib was built without OpenMP: its sweeps would run on one core.
$how_to_build"
  if grep -q 'U __assert_fail' <<< "$(nm "$heman_lib" 2> /dev/null | sed -n '/^lighting\.c\.o:/,/^$/p')"; then
    echo "heman_compare.sh: warning: $heman_lib keeps its assert()s (built without -DNDEBUG, i.e." \
      "not a Release build?); its sweep asserts in the inner loop, so it may be timed slow" >&2
  fi
else
  echo "heman_compare.sh: warning: nm not found, cannot check that heman was built with OpenMP" >&2
fi

# --- hfvis --------------------------------------------------------------------------------------
[[ -x $hfvis ]] || die "hfvis binary not found or not executable: $hfvis (build it, or pass --hfvis PATH)"
hfvis=$(cd "$(dirname "$hfvis")" && pwd)/$(basename "$hfvis")
if [[ -x $bench ]]; then
  bench=$(cd "$(dirname "$bench")" && pwd)/$(basename "$bench")
else
  echo "heman_compare.sh: no hfvis_bench at $bench: the library-call row is left out" >&2
  bench=""
fi

mkdir -p "$out"
out=$(cd "$out" && pwd)
data=$root/bench/out/data
mkdir -p "$data"
# PoCL's kernel cache of the benchmark's own (see bench/README.md, PoCL notes).
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
export OMP_NUM_THREADS=$threads
export POCL_MAX_PTHREAD_COUNT=$threads POCL_CPU_MAX_CU_NUM=$threads  # PoCL 3.1 / newer names

# --- the driver (our code), linked against the user's heman ---------------------------------------
cc=${CC:-cc}
driver=$out/heman_driver
build_driver() {
  # shellcheck disable=SC2086  # HEMAN_CFLAGS / HEMAN_LIBS are word lists
  "$cc" -O2 -std=c99 -fopenmp ${HEMAN_CFLAGS:-} "$@" -I"$heman_include" "$root/bench/heman_driver.c" \
    "$heman_lib" ${HEMAN_LIBS:-} -lm -o "$driver" || die "compiling bench/heman_driver.c against $heman_lib failed"
}
build_driver
probe=$("$driver" --probe)
lib_bytes=$(sed -n 's/^library_float_bytes=//p' <<< "$probe")
drv_bytes=$(sed -n 's/^driver_float_bytes=//p' <<< "$probe")
if [[ $lib_bytes != "$drv_bytes" ]]; then
  [[ $lib_bytes == 8 ]] || die "heman's HEMAN_FLOAT is $lib_bytes bytes, the driver's $drv_bytes: set HEMAN_CFLAGS to match"
  build_driver -DUSE_DOUBLE_PRECISION
fi
heman_float=float
[[ $lib_bytes == 8 ]] && heman_float=double

# --- inputs ---------------------------------------------------------------------------------------
IFS=, read -r -a size_list <<< "$sizes"
for n in "${size_list[@]}"; do
  (( n >= 16 )) || die "sizes must be >= 16"
  exr=$data/${field}_$n.exr
  raw=$data/${field}_$n.f32le.raw
  [[ -f $exr ]] || "$python" "$root/data/make_data.py" --size "$n" --out "$data" --no-dem --fields "$field" > /dev/null
  if [[ ! -f $raw || $raw -ot $exr ]]; then
    "$python" - "$root/data" "$field" "$n" "$raw" << 'EOF'
import sys
sys.path.insert(0, sys.argv[1])
import make_data
gens = {"fractal": make_data.fractal, "bricks": make_data.bricks, "sine": make_data.sine,
        "blocks": make_data.blocks, "random": make_data.random_field}
gens[sys.argv[2]](int(sys.argv[3])).astype("<f4").tofile(sys.argv[4])
EOF
  fi
  if command -v oiiotool > /dev/null; then
    # oiiotool hashes the pixels as float32 in memory: equal to the raw file's SHA-1 when equal.
    want=$(oiiotool --hash "$exr" | sed -n 's/.*SHA-1: *//p' | tr 'A-F' 'a-f')
    have=$(sha1sum "$raw" | cut -d' ' -f1)
    [[ $want == "$have" ]] || die "$exr and $raw hold different heights (stale input? delete both and rerun)"
  fi
done

# --- the interleaved runs -------------------------------------------------------------------------
commit=$(git -C "$root" rev-parse --short HEAD 2> /dev/null || echo unknown)
if ! git -C "$root" diff --quiet HEAD 2> /dev/null; then commit="$commit (with uncommitted changes)"; fi
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)

"$python" - "$hfvis" "$driver" "$data" "$field" "$sizes" "$rounds" "$warmup" "$out" "$root/data" \
  "$threads" "$heman_lib" "$heman_float" "$commit" "$cpu" "$bench" << 'EOF'
import csv, datetime, os, re, resource, statistics, subprocess, sys, time
import numpy as np

(hfvis, driver, data, field, sizes, rounds, warmup, out, data_dir, threads, heman_lib, heman_float,
 commit, cpu, bench) = sys.argv[1:]
sizes = [int(s) for s in sizes.split(",")]
rounds, warmup = int(rounds), int(warmup)


def run(cmd):
    """Whole-process wall clock (monotonic) and CPU time (user + sys of the child), stdout."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        sys.exit("heman_compare.sh: command failed (%d): %s\n%s%s"
                 % (p.returncode, " ".join(cmd), p.stdout, p.stderr))
    cpu_s = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu_s, p.stdout


def hfvis_run(n):
    exr = os.path.join(data, "%s_%d.exr" % (field, n))
    # Without --quiet: the summary line gives the library call's time (computeHorizons, 2 decimals).
    wall, cpu_s, text = run([hfvis, "ao", exr, "-o", os.path.join(out, "hfvis_ao_%d.exr" % n), "-k", "16"])
    m = re.search(r", ([0-9.]+) s on (.*)\); mean ao ([0-9.]+)", text)
    if not m:
        sys.exit("heman_compare.sh: cannot read hfvis's summary line: %r" % text)
    devices.add(m.group(2))
    return wall, cpu_s, float(m.group(1)), float(m.group(3))


def heman_run(n):
    raw = os.path.join(data, "%s.f32le.raw" % ("%s_%d" % (field, n)))
    wall, cpu_s, text = run([driver, raw, str(n), str(n), "--out", os.path.join(out, "heman_ao_%d.raw" % n)])
    kv = dict(line.split("=", 1) for line in text.split() if "=" in line)
    return wall, cpu_s, float(kv["compute_seconds"]), float(kv["mean_ao"])


def library_run(n):
    exr = os.path.join(data, "%s_%d.exr" % (field, n))
    wall, cpu_s, text = run([bench, "run", exr, "-k", "16", "--outputs", "ao", "--reps", "1"])
    m = re.search(r"min ([0-9.]+) s, .* on (.*) \(", text)
    if not m:
        sys.exit("heman_compare.sh: cannot read hfvis_bench's line: %r" % text)
    devices.add(m.group(2))
    return wall, cpu_s, float(m.group(1)), float("nan")


devices = set()
tools = (("hfvis", hfvis_run), ("heman", heman_run)) + ((("hfvis_lib", library_run),) if bench else ())
rows = []
load_before = open("/proc/loadavg").read().split()[:3]
for n in sizes:
    for _ in range(warmup):
        for _, f in tools:
            f(n)
    for r in range(rounds):
        for name, f in tools:
            wall, cpu_s, compute, mean = f(n)
            rows.append(dict(size=n, round=r + 1, program=name, wall_s=round(wall, 6), cpu_s=round(cpu_s, 6),
                             compute_s=compute, mean_ao=mean))
            print("  %dx%d round %d/%d %-5s wall %.3f s, compute %.3f s, cpu %.3f s"
                  % (n, n, r + 1, rounds, name, wall, compute, cpu_s), file=sys.stderr, flush=True)
load_after = open("/proc/loadavg").read().split()[:3]

with open(os.path.join(out, "timings.csv"), "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)

# heman's last output as an EXR too (channel Y), to view beside hfvis's.
sys.path.insert(0, data_dir)
import make_data
for n in sizes:
    a = np.fromfile(os.path.join(out, "heman_ao_%d.raw" % n), dtype="<f4").reshape(n, n)
    make_data.write_exr_builtin(os.path.join(out, "heman_ao_%d.exr" % n), a,
                                {"hfvis:description": "heman_lighting_compute_occlusion (bench/heman_compare.sh)"})


def pick(n, prog, key):
    return [r[key] for r in rows if r["size"] == n and r["program"] == prog]


lines = []
lines.append("`hfvis ao -k 16` against heman's `heman_lighting_compute_occlusion` (16 directions), "
             "%s field, %d interleaved rounds after %d warm-up run(s) each, %s thread(s) each."
             % (field, rounds, warmup, threads))
lines.append("")
lines.append("| size | timed | hfvis min (s) | hfvis median (s) | heman min (s) | heman median (s) "
             "| heman/hfvis min | heman/hfvis median |")
lines.append("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
timed = [("hfvis", "wall_s", "whole process"), ("hfvis", "compute_s", "computation")]
if bench:
    timed.append(("hfvis_lib", "compute_s", "library call (program built)"))
for n in sizes:
    for prog, key, what in timed:
        a, b = pick(n, prog, key), pick(n, "heman", key)
        amin, amed, bmin, bmed = min(a), statistics.median(a), min(b), statistics.median(b)
        lines.append("| %dx%d | %s | %.3f | %.3f | %.3f | %.3f | %.2f | %.2f |"
                     % (n, n, what, amin, amed, bmin, bmed, bmin / amin, bmed / amed))
lines.append("")
for n in sizes:
    util = []
    for prog in ("hfvis", "heman"):
        util.append("%s %.2f" % (prog, statistics.median(
            [c / w for c, w in zip(pick(n, prog, "cpu_s"), pick(n, prog, "wall_s"))])))
    lines.append("- %dx%d: cores busy (process CPU time / wall, median): %s; mean AO: hfvis %.4f, heman %.4f "
                 "(different AO formulas and directions: compare images, not values)"
                 % (n, n, ", ".join(util), pick(n, "hfvis", "mean_ao")[-1], pick(n, "heman", "mean_ao")[-1]))
noisy = []
for n in sizes:
    for prog in ("hfvis", "heman"):
        w = pick(n, prog, "wall_s")
        if max(w) > 1.15 * min(w):
            noisy.append("%s %dx%d (max/min %.2f)" % (prog, n, n, max(w) / min(w)))
if noisy:
    lines.append("- WARNING: wide spread of wall times: %s; other processes probably shared the cores: "
                 "rerun on a quiet machine (the minimums are the more robust figures meanwhile)."
                 % ", ".join(noisy))
lines.append("- whole process: hfvis reads the ZIP EXR, sets up OpenCL (kernels from PoCL's cache), "
             "computes, writes a ZIP EXR; heman's driver reads raw float32, computes, writes raw float32.")
lines.append("- computation: hfvis's `computeHorizons` call as its summary line prints it (10 ms steps; "
             "includes building the program from PoCL's cache and the transfers); heman's "
             "`heman_lighting_compute_occlusion` call (with its allocations), timed in the driver.")
if bench:
    lines.append("- library call (program built): one `computeHorizons` call (ambient occlusion, K = 16) timed "
                 "by `hfvis_bench run FIELD -k 16 --outputs ao --reps 1` after a full-size untimed call on the "
                 "same context, as a renderer calling the library again sees it; against heman's call.")
lines.append("- same geometry: heights in pixel units, cell size 1 (heman: occlusion scale = field size). "
             "hfvis: 16 azimuths 22.5 deg apart, bilinear heights; heman: 16 lattice steps "
             "(rook, bishop, knight), heights at the lattice points, HEMAN_FLOAT = %s." % heman_float)
lines.append("- hfvis `%s` on %s (repository at commit %s); heman `%s`; CPU %s, %d cores; load average %s before, %s after; %s."
             % (hfvis, ", ".join(sorted(devices)), commit, heman_lib, cpu, os.cpu_count(), " ".join(load_before),
                " ".join(load_after), datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%MZ")))
text = "\n".join(lines) + "\n"
with open(os.path.join(out, "results.md"), "w") as f:
    f.write(text)
sys.stdout.write(text)
print("\nwritten: %s/results.md, timings.csv, hfvis_ao_N.exr, heman_ao_N.exr (and .raw)" % out, file=sys.stderr)
EOF
