"""How far a chunked (Dask) run is from the in-memory one on a latitude / longitude grid, where
positions along the sweep's lines are whole units of ground length counted along the whole field's
lines (HeightField::origin carries the whole field's rows, docs/python.md#dask): the bundled
Jacksboro DEM on its 3 arc-second grid, chunked, every horizon sweep output (sky-view factor,
ambient occlusion, horizon angles and distances, sun shading, insolation) and intervisibility
(K = 16) within a maximum distance. Reports the pixels that differ and the largest difference.
Then the in-memory sky-view factor and horizon angles against a dense naive march (16 samples per
pixel along each ray, the same K and maximum distance): the sweep's accuracy on this grid. With
--save, writes the in-memory outputs to an .npz; with --against, also reports how far the
in-memory outputs are from such a file (another build's, e.g. before a change of the positions).
Writes Markdown to stdout.

    build/python-venv/bin/python python/bench/dask_latitude_longitude.py [--chunks 37 53] [--max-distance 800]
        [--save in_memory.npz] [--against other.npz]
"""

import argparse
from pathlib import Path

import numpy as np
import xarray as xr

import hfvis

ROOT = Path(__file__).resolve().parents[2]
# data/jacksboro_fault_dem.txt: 3 arc-second cells, row 0 north; the north-west corner.
WEST, NORTH, STEP = -84.41375, 36.732917, 0.0008333333333333334


def outputs(directions, max_distance):
    """Every output measured, by name: a function of the DataArray giving a DataArray."""
    o = {"directions": directions, "max_distance": max_distance}
    return {
        "sky-view factor": lambda a: hfvis.sky_view_factor(a, **o),
        "ambient occlusion": lambda a: hfvis.ambient_occlusion(a, **o),
        "horizon angles": lambda a: hfvis.horizon_angles(a, **o),
        "horizon distances": lambda a: hfvis.horizon_distances(a, **o),
        "sun shading (direct)": lambda a: hfvis.sun_shading(a, 200, 15, max_distance=max_distance).direct,
        "insolation (direct)": lambda a: hfvis.insolation(a, 36.6, -84.3, "2024-06-21T14:00:00Z",
                                                          "2024-06-21T16:00:00Z", step_minutes=30,
                                                          max_distance=max_distance).direct,
        "intervisibility (visible count)": lambda a: hfvis.intervisibility(a, **o).visible_count,
    }


def differences(got, want):
    """(pixels that differ, of them by more than 1e-6, largest difference); NaN on one side only
    counts as an infinite difference."""
    differ = ~((got == want) | (np.isnan(got) & np.isnan(want)))
    gap = np.where(differ, np.abs(got - want), 0.0)
    gap = np.where(np.isnan(gap), np.inf, gap)
    return int(differ.sum()), int((gap > 1e-6).sum()), float(gap.max())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--chunks", type=int, nargs=2, default=(37, 53), metavar=("ROWS", "COLUMNS"))
    parser.add_argument("--max-distance", type=float, default=800.0, help="metres")
    parser.add_argument("--directions", type=int, default=16)
    parser.add_argument("--save", type=Path, help="write the in-memory outputs to this .npz")
    parser.add_argument("--against", type=Path, help="compare the in-memory outputs with this .npz")
    args = parser.parse_args()
    heights = hfvis.read_height_field(ROOT / "data" / "jacksboro_fault_dem.exr").heights
    rows, cols = heights.shape
    lat = NORTH - STEP * (np.arange(rows) + 0.5)
    lon = WEST + STEP * (np.arange(cols) + 0.5)
    field = xr.DataArray(heights, dims=("lat", "lon"), coords={"lat": lat, "lon": lon})
    chunked = field.chunk({"lat": args.chunks[0], "lon": args.chunks[1]})
    print(f"Jacksboro DEM, {rows} x {cols} cells of 3 arc-seconds, chunks {args.chunks[0]} x {args.chunks[1]}, "
          f"K = {args.directions}, max_distance {args.max_distance:g} m.\n")
    print("| output | values | chunked: values that differ | by more than 1e-6 | largest difference |")
    print("| --- | ---: | ---: | ---: | ---: |")
    in_memory = {}
    for name, run in outputs(args.directions, args.max_distance).items():
        whole, parts = run(field).values, run(chunked).values
        in_memory[name] = whole
        differ, beyond, largest = differences(parts, whole)
        print(f"| {name} | {whole.size} | {differ} ({100.0 * differ / whole.size:.2f} %) | {beyond} | {largest:.2g} |")
    o = {"directions": args.directions, "max_distance": args.max_distance, "method": "naive", "samples_per_unit": 16}
    dense = {"sky-view factor": hfvis.sky_view_factor(field, **o).values,
             "horizon angles": hfvis.horizon_angles(field, **o).values}
    print("\nIn memory, against the naive march at 16 samples per pixel:\n")
    print("| output | mean difference | 99th percentile | largest difference |")
    print("| --- | ---: | ---: | ---: |")
    for name, reference in dense.items():
        gap = np.abs(in_memory[name] - reference)
        gap = gap[~np.isnan(gap)]
        print(f"| {name} | {gap.mean():.3g} | {np.percentile(gap, 99):.3g} | {gap.max():.3g} |")
    if args.save:
        np.savez(args.save, **in_memory)
    if args.against:
        other = np.load(args.against)
        print(f"\nIn memory, against {args.against.name}:\n")
        print("| output | values that differ | by more than 1e-6 | largest difference | mean difference |")
        print("| --- | ---: | ---: | ---: | ---: |")
        for name, whole in in_memory.items():
            differ, beyond, largest = differences(whole, other[name])
            mean = float(np.nanmean(np.abs(whole - other[name])))
            print(f"| {name} | {differ} ({100.0 * differ / whole.size:.2f} %) | {beyond} | {largest:.2g} | "
                  f"{mean:.2g} |")


if __name__ == "__main__":
    main()
