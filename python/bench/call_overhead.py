"""Python call overhead against the C++ library call: the sky-view factor (K = 16) of a
1024 x 1024 fractal, hfvis.sky_view_factor from Python against (1) the bare library call from the
same process (hfvis._core.horizons on a field made beforehand), alternated call by call, and (2)
hfvis_bench's timing of computeHorizons on the same file in its own process, in rounds that
alternate with the Python calls so that the machine's load falls on all alike. Writes a Markdown
table to stdout (bench/report/python.md holds one).

    build/python-venv/bin/python python/bench/call_overhead.py [--size 1024] [--rounds 5] [--reps 3]
"""

import argparse
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import hfvis
from hfvis import _arrays, _core

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "build" / "bench" / "hfvis_bench"


def cpp_seconds(field, directions, reps):
    """The fastest of `reps` library calls, as hfvis_bench run measures them (after a warm-up)."""
    out = subprocess.run([str(BENCH), "run", str(field), "--method", "sweep", "-k", str(directions), "--outputs",
                          "svf", "--reps", str(reps)], capture_output=True, text=True, check=True).stdout
    return float(re.search(r"min ([0-9.]+) s", out).group(1))


def python_seconds(heights, directions, reps):
    """The fastest of `reps` calls of hfvis.sky_view_factor from Python, and of the bare library
    call hfvis._core.horizons on a field made beforehand (no conversion of the heights, no
    result wrapping), alternated call by call in this process."""
    field = _core.height_field(heights, **_arrays.geometry())
    options = _core.HorizonOptions()
    options.directions = directions
    best_py = best_core = float("inf")
    for _ in range(reps):
        start = time.perf_counter()
        hfvis.sky_view_factor(heights, directions=directions)
        best_py = min(best_py, time.perf_counter() - start)
        start = time.perf_counter()
        _core.horizons(field, options, angles=False, distances=False, sky_view_factor=True, ambient_occlusion=False,
                       device="", progress=None)
        best_core = min(best_core, time.perf_counter() - start)
    return best_py, best_core


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--directions", type=int, default=16)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--reps", type=int, default=3)
    args = parser.parse_args()
    if not BENCH.exists():
        sys.exit(f"{BENCH} is missing: bash scripts/build.sh")
    with tempfile.TemporaryDirectory() as tmp:
        field = Path(tmp) / "fractal.exr"
        subprocess.run([str(BENCH), "field", "noise", str(args.size), str(field)], check=True)
        heights = hfvis.read_height_field(field).heights
        hfvis.sky_view_factor(heights[:64, :64], directions=args.directions)  # the context and kernels, once
        rows = []
        for r in range(args.rounds):
            py, core = python_seconds(heights, args.directions, args.reps)
            cpp = cpp_seconds(field, args.directions, args.reps)
            rows.append((r + 1, py, core, cpp))
    device = hfvis.devices()[0]["name"]
    print(f"Sky-view factor, K = {args.directions}, {args.size} x {args.size} fractal (the synthetic 'noise' field); fastest of {args.reps} "
          f"calls per round; {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, {device}.\n")
    print("| round | hfvis.sky_view_factor, s | library call in Python, s | hfvis_bench (C++), s | over the library call | over hfvis_bench |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: |")
    for r, py, core, cpp in rows:
        print(f"| {r} | {py:.4f} | {core:.4f} | {cpp:.4f} | {100 * (py / core - 1):+.1f} % | {100 * (py / cpp - 1):+.1f} % |")
    py, core, cpp = (min(row[i] for row in rows) for i in (1, 2, 3))
    print(f"| fastest of all rounds | {py:.4f} | {core:.4f} | {cpp:.4f} | {100 * (py / core - 1):+.1f} % | "
          f"{100 * (py / cpp - 1):+.1f} % |")
    over_core = sorted(row[1] / row[2] for row in rows)
    over_cpp = sorted(row[1] / row[3] for row in rows)
    middle = len(rows) // 2
    print(f"| median of the rounds' ratios | | | | {100 * (over_core[middle] - 1):+.1f} % | "
          f"{100 * (over_cpp[middle] - 1):+.1f} % |")

if __name__ == "__main__":
    main()
