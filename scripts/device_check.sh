#!/usr/bin/env bash
# scripts/device_check.sh: the OpenCL kernel tests and a short benchmark on a machine with no
# build tools and no libraries of ours (the GPU machine the `device` tool lends), from a bundle
# built here. Two modes:
#
#   scripts/device_check.sh bundle   (here, where the project builds)
#     Configures and builds hfvis_tests, hfvis (CLI) and hfvis_bench (Release) in BUILD_DIR
#     (default: ../gpu-build beside the checkout; never build/), then packs them with every
#     shared library they load except glibc's into .device/hfvis-device-bundle.tar.xz (the
#     folder .device/ is added to .git/info/exclude). OpenImageIO and GDAL pull in ~250
#     libraries (360 MB); the ones that reading EXR and GeoTIFF never calls (video codecs,
#     OpenVDB, OpenCV, DICOM, PDF, HDF5, ICU, ...; STUB_PATTERN below) are replaced by stubs
#     that define the symbols the carried objects import from them and abort, naming the symbol,
#     if one is ever called (version queries, which plugin tables make at start, get a string),
#     so the bundle (about 23 MiB) stays under the tool's 64 MiB with the working tree. The
#     bundle checks that every symbol resolves (ldd -r) before packing. The kernel tests are
#     the suites of the KERNEL_TEST_FILES below (their filter is stored in the bundle).
#
#   scripts/device_check.sh run      (there, or here to rehearse with PoCL: same bundle, same steps)
#     Unpacks the bundle into $TMPDIR/hfvis-device, points the OpenCL ICD loader at NVIDIA's
#     libnvidia-opencl.so.1 where it finds one (OCL_ICD_VENDORS; else the system's vendors, e.g.
#     PoCL), then writes to LOG_DIR ($OUT on the device machine, else .device/logs/):
#       env.txt      machine, nvidia-smi, bundle manifest, library resolution, `hfvis devices`
#       tests.log    the kernel tests (those that compare layouts run both line-buffer layouts,
#                    the rest the device's own), in DEVICE_CHECK_SHARDS gtest shards run side by
#                    side, each under a timeout
#       bench.log    hfvis_bench run (sweep, K = 64, svf and angles, fractal 1024^2 and 4096^2
#                    from data/make_data.py; the naive march too on a GPU) and whole `hfvis svf`
#                    and `hfvis viewcount` runs, wall/user/sys seconds each
#       summary.txt  passed / failed counts, every failed test with its messages, the timings
#     Exit status: 0 when every test passed, 1 when one failed or a shard crashed or timed out.
#     HFVIS_DEVICE defaults to "gpu" where NVIDIA's library was found (else the library's
#     automatic choice); the other HFVIS_* variables pass through.
#
# Through the device tool (one call: 148 s on an H200 on 2026-12-04, plus the machine's start):
#   run(command="bash scripts/device_check.sh run", carry=[".device"], timeout_s=420)
# The logs come back under the tool's files_at folder; copy them to bench/report/gpu/.
# Rehearsal here (2 cores, PoCL: about 11 minutes):
#   LOG_DIR=/tmp/rehearsal DEVICE_CHECK_TEST_TIMEOUT=1800 DEVICE_CHECK_BUDGET=4000 scripts/device_check.sh run
#
# Knobs (environment): BUILD_DIR, JOBS (bundle); LOG_DIR, DEVICE_CHECK_SHARDS (default: cores,
# at most 12), DEVICE_CHECK_TEST_TIMEOUT (s per shard, default 240), DEVICE_CHECK_BUDGET (s for
# the whole run, default 360: each benchmark command is cut off at it plus 20 s, and skipped when
# less than 30 s would be left, so that the run ends inside the tool's 420 s),
# DEVICE_CHECK_BENCH=0 (tests only), DEVICE_CHECK_TESTS=0 (benchmark only), DEVICE_CHECK_NAIVE=1
# (the naive march on a CPU device too: about 6 minutes on 2 cores).
set -uo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
bundle_name=hfvis-device-bundle.tar.xz
bundle_file=$root/.device/$bundle_name

