"""Grazing samples on planes: the visible count (intervisibility, hull tree and naive march) and
the viewshed of an eye on the surface, on a flat plane and on tilted ones, where under the tie
rule (grazing samples see) every sample of the plane is visible from every other. The samples'
float heights are rounded, which tips collinear samples of a tilted plane above or below one
another's sight lines; the visible counts, the viewshed and region visibility forgive that
rounding (docs/ALGORITHMS.md, "Grazing samples and the heights' rounding"). A second table shows
what the tolerance also takes as ties: the Earth's drop between neighbouring samples on tilted
planes, and sub-millimetre noise on a field at 1000 m (with and without one pixel at 0, which
moved the heights a thousand metres above the base while the base was the lowest height). A third gives the viewshed and a region pair with
both ends on the surface (heights 0) on planes at 8848 m and far from 0, and on the same plane with
a wall of 2 cm (still hiding). A fourth shows the price of that tolerance: a sight line that
grazes a wall top beside the eye forgives it by a few units in the last place there, which lets a
target far beyond lie lower by as much times their distances' ratio, so the field's datum moves
the edge of what is seen. A fifth times `intervisibility` on a tilted plane against noise: the
hull tree walks each horizon's forgiven stretch sample by sample, and on a plane every stretch
runs back to the line's start. Writes Markdown tables to stdout.

    build/python-venv/bin/python python/bench/tilted_plane.py
"""

import time

import numpy as np

import hfvis

WIDTH, HEIGHT, CELL = 48, 64, 10.0


def main():
    columns = np.arange(WIDTH)[None, :] * np.ones((HEIGHT, 1))
    planes = {
        "flat (h = 100)": 100.0 + 0.0 * columns,
        "tilted, whole-number heights (h = 100 + column)": 100.0 + columns,
        "tilted (h = 100 + 2.6255 column)": 100.0 + 2.6255 * columns,
    }
    print("| plane | K | hull tree: mean count | naive: mean count | viewshed from (10, 10), eye and target "
          "at 0: visible share |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for name, heights in planes.items():
        field = heights.astype(np.float32)
        seen = float(np.nanmean(hfvis.viewshed(field, (10, 10), cell_size=CELL, observer_height=0.0)))
        for k in (4, 8, 16):
            counts = [float(np.nanmean(hfvis.intervisibility(field, directions=k, cell_size=CELL,
                                                             method=method).visible_count))
                      for method in ("hull_tree", "naive")]
            print(f"| {name} | {k} | {counts[0]:.1f} | {counts[1]:.1f} | {seen:.3f} |")
    print()
    print("| field (K = 8) | hull tree | naive |")
    print("| --- | ---: | ---: |")
    cols = np.arange(64)[None, :] * np.ones((64, 1))
    earth = 1.0 / (2.0 * 6371000.0)  # the drop per ground unit squared, no refraction
    for grade in (0.0, 0.1, 0.3):
        field = (100.0 + grade * 30.0 * cols).astype(np.float32)
        counts = [float(np.nanmean(hfvis.intervisibility(field, directions=8, cell_size=30.0, curvature=earth,
                                                         method=method).visible_count))
                  for method in ("hull_tree", "naive")]
        print(f"| 64 x 64, cells of 30, h = 100 + {grade * 30:g} column, the Earth's drop: mean count | "
              f"{counts[0]:.2f} | {counts[1]:.2f} |")
    noise = (1000.0 + np.random.default_rng(0).uniform(0.0, 0.002, (128, 128))).astype(np.float32)
    for pit in (False, True):
        field = noise.copy()
        if pit:
            field[0, 0] = 0.0
        counts = [float(np.nanmedian(hfvis.intervisibility(field, directions=8, cell_size=1.0,
                                                           method=method).visible_count))
                  for method in ("hull_tree", "naive")]
        print(f"| 128 x 128, 1000 + U(0, 2 mm){', one pixel at 0' if pit else ''}: median count | "
              f"{counts[0]:.1f} | {counts[1]:.1f} |")
    print()
    print("| 128 x 96 field, cells of 1 | viewshed from (64, 48), eye and targets at 0: visible share | "
          "region pair (4, 4)-(40, 91) to (88, 4)-(124, 91), 1024 x 1024 samples at 0: clear share |")
    print("| --- | ---: | ---: |")
    x = np.arange(128)[None, :] * np.ones((96, 1))
    y = np.arange(96)[:, None] * np.ones((1, 128))
    surfaces = {
        "8848 + 0.001 column": 8848.0 + 0.001 * x,
        "100 + 2.6255 column": 100.0 + 2.6255 * x,
        "3e5 + 1.7 column - 0.9 row": 3e5 + 1.7 * x - 0.9 * y,
        "8848 + 0.001 column, a wall of 2 cm at column 100": 8848.0 + 0.001 * x + 0.02 * (x == 100),
    }
    for name, heights in surfaces.items():
        field = heights.astype(np.float32)
        seen = float(np.nanmean(hfvis.viewshed(field, (64, 48), observer_height=0.0)))
        pair = hfvis.region_pair_visibility(field, (4, 4, 40, 91), (88, 4, 124, 91), samples=1024,
                                            source_height=0.0, receiver_height=0.0)
        print(f"| {name} | {seen:.4f} | {pair.visible_fraction:.4f} |")
    print()
    print("| 300 x 21 field, cells of 1: ground flat to column 100, then rising 1 cm a column; a wall 1.7 high at "
          "column 5; the eye 1.7 above (0, 10), level with the wall's top | first column seen past the wall "
          "(exactly: 270) |")
    print("| --- | ---: |")
    cols = np.arange(300)[None, :] * np.ones((21, 1))
    ground = np.where(cols <= 100, 0.0, 0.01 * (cols - 100)) + np.where(cols == 5, 1.7, 0.0)
    for base in (0.0, 1000.0, 4000.0, 8848.0):
        seen = np.asarray(hfvis.viewshed((base + ground).astype(np.float32), (0, 10), observer_height=1.7))[10]
        past = [c for c in range(6, 300) if seen[c] == 1.0]
        print(f"| heights {base:g} + that | {past[0] if past else 'none'} |")
    print()
    print("| N x N, K = 16 | tilted plane 0.3 column + 0.1 row: seconds | normal noise: seconds | ratio |")
    print("| --- | ---: | ---: | ---: |")
    for n in (128, 256, 512):
        rows, columns = np.mgrid[0:n, 0:n].astype(np.float64)
        fields = [(0.3 * columns + 0.1 * rows).astype(np.float32),
                  np.random.default_rng(1).normal(0.0, 1.0, (n, n)).astype(np.float32)]
        seconds = []
        for field in fields:
            hfvis.intervisibility(field[:8, :8], directions=16)  # (the kernels built before the timing)
            start = time.perf_counter()
            hfvis.intervisibility(field, directions=16)
            seconds.append(time.perf_counter() - start)
        print(f"| {n} | {seconds[0]:.2f} | {seconds[1]:.2f} | {seconds[0] / seconds[1]:.1f} |")


if __name__ == "__main__":
    main()
