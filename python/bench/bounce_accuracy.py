"""The one-bounce gather (`hfvis.bounce`) against a dense reference of its own definition: for
each receiver, the exit radiance of the first surface point each ray meets, weighted by the
projected solid angle, integrated over 1440 azimuths with the bilinear surface and the bilinear
radiance sampled every 1/16 pixel along each ray (the sky adds nothing). Fields: a synthetic city
(blocks with sharp walls and pits of one pixel) and a crop of the bundled Jacksboro DEM, each
with a white-noise radiance (every pixel its own) and a smooth one; receivers: 120 random pixels
and every pit of one pixel. Writes a Markdown table: the mean and the 99th percentile of
|E - reference| / mean reference over the receivers, at K = 16, 64 and 256 (the pits apart).

    build/python-venv/bin/python python/bench/bounce_accuracy.py

The reference takes a few minutes on two cores. `HFVIS_KERNEL_DIR` compares other kernels on the
same reference.
"""

import pathlib
import sys

import numpy as np

import hfvis

REFERENCE_AZIMUTHS, REFERENCE_STEP = 1440, 1.0 / 16.0


def city(size=96, seed=1):
    rng = np.random.default_rng(seed)
    h = np.zeros((size, size), np.float32)
    for _ in range(40):
        r, c = rng.integers(0, size - 6, 2)
        w = rng.integers(2, 8)
        h[r:r + w, c:c + w] = rng.uniform(5, 30)
    for _ in range(30):
        r, c = rng.integers(1, size - 1, 2)
        h[r, c] -= 10.0
    return h


def dem_crop(size=96):
    root = pathlib.Path(__file__).resolve().parents[2]
    field = hfvis.read_height_field(str(root / "data" / "jacksboro_fault_dem.exr"))
    heights = np.asarray(field.heights, np.float64)[100:100 + size, 150:150 + size]
    return (heights / 80.0).astype(np.float32)  # in cells of about 80 m: one ground unit a cell


def bilinear(a, x, y):
    h, w = a.shape
    x0 = np.clip(np.floor(x).astype(np.int64), 0, w - 2)
    y0 = np.clip(np.floor(y).astype(np.int64), 0, h - 2)
    fx, fy = x - x0, y - y0
    return ((a[y0, x0] * (1 - fx) + a[y0, x0 + 1] * fx) * (1 - fy) +
            (a[y0 + 1, x0] * (1 - fx) + a[y0 + 1, x0 + 1] * fx) * fy)


def normal(h, c, r):
    """The pixel normal of hfvis (kernels/shared/surface_normal.cl), cells of 1."""
    height, width = h.shape
    s = np.zeros(3)
    for q in range(4):
        sx, sy = (1 if q & 1 else -1), (1 if q & 2 else -1)
        if 0 <= c + sx < width and 0 <= r + sy < height:
            s += (-(h[r, c + sx] - h[r, c]) / sx, -(h[r + sy, c] - h[r, c]) / sy, 1.0)
    return s / np.linalg.norm(s)


def reference(h, radiance, c, r):
    height, width = h.shape
    n = normal(h, c, r)
    phi = (np.arange(REFERENCE_AZIMUTHS) + 0.5) * (2 * np.pi / REFERENCE_AZIMUTHS)
    wedge = 2 * np.pi / REFERENCE_AZIMUTHS
    dx, dy = np.cos(phi), np.sin(phi)
    # each ray's length to the field's border
    with np.errstate(divide="ignore"):
        tx = np.where(dx > 0, (width - 1 - c) / dx, np.where(dx < 0, -c / dx, np.inf))
        ty = np.where(dy > 0, (height - 1 - r) / dy, np.where(dy < 0, -r / dy, np.inf))
    reach = np.minimum(tx, ty)
    t = np.arange(1, int(reach.max() / REFERENCE_STEP) + 1) * REFERENCE_STEP
    x = c + dx[:, None] * t[None, :]
    y = r + dy[:, None] * t[None, :]
    inside = t[None, :] <= reach[:, None]
    x, y = np.where(inside, x, c), np.where(inside, y, r)
    elevation = np.where(inside, np.arctan2(bilinear(h, x, y) - h[r, c], t[None, :]), -np.pi / 2)
    light = bilinear(radiance, x, y)
    toward = n[0] * dx + n[1] * dy
    nz_term, nh_term = n[2] * wedge / 2, toward * 2 * np.sin(wedge / 2)
    tangent = np.arctan2(-nh_term, 2 * nz_term)

    def g(theta):
        th = np.maximum(theta, tangent[:, None])
        return nz_term * np.sin(th) ** 2 + nh_term[:, None] * 0.5 * (th + np.sin(th) * np.cos(th))

    top = np.maximum.accumulate(elevation, axis=1)
    below = np.concatenate([np.full((len(phi), 1), -np.pi / 2), top[:, :-1]], axis=1)
    return float(np.sum(light * (g(top) - g(below))))


def pits(h):
    inner = h[1:-1, 1:-1]
    lower = np.ones_like(inner, bool)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            if dr or dc:
                lower &= inner < h[1 + dr:h.shape[0] - 1 + dr, 1 + dc:h.shape[1] - 1 + dc]
    rows, cols = np.nonzero(lower)
    return list(zip(cols + 1, rows + 1))


def main():
    rng = np.random.default_rng(7)
    print("| field | radiance | receivers | K | mean error | p99 error |")
    print("| --- | --- | --- | ---: | ---: | ---: |")
    for field_name, h in (("city, 96 x 96", city()), ("Jacksboro DEM crop, 96 x 96", dem_crop())):
        size = h.shape[0]
        yy, xx = np.mgrid[0:size, 0:size]
        radiances = {
            "white noise": rng.uniform(0.5, 2.0, h.shape).astype(np.float32),
            "smooth": (1.0 + 0.5 * np.sin(xx / 7.0) * np.cos(yy / 11.0)).astype(np.float32),
        }
        random = [(int(c), int(r)) for c, r in rng.integers(1, size - 1, (120, 2))]
        groups = {"random": random, "one-pixel pits": pits(h)}
        for radiance_name, radiance in radiances.items():
            h64, rad64 = h.astype(np.float64), radiance.astype(np.float64)
            expected = {name: np.array([reference(h64, rad64, c, r) for c, r in where])
                        for name, where in groups.items() if where}
            for k in (16, 64, 256):
                e = np.asarray(hfvis.bounce(h, radiance, directions=k), np.float64)
                for name, where in groups.items():
                    if not where:
                        continue
                    got = np.array([e[r, c] for c, r in where])
                    error = np.abs(got - expected[name]) / expected[name].mean()
                    print(f"| {field_name} | {radiance_name} | {name} ({len(where)}) | {k} | "
                          f"{error.mean():.4f} | {np.percentile(error, 99):.4f} |")
                    sys.stdout.flush()


if __name__ == "__main__":
    main()
