"""Grazing samples on planes: the visible count (intervisibility, hull tree and naive march) and
the viewshed of an eye on the surface, on a flat plane and on tilted ones, where under the tie
rule (grazing samples see) every sample of the plane is visible from every other. The rule is
decided exactly on the samples' float heights, whose rounding tips collinear samples of a tilted
plane above or below one another's sight lines (docs/ALGORITHMS.md, "Grazing samples on tilted
planes"). Writes a Markdown table to stdout.

    build/python-venv/bin/python python/bench/tilted_plane.py
"""

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


if __name__ == "__main__":
    main()