KERNEL_TEST_FILES="test_horizon_sweep test_intervisibility test_bounce test_viewshed test_viewshed_culling
  test_horizon_lists test_shading test_sun test_environment test_horizon_analytic test_fast_math test_context"
# Libraries (by file name) that EXR reading (OpenImageIO), GeoTIFF reading and writing (GDAL)
# and OpenCL never call: carried as stubs. A stub that is called aborts with its name: then
# take the library off this list.
STUB_PATTERN='^lib(openvdb|tbb|icu(data|uc|i18n)|codec2|x26[45]|av(codec|format|util|device|filter)|sw(scale|resample)|postproc|rsvg-2|spatialite|lapack|blas|arpack|superlu|armadillo|gfortran|SvtAv1Enc|aom|dav1d|rav1e|vpx|opencv_[a-z]+|hdf5[a-z_]*|mfhdfalt|dfalt|netcdf|xerces-c|poppler|jxl|jxl_threads|gdcm[A-Za-z0-9]*|openmpt|cfitsio|gst[a-z]+-1\.0|gstreamer-1\.0|X11|X11-xcb|cairo|cairo-gobject|raw_r|harfbuzz|srt-gnutls|zmq|GLdispatch|GLX|pixman-1|xvidcore|vorbis(enc|file)?|dw|log4cplus-2\.0|orc-0\.4|kml(base|dom|engine|convenience|regionator|xsd)|zvbi|mariadb|pq|geos|geos_c|de265|heif|ssh-gcrypt|ssh2|bluray|gme|mp3lame|theora(enc|dec)|dc1394|soxr|speex|gsm|twolame|shine|chromaprint|rabbitmq|va|va-drm|va-x11|vdpau|gphoto2|gphoto2_port|usb-1\.0|raw1394|OpenColorIO|ogdi|fyba|fygm|fyut|freexl|odbc|odbcinst|qhull_r|rttopo|sz|aec|mfx|opus|rist|norm|pgm-5\.3|sodium|zmq|gcrypt|nss3|nssutil3|smime3|nspr4|plc4|plds4)\.so'
GLIBC_PATTERN='^(libc|libm|libpthread|libdl|librt|libresolv|libutil|libanl|libBrokenLocale|libnss_[a-z]+|libmvec|libthread_db|ld-linux-x86-64)\.so'

die() { echo "device_check: $*" >&2; exit 2; }

