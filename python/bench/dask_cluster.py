"""A Dask run on a LocalCluster against the single process: the sky-view factor (K = 16, a
maximum distance of 50 cells) of an N x N fractal in memory, then chunked on a LocalCluster of
two worker processes of one thread each. Reports the chunk size, the halo's overhead (the pixels
the blocks compute, halos included, over the field's), the wall times, the largest difference
from the in-memory result, whether it has the in-memory result's bits, and each worker's peak
resident memory; then what telling a block where it lies costs (HeightField::origin, which makes
the bits equal): one block with its halo computed with and without its origin, alternated. Writes Markdown to stdout.

    build/python-venv/bin/python python/bench/dask_cluster.py [--size 2048] [--chunk 512]
"""

import argparse
import os
import resource
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr

import hfvis
from hfvis import _arrays, _dask

ROOT = Path(__file__).resolve().parents[2]


def peak_rss_mib():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=2048)
    parser.add_argument("--chunk", type=int, default=512)
    parser.add_argument("--max-distance", type=float, default=50.0)
    args = parser.parse_args()
    import distributed

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "noise.exr"
        subprocess.run([str(ROOT / "build" / "bench" / "hfvis_bench"), "field", "noise", str(args.size), str(path)],
                       check=True)
        heights = hfvis.read_height_field(path).heights
    n = args.size
    field = xr.DataArray(heights, dims=("y", "x"), coords={"y": np.arange(n) * -1.0, "x": np.arange(n) * 1.0})
    options = {"directions": 16, "max_distance": args.max_distance}
    hfvis.sky_view_factor(heights[:64, :64], directions=16)  # kernels built once (PoCL's cache then serves workers)
    start = time.perf_counter()
    whole = hfvis.sky_view_factor(field, **options)
    single = time.perf_counter() - start
    depth = _dask.halo(_arrays.geometry(), args.max_distance, "sky_view_factor")
    chunks = field.chunk(args.chunk).chunks
    computed = sum((min(c0 + c, n) - max(c0 - depth, 0)) for c0, c in _offsets(chunks[0])) * \
        sum((min(c0 + c, n) - max(c0 - depth, 0)) for c0, c in _offsets(chunks[1]))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            client.run(lambda: hfvis.sky_view_factor(np.zeros((64, 64), np.float32), directions=16))  # contexts
            lazy = hfvis.sky_view_factor(field.chunk(args.chunk), **options)
            start = time.perf_counter()
            chunked = lazy.compute()
            clustered = time.perf_counter() - start
            peaks = client.run(peak_rss_mib)
    diff = float(np.nanmax(np.abs(chunked.values - whole.values)))
    holes = np.isnan(whole.values)
    same = np.array_equal(np.isnan(chunked.values), holes) and np.array_equal(
        chunked.values[~holes].view(np.uint32), whole.values[~holes].view(np.uint32))
    print(f"Sky-view factor, K = 16, max_distance {args.max_distance:g} cells, {n} x {n} fractal; {os.cpu_count()} "
          f"CPUs, {hfvis.devices()[0]['name']}.\n")
    print("| run | chunks | halo | pixels computed / field | wall, s | largest difference | same bits | "
          "peak RSS per worker, MiB |")
    print("| --- | --- | ---: | ---: | ---: | ---: | --- | --- |")
    print(f"| one process, in memory | 1 | 0 | 1.00 | {single:.2f} | 0 | yes | {peak_rss_mib():.0f} (this process) |")
    print(f"| LocalCluster, 2 workers x 1 thread | {args.chunk} x {args.chunk} | {depth} | {computed / n / n:.2f} | "
          f"{clustered:.2f} | {diff:.1e} | {'yes' if same else 'no'} | {', '.join(f'{v:.0f}' for v in peaks.values())} |")
    block = np.ascontiguousarray(heights[args.chunk - depth:2 * args.chunk + depth, args.chunk - depth:2 * args.chunk + depth])
    geometry = _arrays.geometry()
    placed = dict(geometry, origin=[args.chunk - depth, args.chunk - depth, n, n, float(np.nanmin(heights))])
    times = {False: [], True: []}
    for _ in range(5):
        for told in (False, True):
            start = time.perf_counter()
            _arrays.compute("sky_view_factor", block, placed if told else geometry, options)
            times[told].append(time.perf_counter() - start)
    plain, told = np.median(times[False]), np.median(times[True])
    print(f"\nOne {block.shape[0]} x {block.shape[1]} block (a chunk and its halo), median of 5 alternated: "
          f"{plain:.3f} s without its origin, {told:.3f} s with it ({told / plain:.2f}x).")


def _offsets(sizes):
    at = 0
    for size in sizes:
        yield at, size
        at += size


if __name__ == "__main__":
    main()
