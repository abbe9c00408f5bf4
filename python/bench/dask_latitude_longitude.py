"""How far a chunked (Dask) run is from the in-memory one on a latitude / longitude grid, where the
horizon sweep's positions along a line are ground lengths summed from where the line enters each
block (the one case HeightField::origin does not make exact, docs/python.md; intervisibility's
whole units are): the bundled Jacksboro DEM on its 3
arc-second grid, chunked, sky-view factor and intervisibility (K = 16) within a maximum distance.
Reports the pixels that differ and the largest difference. Writes Markdown to stdout.

    build/python-venv/bin/python python/bench/dask_latitude_longitude.py [--chunks 37 53] [--max-distance 800]
"""

import argparse
from pathlib import Path

import numpy as np
import xarray as xr

import hfvis

ROOT = Path(__file__).resolve().parents[2]
# data/jacksboro_fault_dem.txt: 3 arc-second cells, row 0 north; the north-west corner.
WEST, NORTH, STEP = -84.41375, 36.732917, 0.0008333333333333334


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--chunks", type=int, nargs=2, default=(37, 53), metavar=("ROWS", "COLUMNS"))
    parser.add_argument("--max-distance", type=float, default=800.0, help="metres")
    parser.add_argument("--directions", type=int, default=16)
    args = parser.parse_args()
    heights = hfvis.read_height_field(ROOT / "data" / "jacksboro_fault_dem.exr").heights
    rows, cols = heights.shape
    lat = NORTH - STEP * (np.arange(rows) + 0.5)
    lon = WEST + STEP * (np.arange(cols) + 0.5)
    field = xr.DataArray(heights, dims=("lat", "lon"), coords={"lat": lat, "lon": lon})
    chunked = field.chunk({"lat": args.chunks[0], "lon": args.chunks[1]})
    options = {"directions": args.directions, "max_distance": args.max_distance}
    print(f"Jacksboro DEM, {rows} x {cols} cells of 3 arc-seconds, chunks {args.chunks[0]} x {args.chunks[1]}, "
          f"K = {args.directions}, max_distance {args.max_distance:g} m.\n")
    print("| output | pixels that differ | of them by more than 1e-6 | largest difference |")
    print("| --- | ---: | ---: | ---: |")
    runs = {
        "sky-view factor": lambda a: hfvis.sky_view_factor(a, **options),
        "intervisibility (visible count)": lambda a: hfvis.intervisibility(a, **options).visible_count,
    }
    for name, run in runs.items():
        whole, parts = run(field).values, run(chunked).values
        differ = ~((whole == parts) | (np.isnan(whole) & np.isnan(parts)))
        gap = np.where(differ, np.abs(whole - parts), 0.0)
        gap = np.where(np.isnan(gap), np.inf, gap)  # NaN on one side only
        print(f"| {name} | {differ.sum()} of {differ.size} ({100.0 * differ.mean():.2f} %) | {(gap > 1e-6).sum()} | "
              f"{gap.max():.2g} |")


if __name__ == "__main__":
    main()