# ---------------------------------------------------------------------------------------------
bundle() {
  local build_dir=${BUILD_DIR:-$(dirname "$root")/gpu-build}
  build_dir=$(mkdir -p "$build_dir" && cd "$build_dir" && pwd)
  [[ $build_dir == "$root/build" ]] && die "BUILD_DIR must not be build/ (another engineer's build)"
  echo "== building hfvis_tests, hfvis, hfvis_bench in $build_dir"
  if [[ ! -f $build_dir/CMakeCache.txt ]]; then
    cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release > /dev/null || die "cmake configure failed"
  fi
  cmake --build "$build_dir" -j "${JOBS:-2}" --target hfvis_tests hfvis_cli hfvis_bench || die "build failed"

  local exclude
  exclude=$(git -C "$root" rev-parse --git-path info/exclude)
  [[ $exclude == /* ]] || exclude=$root/$exclude
  mkdir -p "$(dirname "$exclude")"
  grep -qxF '/.device/' "$exclude" 2>/dev/null || echo '/.device/' >> "$exclude"

  local stage
  stage=$(mktemp -d "${TMPDIR:-/tmp}/hfvis-bundle.XXXXXX")
  mkdir -p "$stage/build/tests" "$stage/build/bench" "$stage/lib" "$stage/lib-cxx"
  cp "$build_dir/hfvis" "$build_dir/libhfvis_oiio.so" "$stage/build/"
  cp "$build_dir/bench/hfvis_bench" "$stage/build/bench/"
  cp "$build_dir/tests/hfvis_tests" "$stage/build/tests/"
  strip --strip-unneeded "$stage/build/hfvis" "$stage/build/libhfvis_oiio.so" "$stage/build/bench/hfvis_bench" \
    "$stage/build/tests/hfvis_tests"

  # The gtest filter of the kernel test suites.
  local filter="" f suite
  for f in $KERNEL_TEST_FILES; do
    [[ -f $root/tests/$f.cpp ]] || die "no tests/$f.cpp"
    for suite in $(grep -oE '^(TEST|TEST_F|TEST_P|TYPED_TEST)\( *[A-Za-z0-9_]+' "$root/tests/$f.cpp" |
                   sed -E 's/.*\( *//' | sort -u); do
      filter+="${filter:+:}$suite.*:*/$suite.*"
    done
  done

  echo "== libraries (stubs for $(echo "$STUB_PATTERN" | tr '|' '\n' | wc -l) name patterns)"
  python3 - "$stage" "$STUB_PATTERN" "$GLIBC_PATTERN" "$stage/build/hfvis" "$stage/build/libhfvis_oiio.so" \
    "$stage/build/bench/hfvis_bench" "$stage/build/tests/hfvis_tests" <<'PY' || die "library bundling failed"
import os, re, shutil, subprocess, sys
stage, stub_re, glibc_re, roots = sys.argv[1], re.compile(sys.argv[2]), re.compile(sys.argv[3]), sys.argv[4:]

def run(*args):
    return subprocess.run(args, check=True, capture_output=True, text=True).stdout

def needed(path):
    return re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", run("readelf", "-W", "-d", path))

# Where the system resolves each library name (ldd of the roots gives the whole closure).
where = {}
for r in roots:
    for line in run("ldd", r).splitlines():
        m = re.match(r"\s*(\S+) => (\S+) \(", line)
        if m: where[m.group(1)] = m.group(2)
        elif "not found" in line: sys.exit("ldd: %s: %s" % (r, line.strip()))

# Breadth-first over DT_NEEDED, stopping at glibc and at the stubbed libraries.
kept, stubbed, queue, seen = {}, {}, list(roots), set()
while queue:
    obj = queue.pop(0)
    for name in needed(obj):
        if name in seen or glibc_re.match(name): continue
        seen.add(name)
        if name not in where: sys.exit("cannot resolve %s (needed by %s)" % (name, obj))
        if stub_re.match(name): stubbed[name] = where[name]
        else:
            kept[name] = where[name]; queue.append(where[name])

def dynsyms(path):
    """(name, version, defined, type, size, bind) of each dynamic symbol."""
    out = []
    for line in run("readelf", "-W", "--dyn-syms", path).splitlines():
        m = re.match(r"\s*\d+:\s+[0-9a-f]+\s+(0x[0-9a-f]+|\d+)\s+(\w+)\s+(\w+)\s+\w+\s+(\w+)\s+(\S+)", line)
        if not m: continue
        size, typ, bind, ndx, name = m.groups()
        if ndx == "ABS" or typ in ("SECTION", "FILE"): continue
        version = ""
        if "@" in name:
            name, _, version = name.partition("@")
            version = version.lstrip("@")
        out.append((name, version, ndx != "UND", typ, int(size, 0), bind))
    return out

def verneed(path):
    """{file: set of version names} this object requires."""
    req, current = {}, None
    for line in run("readelf", "-W", "-V", path).splitlines():
        m = re.search(r"File: (\S+)\s+Cnt:", line)
        if m: current = req.setdefault(m.group(1), set()); continue
        m = re.search(r"Name: (\S+)\s+Flags:", line)
        if m and current is not None: current.add(m.group(1))
    return req

carried = roots + list(kept.values())
undefined, defined_kept, required_versions = {}, set(), {}
for obj in carried:
    for name, version, is_def, typ, size, bind in dynsyms(obj):
        if is_def: defined_kept.add(name)
        else: undefined.setdefault(name, set()).add(version)
    for file, versions in verneed(obj).items():
        required_versions.setdefault(file, set()).update(versions)

os.makedirs(os.path.join(stage, "stubs"), exist_ok=True)
total_stubs = 0
for soname, path in sorted(stubbed.items()):
    # Each imported symbol that no carried object defines, in each version it is imported
    # under (an unversioned import: the library's default version).
    defs = {}
    for name, version, is_def, typ, size, bind in dynsyms(path):
        if is_def and name in undefined and name not in defined_kept:
            defs.setdefault(name, []).append((version, typ, size))
    syms = []
    for name, versions in defs.items():
        wanted = sorted(v for v in undefined[name] if v) or [versions[-1][0]]
        for k, version in enumerate(wanted):
            typ, size = next(((t, z) for v, t, z in versions if v == version), versions[0][1:])
            syms.append((name, version, typ, size, k == 0))
    src = ['#include <stdio.h>', '#include <stdlib.h>',
           'static void fail(const char* name) {',
           '  fprintf(stderr, "device bundle: %%s is a stub of %s (not carried); %%s was called: take it off '
           'STUB_PATTERN in scripts/device_check.sh\\n", "%s", name);' % (soname, soname),
           '  abort();', '}']
    nodes = {v: [] for v in required_versions.get(soname, set())}
    for i, (name, version, typ, size, primary) in enumerate(sorted(syms)):
        # The primary version through the version script (name@@version); others through .symver.
        label = name if primary else "%s__stub_v%d" % (name, i)
        if typ in ("FUNC", "IFUNC", "GNU_IFUNC") and re.search(r"(?i)version|libvers", name):
            # Version queries (plugin tables, driver registration ask them at start): a string.
            src.append('const char* f%d(void) __asm__("%s");\nconst char* f%d(void) { return "0.0.0-stub"; }'
                       % (i, label, i))
        elif typ in ("FUNC", "IFUNC", "GNU_IFUNC"):
            src.append('void f%d(void) __asm__("%s");\nvoid f%d(void) { fail("%s"); }' % (i, label, i, name))
        elif typ == "TLS":
            src.append('__thread char t%d[%d] __asm__("%s") __attribute__((aligned(16)));' % (i, max(size, 1), label))
        else:
            src.append('char d%d[%d] __asm__("%s") __attribute__((aligned(16)));' % (i, max(size, 8), label))
        if not primary:
            src.append('__asm__(".symver %s, %s@%s");' % (label, name, version))
            nodes.setdefault(version, [])
        elif version: nodes.setdefault(version, []).append(name)
    c_file = os.path.join(stage, "stubs", soname + ".c")
    with open(c_file, "w") as f: f.write("\n".join(src) + "\n")
    args = ["gcc", "-shared", "-fPIC", "-O0", "-w", "-o", os.path.join(stage, "lib", soname), c_file,
            "-Wl,-soname," + soname]
    if nodes:
        vs = os.path.join(stage, "stubs", soname + ".map")
        with open(vs, "w") as f:
            for v, names in sorted(nodes.items()):
                f.write("%s { %s };\n" % (v, "global: " + " ".join('"%s";' % n for n in names) if names else ""))
        args.append("-Wl,--version-script=" + vs)
    subprocess.run(args, check=True)
    total_stubs += len(syms)
shutil.rmtree(os.path.join(stage, "stubs"))

cxx = {"libstdc++.so.6", "libgcc_s.so.1"}
size = 0
for soname, path in sorted(kept.items()):
    dest = os.path.join(stage, "lib-cxx" if soname in cxx else "lib", soname)
    shutil.copy2(path, dest)  # follows links: the file under its soname
    size += os.path.getsize(dest)
with open(os.path.join(stage, "cxx-versions.txt"), "w") as f:
    for file in sorted(cxx):
        for v in sorted(required_versions.get(file, ())): f.write("%s %s\n" % (file, v))
print("carried %d libraries (%.1f MiB), stubbed %d (%d symbols): %s" %
      (len(kept), size / 2**20, len(stubbed), total_stubs, " ".join(sorted(stubbed))))
PY
  # Every symbol of every carried object resolves (data and functions: ldd -r) against the bundle.
  local f undefined_syms=""
  for f in "$stage/build/hfvis" "$stage/build/libhfvis_oiio.so" "$stage/build/bench/hfvis_bench" \
           "$stage/build/tests/hfvis_tests"; do
    undefined_syms+=$(LD_LIBRARY_PATH=$stage/lib:$stage/lib-cxx ldd -r "$f" 2>&1 | grep -E 'undefined symbol|not found')
  done
  [[ -z $undefined_syms ]] || die "unresolved in the bundle: $(echo "$undefined_syms" | head -20)"
  cat > "$stage/manifest.env" <<EOF
SRC_DIR='$root'
BUILD_DIR='$build_dir'
COMMIT='$(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet HEAD -- src kernels include tests testing bench cli || echo ' (with uncommitted changes)')'
BUILT='$(date -u +%Y-%m-%dT%H:%M:%SZ) on $(uname -n), $(ldd --version | head -1)'
KERNEL_TEST_FILTER='$filter'
EOF
  echo "== packing"
  mkdir -p "$root/.device"
  tar -C "$stage" -cf - . | xz -T "${JOBS:-2}" -6 > "$bundle_file.tmp" && mv "$bundle_file.tmp" "$bundle_file" ||
    die "packing failed"
  rm -rf "$stage"
  local mib
  mib=$(( $(stat -c %s "$bundle_file") / 1048576 ))
  echo "== $bundle_file: $mib MiB (the tool carries at most 64 MiB with the working tree)"
  (( mib < 56 )) || echo "device_check: warning: the bundle is large; add libraries to STUB_PATTERN" >&2
}

# ---------------------------------------------------------------------------------------------
run_checks() {
  local start=$SECONDS budget=${DEVICE_CHECK_BUDGET:-360}
  [[ -f $bundle_file ]] || die "no $bundle_file: run '$0 bundle' first (and carry .device)"
  local logs=${LOG_DIR:-${OUT:-$root/.device/logs}}
  mkdir -p "$logs"
  logs=$(cd "$logs" && pwd)
  local env_log=$logs/env.txt tests_log=$logs/tests.log bench_log=$logs/bench.log summary=$logs/summary.txt
  : > "$env_log"; : > "$tests_log"; : > "$bench_log"; : > "$summary"
  local work=${TMPDIR:-/tmp}/hfvis-device
  rm -rf "$work"; mkdir -p "$work"
  xz -dc "$bundle_file" | tar -C "$work" -xf - || die "cannot unpack $bundle_file"
  # shellcheck disable=SC1091
  source "$work/manifest.env"

  {
    echo "== date: $(date -u +%Y-%m-%dT%H:%M:%SZ)   host: $(uname -n)   $(uname -srm)"
    echo "cores: $(nproc)   $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
    echo "memory: $(awk '/MemTotal/{printf "%.1f GiB", $2/1048576}' /proc/meminfo)   load: $(cut -d' ' -f1-3 /proc/loadavg)"
    echo "glibc: $(ldd --version 2>&1 | head -1)"
    echo "repository here: $root"
    echo "== bundle: commit $COMMIT, built $BUILT (source $SRC_DIR, build $BUILD_DIR)"
  } >> "$env_log"

  # The tests have the build's paths compiled in (data, the CLI, their tmp folder): make them
  # exist here when they do not.
  if [[ ! -e $SRC_DIR/data ]]; then
    mkdir -p "$(dirname "$SRC_DIR")" && ln -sfn "$root" "$SRC_DIR" &&
      echo "linked $SRC_DIR -> $root" >> "$env_log"
  elif [[ $(cd "$SRC_DIR" && pwd -P) != $(cd "$root" && pwd -P) ]]; then
    echo "note: $SRC_DIR exists and is not this checkout: the tests read its data/" >> "$env_log"
  fi
  if [[ ! -e $BUILD_DIR ]]; then
    mkdir -p "$(dirname "$BUILD_DIR")" && ln -sfn "$work/build" "$BUILD_DIR" &&
      echo "linked $BUILD_DIR -> $work/build" >> "$env_log"
  fi
  mkdir -p "$work/build/tests/tmp" "$BUILD_DIR/tests/tmp" 2>/dev/null

  # OpenCL: NVIDIA's ICD where there is one.
  local nv="" d
  for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu /usr/lib64 /usr/lib \
           /usr/local/cuda/lib64 /usr/local/cuda/compat; do
    [[ -e $d/libnvidia-opencl.so.1 ]] && { nv=$d/libnvidia-opencl.so.1; break; }
  done
  {
    echo "== OpenCL ICDs"
    echo "search: $(timeout 20 find / -xdev -name 'libnvidia-opencl*' 2>/dev/null | head -5 | tr '\n' ' ')" \
         "$(timeout 20 find /usr/local/nvidia -name 'libnvidia-opencl*' 2>/dev/null | head -5 | tr '\n' ' ')"
    ls /usr/local/nvidia/lib64 /usr/local/nvidia/lib 2>&1 | grep -iE 'opencl|cuda\.so|nvidia:|lib64:|lib:|No such' | head -12
    echo "/etc/OpenCL/vendors: $(cat /etc/OpenCL/vendors/*.icd 2>/dev/null | tr '\n' ' ')"
  } >> "$env_log"
  if [[ -z $nv ]]; then
    nv=$(timeout 30 find /usr/local/nvidia /usr /opt -name 'libnvidia-opencl.so.1' 2>/dev/null | head -1)
  fi
  local extra_path=""
  if [[ -n $nv ]]; then
    mkdir -p "$work/vendors"
    echo "$nv" > "$work/vendors/nvidia.icd"
    export OCL_ICD_VENDORS=$work/vendors
    extra_path=:$(dirname "$nv")
    export HFVIS_DEVICE=${HFVIS_DEVICE-gpu}
    echo "using $nv (OCL_ICD_VENDORS=$OCL_ICD_VENDORS)" >> "$env_log"
  else
    echo "no libnvidia-opencl.so.1: the system's OpenCL vendors (OCL_ICD_VENDORS=${OCL_ICD_VENDORS:-unset})" >> "$env_log"
  fi
  echo "HFVIS_DEVICE=${HFVIS_DEVICE-(unset: automatic)} HFVIS_LINE_LAYOUT=${HFVIS_LINE_LAYOUT-(unset)}" >> "$env_log"

  # libstdc++ and libgcc_s: the system's where they have every version the bundle needs.
  local cxx_path=":$work/lib-cxx" file version sys_lib ok=1
  while read -r file version; do
    sys_lib=$(ldconfig -p 2>/dev/null | awk -v f="$file" '$1 == f && /x86-64/ {print $NF; exit}')
    [[ -n $sys_lib ]] && grep -aq "$version" "$sys_lib" || { ok=0; break; }
  done < "$work/cxx-versions.txt"
  if (( ok )); then cxx_path=""; echo "libstdc++/libgcc_s: the system's" >> "$env_log"
  else echo "libstdc++/libgcc_s: the bundle's (the system's lack $file $version)" >> "$env_log"; fi
  export LD_LIBRARY_PATH=$work/lib$cxx_path$extra_path${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}

  local bin=$work/build
  {
    echo "== nvidia-smi"
    local smi
    smi=$(command -v nvidia-smi || ls /usr/local/nvidia/bin/nvidia-smi 2>/dev/null)
    if [[ -n $smi ]]; then
      "$smi" 2>&1 | head -20
      "$smi" --query-gpu=name,driver_version,memory.total,clocks.max.sm,clocks.sm --format=csv 2>&1
    else
      echo "(none)"
    fi
    echo "== unresolved libraries (none expected)"
    for f in "$bin/hfvis" "$bin/libhfvis_oiio.so" "$bin/bench/hfvis_bench" "$bin/tests/hfvis_tests" $nv; do
      ldd "$f" 2>&1 | grep -E 'not found|version .* not found' | sed "s|^|$(basename "$f"): |"
    done
    echo "== hfvis devices"
    timeout 120 "$bin/hfvis" devices 2>&1
    echo "rc=$?"
  } >> "$env_log" 2>&1
  cat "$env_log"

  local failed=0 n_pass=0 n_fail=0
  # ------------------------------------------------------------------ tests
  if [[ ${DEVICE_CHECK_TESTS:-1} != 0 ]]; then
    local cores shards timeout_s i
    cores=$(nproc)
    shards=${DEVICE_CHECK_SHARDS:-$(( cores < 12 ? cores : 12 ))}
    timeout_s=${DEVICE_CHECK_TEST_TIMEOUT:-240}
    echo "== kernel tests: $shards shards, ${timeout_s} s each, filter $KERNEL_TEST_FILTER" | tee -a "$tests_log"
    local t0=$SECONDS
    mkdir -p "$work/shards"
    for (( i = 0; i < shards; i++ )); do
      ( cd "$work" && GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX=$i timeout -k 10 "$timeout_s" \
          "$bin/tests/hfvis_tests" --gtest_filter="$KERNEL_TEST_FILTER" --gtest_color=no \
          > "$work/shards/$i.log" 2>&1
        echo $? > "$work/shards/$i.rc" ) &
    done
    wait
    local rc
    for (( i = 0; i < shards; i++ )); do
      rc=$(cat "$work/shards/$i.rc")
      { echo "======== shard $i of $shards: exit status $rc"; cat "$work/shards/$i.log"; } >> "$tests_log"
      case $rc in
        0) ;;
        1) failed=1 ;;
        124|137) failed=1; echo "shard $i: TIMED OUT after ${timeout_s} s (last test started:" \
                   "$(grep -E '^\[ RUN' "$work/shards/$i.log" | tail -1))" >> "$summary" ;;
        *) failed=1; echo "shard $i: CRASHED with exit status $rc; its last lines:" >> "$summary"
           tail -5 "$work/shards/$i.log" | sed 's/^/    /' >> "$summary" ;;
      esac
    done
    n_pass=$(grep -hcE '^\[       OK \]' "$work"/shards/*.log | awk '{s+=$1} END{print s+0}')
    n_fail=$(grep -hcE '^\[  FAILED  \] .*\([0-9]+ ms\)$' "$work"/shards/*.log | awk '{s+=$1} END{print s+0}')
    {
      echo "== kernel tests on: $(grep -m1 -A3 '^== hfvis devices' "$env_log" | grep '^\*' | sed 's/  */ /g')"
      echo "passed $n_pass, failed $n_fail, in $(( SECONDS - t0 )) s ($shards shards)"
      if (( n_fail > 0 )); then
        echo "== failed tests, with their messages"
        # Each failed test's block: from its [ RUN ] line to its [ FAILED ] line.
        awk '/^\[ RUN      \]/ {name = $4; block = $0 "\n"; next}
             name != "" {block = block $0 "\n"}
             /^\[  FAILED  \]/ && name != "" && index($0, name) {printf "%s\n", block; name = ""}
             /^\[       OK \]/ {name = ""}' "$work"/shards/*.log | cut -c1-400 | head -400
      fi
    } >> "$summary"
    echo "== tests took $(( SECONDS - t0 )) s" >> "$tests_log"
  fi

  # ------------------------------------------------------------------ benchmark
  if [[ ${DEVICE_CHECK_BENCH:-1} != 0 ]]; then
    local data=$work/data
    mkdir -p "$data"
    local py="" p
    for p in python3 /usr/bin/python3 python; do
      command -v "$p" > /dev/null && "$p" -c 'import numpy' 2> /dev/null && { py=$p; break; }
    done
    {
      echo "== inputs: data/make_data.py --fields fractal (${py:-no python with numpy}" \
           "$([[ -n $py ]] && "$py" -c 'import sys, numpy; print(sys.version.split()[0], "numpy", numpy.__version__)'))"
      for n in 1024 4096; do
        [[ -n $py ]] && "$py" "$root/data/make_data.py" --size "$n" --out "$data" --no-dem --no-env --fields fractal 2>&1
      done
      md5sum "$data"/*.exr
    } >> "$bench_log" 2>&1
    cat "$bench_log"
    local gpu=0
    grep -qE '^\* +[0-9]+ +GPU' "$env_log" && gpu=1
    local -a cmds=(
      "hfvis_bench run $data/fractal_1024.exr --method sweep -k 64 --outputs svf --reps 3"
      "hfvis_bench run $data/fractal_1024.exr --method sweep -k 64 --outputs angles --reps 3"
      "hfvis_bench run $data/fractal_4096.exr --method sweep -k 64 --outputs svf --reps 3"
    )
    if (( gpu )) || [[ ${DEVICE_CHECK_NAIVE:-0} == 1 ]]; then
      cmds+=("hfvis_bench run $data/fractal_1024.exr --method naive -k 64 --outputs svf --reps 3")
    fi
    cmds+=(
      "hfvis svf $data/fractal_1024.exr -o $work/svf_1024.exr -k 64"
      "hfvis svf $data/fractal_4096.exr -o $work/svf_4096.exr -k 64"
      "HFVIS_PROFILE=1 hfvis svf $data/fractal_4096.exr -o $work/svf_4096p.exr -k 64"
      "hfvis viewcount $data/fractal_1024.exr -o $work/viewcount_1024.exr -k 64"
    )
    local c exe TIMEFORMAT='   [time] wall %R s  user %U s  sys %S s'
    echo "== benchmark ($( ((gpu)) && echo GPU || echo CPU ) device; whole-command times include program start and kernel compilation)" >> "$summary"
    for c in "${cmds[@]}"; do
      local left=$(( budget + 20 - (SECONDS - start) ))
      if (( left < 30 )); then
        echo "skipped (budget of $budget s spent): $c" | tee -a "$bench_log" >> "$summary"
        continue
      fi
      echo "== $c" >> "$bench_log"
      exe=$c; exe=${exe/#hfvis_bench /$bin/bench/hfvis_bench }; exe=${exe/#hfvis /$bin/hfvis }
      exe=${exe/ hfvis / $bin/hfvis }
      { time ( cd "$work" && eval "timeout -k 5 $(( left < 150 ? left : 150 )) env $exe" ) ; } >> "$bench_log" 2>&1
      rc=$?
      (( rc == 0 )) || echo "   exit status $rc" >> "$bench_log"
      {
        echo "$ ${c//$data\//}" | sed "s|$work/||g"
        awk -v c="== $c" '$0 == c {on = 1; next} on && /^== / {on = 0} on' "$bench_log" |
          grep -E 'time|min|median|ns|\[time\]|profile|exit status|error' | head -12 | sed 's/^/    /'
      } >> "$summary"
    done
  fi
  echo "== total $(( SECONDS - start )) s" >> "$summary"
  cat "$summary"
  return $failed
}

case ${1:-} in
  bundle) bundle ;;
  run) run_checks ;;
  *) sed -n '2,/^set -uo/p' "$0" | sed '$d'; exit 2 ;;
esac
