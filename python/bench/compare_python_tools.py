"""hfvis against the Python tools terrain analysts use, from one Python process on the same
arrays: the sky-view factor against RVT's (rvt.vis.sky_view_factor, 16 directions, radius 10 and
100 pixels) and a viewshed against xarray-spatial's (xrspatial.viewshed). Times are the faster
of two calls (the first also compiles numba's and hfvis's kernels); agreement is with hfvis's
result at the same radius (the mean absolute difference of the sky-view factors) and, for the
viewshed, the Jaccard index of the visible sets. Writes Markdown to stdout.

Needs rvt-py and xarray-spatial beside hfvis (scripts/bench_python_tools.sh sets up
build/bench-venv and runs this):
    build/bench-venv/bin/python python/bench/compare_python_tools.py [--size 1024]
"""

import argparse
import importlib.metadata as md
import os
import platform
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr

import hfvis

ROOT = Path(__file__).resolve().parents[2]


def best_of_two(call):
    times = []
    for _ in range(2):
        start = time.perf_counter()
        out = call()
        times.append(time.perf_counter() - start)
    return min(times), out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=1024)
    args = parser.parse_args()
    import rvt.vis
    import xrspatial

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "noise.exr"
        subprocess.run([str(ROOT / "build" / "bench" / "hfvis_bench"), "field", "noise", str(args.size), str(path)],
                       check=True)
        dem = hfvis.read_height_field(path).heights.astype(np.float64)
    n = args.size
    print(f"{n} x {n} fractal (hfvis_bench's 'noise' field), cell size 1; {platform.machine()}, {os.cpu_count()} "
          f"CPUs, hfvis on {hfvis.devices()[0]['name']}; the faster of two calls.\n")
    print("| what | tool | time, s | hfvis, s | hfvis faster | agreement with hfvis |")
    print("| --- | --- | ---: | ---: | ---: | --- |")
    for radius in (10, 100):
        t_rvt, r = best_of_two(lambda: rvt.vis.sky_view_factor(dem, resolution=1.0, svf_n_dir=16, svf_r_max=radius,
                                                               compute_opns=False)["svf"])
        t_ours, ours = best_of_two(lambda: hfvis.sky_view_factor(dem, directions=16, max_distance=radius))
        inner = (slice(radius, -radius), slice(radius, -radius))  # RVT pads the edges
        diff = np.nanmean(np.abs(np.asarray(r)[inner] - ours[inner]))
        print(f"| sky-view factor, K = 16, radius {radius} | RVT {md.version('rvt-py')}"
              f" | {t_rvt:.2f} | {t_ours:.2f} | {t_rvt / t_ours:.1f}x | mean abs difference {diff:.4f} |")
    t_all, _ = best_of_two(lambda: hfvis.sky_view_factor(dem, directions=16))
    print(f"| sky-view factor, K = 16, no radius limit | hfvis only | | {t_all:.2f} | | |")
    raster = xr.DataArray(dem, dims=("y", "x"), coords={"y": np.arange(n, dtype=float), "x": np.arange(n, dtype=float)})
    col, row = n // 2 + 7, n // 3 + 5
    t_xs, seen = best_of_two(lambda: xrspatial.viewshed(raster, x=float(col), y=float(row), observer_elev=10.0,
                                                        target_elev=0.0))
    t_ours, ours = best_of_two(lambda: hfvis.viewshed(dem, (col, row), observer_height=10.0))
    theirs = np.asarray(seen) > -1  # xarray-spatial: the viewing angle where visible, -1 where not
    mine = ours == 1
    jaccard = (theirs & mine).sum() / max(1, (theirs | mine).sum())
    print(f"| viewshed, observer 10 above ({col}, {row}) | xarray-spatial {md.version('xarray-spatial')} | {t_xs:.2f} | "
          f"{t_ours:.2f} | {t_xs / t_ours:.1f}x | Jaccard {jaccard:.4f} of the visible sets ({theirs.mean():.3f} / "
          f"{mine.mean():.3f} visible) |")


if __name__ == "__main__":
    main()
