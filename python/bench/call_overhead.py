"""Python call overhead against the C++ library call: the sky-view factor (K = 16) of a
1024 x 1024 fractal, hfvis.sky_view_factor from Python against hfvis_bench's timing of
computeHorizons on the same file, in rounds that alternate the two so that the machine's load
falls on both alike. Writes a Markdown table to stdout (bench/report/python.md holds one).

    build/python-venv/bin/python python/bench/call_overhead.py [--size 1024] [--rounds 3] [--reps 3]
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

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "build" / "bench" / "hfvis_bench"


def cpp_seconds(field, directions, reps):
    """The fastest of `reps` library calls, as hfvis_bench run measures them (after a warm-up)."""
    out = subprocess.run([str(BENCH), "run", str(field), "--method", "sweep", "-k", str(directions), "--outputs",
                          "svf", "--reps", str(reps)], capture_output=True, text=True, check=True).stdout
    return float(re.search(r"min ([0-9.]+) s", out).group(1))


def python_seconds(heights, directions, reps):
    """The fastest of `reps` calls from Python (the context already made and warm)."""
    best = float("inf")
    for _ in range(reps):
        start = time.perf_counter()
        hfvis.sky_view_factor(heights, directions=directions)
        best = min(best, time.perf_counter() - start)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--directions", type=int, default=16)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--reps", type=int, default=3)
    args = parser.parse_args()
    if not BENCH.exists():
        sys.exit(f"{BENCH} is missing: bash scripts/build.sh")
    with tempfile.TemporaryDirectory() as tmp:
        field = Path(tmp) / "fractal.exr"
        subprocess.run([str(BENCH), "field", "fractal", str(args.size), str(field)], check=True)
        heights = hfvis.read_height_field(field).heights
        hfvis.sky_view_factor(heights[:64, :64], directions=args.directions)  # the context and kernels, once
        rows = []
        for r in range(args.rounds):
            py = python_seconds(heights, args.directions, args.reps)
            cpp = cpp_seconds(field, args.directions, args.reps)
            rows.append((r + 1, py, cpp))
    device = hfvis.devices()[0]["name"]
    print(f"Sky-view factor, K = {args.directions}, {args.size} x {args.size} fractal; fastest of {args.reps} "
          f"calls per round; {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, {device}.\n")
    print("| round | Python call, s | C++ call, s | overhead |")
    print("| ---: | ---: | ---: | ---: |")
    for r, py, cpp in rows:
        print(f"| {r} | {py:.4f} | {cpp:.4f} | {100 * (py / cpp - 1):+.1f} % |")
    py, cpp = min(p for _, p, _ in rows), min(c for _, _, c in rows)
    print(f"| best | {py:.4f} | {cpp:.4f} | {100 * (py / cpp - 1):+.1f} % |")


if __name__ == "__main__":
    main()
