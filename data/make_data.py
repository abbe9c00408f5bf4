#!/usr/bin/python3
"""Generate the bundled hfvis test / benchmark height fields.

Synthetic fields after V. Timonen, "Low-Complexity Intervisibility in Height
Fields" (2013), Figure 7 / Table 1: fractal terrain, brick surface, sine grid,
blocks; optionally also the i.i.d. random field of its Figure 8 ("extent"
scaling).  Plus two real DEMs converted from matplotlib's sample data.

Every output is a single-channel float32 OpenEXR image (channel "Y"), ZIP
compressed.  Row 0 is the top (north) row, column 0 the left (west) column.

Synthetic fields have heights in pixel units (ground cell size 1).  The DEMs
keep metres; their ground cell sizes are stored as EXR string attributes
"hfvis:cell_size_x" / "hfvis:cell_size_y" and in a sidecar .txt.

Usage (from the repository root):
    /usr/bin/python3 data/make_data.py                      # committed set, N=256
    /usr/bin/python3 data/make_data.py --size 4096 --out /tmp/hfvis-bench --no-dem

Deterministic: every random draw comes from numpy.random.default_rng with a
fixed seed, and the built-in EXR writer emits no time stamps, so re-running
reproduces the committed files byte for byte (same numpy/zlib behaviour).
Needs only numpy; OpenImageIO's Python module is used only with --writer oiio.
"""

import argparse
import math
import os
import struct
import sys
import time
import zlib
from concurrent.futures import ThreadPoolExecutor

import numpy as np

SAMPLE_DIR = "/usr/share/matplotlib/mpl-data/sample_data"

SEED_FRACTAL = 20130001
SEED_BRICKS = 20130002
SEED_BLOCKS = 20130004
SEED_RANDOM = 20130005


# ---------------------------------------------------------------------------
# EXR output
# ---------------------------------------------------------------------------

def _attr(name, typ, payload):
    return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(payload)) + payload


def _zip_block(raw):
    """OpenEXR ZIP(S) compression of one chunk: byte de-interleave, delta predictor, zlib."""
    b = np.frombuffer(raw, dtype=np.uint8)
    t = np.concatenate([b[0::2], b[1::2]])
    d = t.copy()
    d[1:] = t[1:] - t[:-1] + np.uint8(128)       # uint8 arithmetic wraps mod 256
    out = zlib.compress(d.tobytes(), 6)
    return out if len(out) < len(raw) else raw    # stored raw when it would not shrink


def write_exr_builtin(path, img, attrs, names=("Y",)):
    """Minimal single-part scanline EXR writer: FLOAT channels (one "Y", or `names` for an
    (h, w, len(names)) image), ZIP (16 lines)."""
    img = np.ascontiguousarray(img, dtype="<f4")
    if img.ndim == 2:
        img = img[:, :, None]
    h, w, nc = img.shape
    if nc != len(names):
        raise ValueError("%d channels, %d names" % (nc, len(names)))
    order = sorted(range(nc), key=lambda c: names[c])  # EXR keeps channels sorted by name
    lines_per_chunk = 16
    hdr = [b"\x76\x2f\x31\x01", struct.pack("<i", 2)]
    chlist = b"".join(names[c].encode() + b"\0" + struct.pack("<i", 2) + b"\0\0\0\0" +
                      struct.pack("<ii", 1, 1) for c in order) + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header_attrs = [
        ("channels", "chlist", chlist),
        ("compression", "compression", bytes([3])),          # ZIP_COMPRESSION
        ("dataWindow", "box2i", box),
        ("displayWindow", "box2i", box),
        ("lineOrder", "lineOrder", bytes([0])),              # INCREASING_Y
        ("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        ("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        ("screenWindowWidth", "float", struct.pack("<f", 1.0)),
    ]
    for k in sorted(attrs):
        header_attrs.append((k, "string", str(attrs[k]).encode()))
    for name, typ, payload in header_attrs:
        hdr.append(_attr(name, typ, payload))
    hdr.append(b"\0")
    header = b"".join(hdr)
    nchunks = (h + lines_per_chunk - 1) // lines_per_chunk
    starts = [c * lines_per_chunk for c in range(nchunks)]
    # Each scanline holds its channels one after another, in the sorted order.
    planar = np.ascontiguousarray(img[:, :, order].transpose(0, 2, 1))
    # zlib releases the GIL, so big images compress on all cores; order is kept.
    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        blocks = list(pool.map(lambda y0: _zip_block(planar[y0:y0 + lines_per_chunk].tobytes()),
                               starts))
    chunks = [struct.pack("<ii", y0, len(data)) + data for y0, data in zip(starts, blocks)]
    offsets = []
    pos = len(header) + 8 * nchunks
    for ch in chunks:
        offsets.append(pos)
        pos += len(ch)
    with open(path, "wb") as f:
        f.write(header)
        f.write(struct.pack("<%dQ" % nchunks, *offsets))
        for ch in chunks:
            f.write(ch)


def clear_sky(height=128, sun_compass=240.0, sun_elevation=25.0):
    """A synthetic HDR environment for the lighting examples, equirectangular (row 0 at the
    zenith; column fraction u looks toward compass azimuth 360 u): a blue sky brightening
    toward the horizon and around the sun, a sun of one pixel (1.4 degrees) whose irradiance at normal
    incidence is 8 times the sky's on flat ground, and dark ground below the horizon."""
    w = 2 * height
    zen = (np.arange(height) + 0.5) * math.pi / height
    az = (np.arange(w) + 0.5) * 2 * math.pi / w
    Z, A = np.meshgrid(zen, az, indexing="ij")
    sz, sa = math.radians(90.0 - sun_elevation), math.radians(sun_compass)
    # Angle from the sun.
    cosg = np.cos(Z) * math.cos(sz) + np.sin(Z) * math.sin(sz) * np.cos(A - sa)
    gamma = np.arccos(np.clip(cosg, -1.0, 1.0))
    up = Z < math.pi / 2
    t = np.clip(Z / (math.pi / 2), 0.0, 1.0)[:, :, None]  # 0 zenith .. 1 horizon
    zenith, horizon = np.array([0.25, 0.45, 0.95]), np.array([0.85, 0.90, 1.0])
    sky = (1 - t) * zenith + t * horizon
    sky = sky * (1.0 + 2.5 * np.exp(-gamma / 0.25))[:, :, None]          # circumsolar glow
    ground = np.array([0.10, 0.08, 0.06])
    img = np.where(up[:, :, None], sky, ground)
    # Sky irradiance on flat ground: sum over the upper rows of L cos(theta) dOmega.
    dphi, dtheta = 2 * math.pi / w, math.pi / height
    omega = np.sin(Z) * dtheta * dphi
    e_sky = float((img[:, :, 1] * np.cos(Z) * omega * up).sum())
    r = int(sz / dtheta)
    c = int(sa / dphi)
    img[r, c, :] += (8.0 * e_sky / omega[r, c]) * np.array([1.0, 0.95, 0.85])
    return img.astype(np.float32)


def write_exr_oiio(path, img, attrs):
    import OpenImageIO as oiio
    h, w = img.shape
    img = np.ascontiguousarray(img, dtype=np.float32).reshape(h, w, 1)
    spec = oiio.ImageSpec(w, h, 1, "float")
    spec.channelnames = ("Y",)
    spec.attribute("compression", "zip")
    for k in sorted(attrs):
        spec.attribute(k, str(attrs[k]))
    out = oiio.ImageOutput.create(path)
    if not out or not out.open(path, spec):
        raise RuntimeError("OpenImageIO cannot write %s: %s" % (path, oiio.geterror()))
    ok = out.write_image(img)
    out.close()
    if not ok:
        raise RuntimeError("OpenImageIO failed writing %s" % path)


WRITERS = {"builtin": write_exr_builtin, "oiio": write_exr_oiio}


# ---------------------------------------------------------------------------
# Synthetic fields (heights in pixel units)
# ---------------------------------------------------------------------------

def fractal(n, seed=SEED_FRACTAL, k=1.0 / 6):
    """Midpoint-displacement fractal terrain (Timonen 2013, Sec. 6 / Fig. 8).

    Built on the (M+1)^2 lattice, M = next power of two >= n, then cropped to
    n x n.  The 4 corners start at 0.  Level l has spacing s = M / 2^l pixels;
    every time the resolution doubles, the new points are interpolated
    (diamond-square: cell centres from their 4 corners, then edge midpoints
    from their 2 end points and adjacent centres) plus a uniform value in
    [-k*s, k*s], i.e. with half the previous range.  Level l always uses rng
    seed (seed, l) and the same number of draws, so for powers of two the
    field of size 2n is exactly 2 * (field of size n) on the even pixels,
    with one more level of detail.
    With k = 1/6 the relief (max - min) is about n/8 (~30 px at n=256; over
    seeds it ranges ~0.07n..0.15n).
    """
    m = 1
    while m < n:
        m *= 2
    levels = int(round(math.log2(m)))
    z = np.zeros((2, 2))                   # corners at 0: no overall tilt
    for lev in range(1, levels + 1):
        s = m >> lev                       # new spacing in pixels
        c = z.shape[0] - 1                 # cells per side at the previous level
        rng = np.random.default_rng([seed, lev])
        r_edge_h = rng.uniform(-1.0, 1.0, size=(c + 1, c))      # midpoints of horizontal edges
        r_edge_v = rng.uniform(-1.0, 1.0, size=(c, c + 1))      # midpoints of vertical edges
        r_cent = rng.uniform(-1.0, 1.0, size=(c, c))            # cell centres
        amp = k * s
        # diamond step: cell centres from their 4 corners
        cen = 0.25 * (z[:-1, :-1] + z[:-1, 1:] + z[1:, :-1] + z[1:, 1:]) + amp * r_cent
        # square step: edge midpoints from their 2 end points and the 1-2 adjacent centres
        pad = np.zeros((c + 2, c + 2))
        pad[1:-1, 1:-1] = cen
        cnt = np.zeros((c + 2, c + 2))
        cnt[1:-1, 1:-1] = 1.0
        eh = (z[:, :-1] + z[:, 1:] + pad[:-1, 1:-1] + pad[1:, 1:-1]) \
            / (2.0 + cnt[:-1, 1:-1] + cnt[1:, 1:-1]) + amp * r_edge_h
        ev = (z[:-1, :] + z[1:, :] + pad[1:-1, :-1] + pad[1:-1, 1:]) \
            / (2.0 + cnt[1:-1, :-1] + cnt[1:-1, 1:]) + amp * r_edge_v
        nz = np.empty((2 * c + 1, 2 * c + 1))
        nz[0::2, 0::2] = z
        nz[0::2, 1::2] = eh
        nz[1::2, 0::2] = ev
        nz[1::2, 1::2] = cen
        z = nz
    return z[:n, :n].astype(np.float32)


def bricks(n, seed=SEED_BRICKS):
    """Running-bond brick wall seen from the front, lying flat.

    At n=256: bricks 32x16 px incl. 2 px mortar joints, brick tops ~4 px above
    the mortar (+-0.5 px per brick), 1.5 px bevels.  All lengths scale with n/256.
    """
    sc = n / 256.0
    bw, bh, mortar, bevel = 32 * sc, 16 * sc, 2 * sc, 1.5 * sc
    c = np.arange(n) + 0.5                                 # pixel centres
    row = np.floor(c / bh).astype(int)                     # brick row of each pixel row
    d_y = np.minimum(c - row * bh, (row + 1) * bh - c) - mortar / 2
    nrows = int(math.ceil(n / bh)) + 1
    ncols = int(math.ceil(n / bw)) + 2
    rng = np.random.default_rng(seed)
    top = (4.0 + rng.uniform(-0.5, 0.5, size=(nrows, ncols))) * sc
    h = np.empty((n, n))
    for parity in (0, 1):                                  # running bond: odd rows shifted
        xs = c + parity * (bw / 2)
        col = np.floor(xs / bw).astype(int)
        d_x = np.minimum(xs - col * bw, (col + 1) * bw - xs) - mortar / 2
        sel = (row % 2) == parity
        d = np.minimum(d_x[None, :], d_y[sel][:, None])    # distance to the brick outline
        h[sel] = top[row[sel][:, None], col[None, :]] * np.clip(d / bevel, 0.0, 1.0)
    return h.astype(np.float32)


def sine(n, periods=8):
    """Grid of periods x periods smooth sine "domes", height n/16, zero valleys.

    h = A * (1 - cos(2 pi P x / n)) (1 - cos(2 pi P y / n)) / 4 on integer
    pixel positions (tiles seamlessly).  The number of domes is fixed, so a
    bigger n adds detail, not extent.
    """
    a = n / 16.0
    t = 2.0 * np.pi * periods * np.arange(n) / n
    u = 0.5 * (1.0 - np.cos(t))
    return (a * np.outer(u, u)).astype(np.float32)


def blocks(n, seed=SEED_BLOCKS, count=64):
    """Random axis-aligned boxes on flat ground (height 0); overlaps take the max.

    Box sides n/40 .. n/6, heights n/64 .. n/8 (at n=256: 6..42 px wide,
    4..32 px high).  Layout is drawn in units of n, so sizes are similar.
    """
    rng = np.random.default_rng(seed)
    h = np.zeros((n, n), dtype=np.float64)
    p = rng.uniform(0.0, 1.0, size=(count, 5))
    for fx, fy, fw, fh, fz in p:
        w = max(1, int(round(n * (1 / 40 + fw * (1 / 6 - 1 / 40)))))
        d = max(1, int(round(n * (1 / 40 + fh * (1 / 6 - 1 / 40)))))
        x0 = int(fx * (n - w))
        y0 = int(fy * (n - d))
        z = n * (1 / 64 + fz * (1 / 8 - 1 / 64))
        np.maximum(h[y0:y0 + d, x0:x0 + w], z, out=h[y0:y0 + d, x0:x0 + w])
    return h.astype(np.float32)


def random_field(n, seed=SEED_RANDOM, hmax=16.0):
    """I.i.d. uniform heights in [0, hmax) px: Timonen 2013 Fig. 8 "extent" series
    (a bigger n randomises more data from the same fixed height range)."""
    return np.random.default_rng(seed).uniform(0.0, hmax, size=(n, n)).astype(np.float32)


# ---------------------------------------------------------------------------
# Real DEMs
# ---------------------------------------------------------------------------

WGS84_A = 6378137.0
WGS84_F = 1 / 298.257223563


def metres_per_degree(lat_deg):
    """(east-west, north-south) metres per degree on the WGS84 ellipsoid at latitude."""
    e2 = WGS84_F * (2 - WGS84_F)
    phi = math.radians(lat_deg)
    w = math.sqrt(1 - e2 * math.sin(phi) ** 2)
    n_rad = WGS84_A / w                            # prime vertical radius
    m_rad = WGS84_A * (1 - e2) / w ** 3            # meridional radius
    return math.radians(1) * n_rad * math.cos(phi), math.radians(1) * m_rad


def jacksboro():
    path = os.path.join(SAMPLE_DIR, "jacksboro_fault_dem.npz")
    with np.load(path) as f:
        meta = {k: f[k] for k in f.files}
    z = meta["elevation"].astype(np.float32)
    rows, cols = z.shape
    dx_deg, dy_deg = float(meta["dx"]), float(meta["dy"])
    xmin, xmax = float(meta["xmin"]), float(meta["xmax"])
    ymin, ymax = float(meta["ymin"]), float(meta["ymax"])
    # The file's "ymin" (36.733) is the northern edge: matplotlib's own examples
    # map row 0 to ymin, so row 0 is north (image orientation) -- kept as is.
    lat_c = 0.5 * (ymin + ymax)
    mx, my = metres_per_degree(lat_c)
    cx, cy = dx_deg * mx, dy_deg * my
    info = {
        "source": path + " (matplotlib sample data)",
        "npz_keys": ", ".join("%s=%s" % (k, meta[k]) for k in meta if k != "elevation"),
        "grid": "%d x %d (width x height), geographic lon/lat, %.6g deg = %.4g arc-second cells"
                % (cols, rows, dx_deg, dx_deg * 3600),
        "extent_lon": "%.6f .. %.6f (W edge .. E edge; %d * dx = %.6f deg)"
                      % (xmin, xmax, cols, cols * dx_deg),
        "extent_lat": "%.6f (row 0, north edge) .. %.6f (south edge); %d * dy = %.6f deg"
                      % (ymin, ymax, rows, rows * dy_deg),
        "centre_latitude": "%.5f" % lat_c,
        "cell_size_x": "%.3f" % cx,
        "cell_size_y": "%.3f" % cy,
        "cell_size_method": "WGS84 metres per degree at the centre latitude times dx, dy; "
                            "x varies by +-%.2f%% over the rows"
                            % (100 * abs(metres_per_degree(ymin)[0] / mx - 1)),
        "cell_size_matplotlib_example": "%.3f x %.3f (matplotlib topographic_hillshading "
                                        "example: 111200*dx*cos(ymin), 111200*dy)"
                                        % (111200 * dx_deg * math.cos(math.radians(ymin)),
                                           111200 * dy_deg),
        "height_unit": "m",
        "orientation": "row 0 = north, column 0 = west",
    }
    return z, cx, cy, info


def topobathy():
    path = os.path.join(SAMPLE_DIR, "topobathy.npz")
    with np.load(path) as f:
        meta = {k: f[k] for k in f.files}
    lon = meta["longitude"].astype(np.float64)
    lat = meta["latitude"].astype(np.float64)
    z = meta["topo"].astype(np.float32)[::-1].copy()   # file rows go south->north; flip to north-up
    rows, cols = z.shape
    dlon = (lon[-1] - lon[0]) / (cols - 1)
    # Latitudes are not evenly spaced, but their Mercator ordinates are, with the
    # same step (in radians) as the longitudes: a square-pixel Mercator grid.
    ymerc = np.log(np.tan(np.pi / 4 + np.radians(lat) / 2))
    dmerc = np.diff(ymerc)
    lat_c = 0.5 * (lat[0] + lat[-1])
    mx, _ = metres_per_degree(lat_c)
    cx = dlon * mx                                    # east-west metres at centre latitude
    cy = cx                                           # conformal grid: same N-S size locally
    lo, hi = metres_per_degree(lat[-1])[0] * dlon, metres_per_degree(lat[0])[0] * dlon
    info = {
        "source": path + " (matplotlib sample data; provenance not documented in the file)",
        "npz_keys": "topo %s, longitude[%d] %.4f..%.4f (deg E), latitude[%d] %.5f..%.5f (deg N)"
                    % (meta["topo"].shape, cols, lon[0], lon[-1], rows, lat[0], lat[-1]),
        "grid": "%d x %d (width x height); longitude step %.5f deg (%.3g arc-min); latitude "
                "steps %.5f..%.5f deg but Mercator-ordinate steps %.7f..%.7f rad vs "
                "longitude step %.7f rad -> square-pixel Mercator grid (inferred)"
                % (cols, rows, dlon, dlon * 60, np.diff(lat).min(), np.diff(lat).max(),
                   dmerc.min(), dmerc.max(), math.radians(dlon)),
        "centre_latitude": "%.5f" % lat_c,
        "cell_size_x": "%.1f" % cx,
        "cell_size_y": "%.1f" % cy,
        "cell_size_method": "inferred from the lon/lat vectors (no cell size stored): WGS84 "
                            "east-west metres of one longitude step at the centre latitude; "
                            "Mercator grid so N-S equals E-W locally; varies %.0f m (north "
                            "row) .. %.0f m (south row)" % (lo, hi),
        "height_unit": "m (negative = below sea level; units not stated in the file, "
                       "values -1437..2205 are consistent with metres)",
        "orientation": "row 0 = north (flipped from the npz, whose row 0 is the "
                       "southernmost latitude), column 0 = west",
    }
    return z, cx, cy, info


# ---------------------------------------------------------------------------

def summary(name, path, z, seconds):
    print("%-26s %5d x %-5d %8.1f KB  min %10.3f  max %10.3f  (%.2f s)"
          % (name, z.shape[1], z.shape[0], os.path.getsize(path) / 1024.0,
             float(z.min()), float(z.max()), seconds))


def main(argv=None):
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=256, help="synthetic field size N (default 256)")
    ap.add_argument("--out", default=here, help="output directory (default: this script's directory)")
    ap.add_argument("--fields", default="fractal,bricks,sine,blocks",
                    help="comma-separated synthetic fields: fractal, bricks, sine, blocks, "
                         "random (default: the four of Fig. 7)")
    ap.add_argument("--no-dem", action="store_true", help="skip the two real DEMs")
    ap.add_argument("--no-env", action="store_true", help="skip the environment map clear_sky.exr")
    ap.add_argument("--writer", choices=sorted(WRITERS), default="builtin",
                    help="EXR writer: built-in (numpy+zlib, default) or OpenImageIO")
    args = ap.parse_args(argv)
    n = args.size
    if n < 2:
        ap.error("--size must be >= 2")
    os.makedirs(args.out, exist_ok=True)
    write = WRITERS[args.writer]
    gens = {"fractal": fractal, "bricks": bricks, "sine": sine, "blocks": blocks,
            "random": random_field}
    desc = {
        "fractal": "midpoint-displacement fractal terrain (Timonen 2013 Fig. 7)",
        "bricks": "brick surface, running bond with mortar grooves (Timonen 2013 Fig. 7)",
        "sine": "sine grid, 8x8 domes (Timonen 2013 Fig. 7)",
        "blocks": "random axis-aligned boxes on flat ground (Timonen 2013 Fig. 7)",
        "random": "i.i.d. uniform heights in [0,16) (Timonen 2013 Fig. 8 extent series)",
    }
    for name in [f.strip() for f in args.fields.split(",") if f.strip()]:
        if name not in gens:
            ap.error("unknown field %r" % name)
        t0 = time.time()
        z = gens[name](n)
        path = os.path.join(args.out, "%s_%d.exr" % (name, n))
        write(path, z, {
            "hfvis:description": desc[name],
            "hfvis:generator": "data/make_data.py --size %d" % n,
            "hfvis:height_unit": "pixel",
            "hfvis:cell_size_x": "1",
            "hfvis:cell_size_y": "1",
        })
        summary(os.path.basename(path), path, z, time.time() - t0)

    if not args.no_env:
        t0 = time.time()
        sky = clear_sky()
        path = os.path.join(args.out, "clear_sky.exr")
        write_exr_builtin(path, sky, {
            "hfvis:description": "synthetic clear sky for the lighting examples: sun at compass 240, "
                                 "elevation 25 degrees",
            "hfvis:generator": "data/make_data.py",
            "hfvis:convention": "equirectangular: row 0 zenith; column fraction u looks toward compass "
                                "azimuth 360 u",
        }, names=("R", "G", "B"))
        print("%-26s %5d x %-5d %10d bytes  %.2fs" % (os.path.basename(path), sky.shape[1], sky.shape[0],
                                                    os.path.getsize(path), time.time() - t0))

    if not args.no_dem:
        for base, fn in (("jacksboro_fault_dem", jacksboro), ("topobathy", topobathy)):
            t0 = time.time()
            z, cx, cy, info = fn()
            path = os.path.join(args.out, base + ".exr")
            write(path, z, {
                "hfvis:description": base + " DEM from matplotlib sample data",
                "hfvis:generator": "data/make_data.py",
                "hfvis:height_unit": "m",
                "hfvis:cell_size_x": info["cell_size_x"],
                "hfvis:cell_size_y": info["cell_size_y"],
                "hfvis:source": info["source"],
            })
            with open(os.path.join(args.out, base + ".txt"), "w") as f:
                f.write("# %s.exr: ground cell size and provenance (written by data/make_data.py)\n"
                        % base)
                f.write("width = %d\nheight = %d\n" % (z.shape[1], z.shape[0]))
                f.write("min_height = %g\nmax_height = %g\n" % (z.min(), z.max()))
                for k, v in info.items():
                    f.write("%s = %s\n" % (k, v))
            summary(os.path.basename(path), path, z, time.time() - t0)
            print("%-26s cell size x %s m, y %s m" % ("", info["cell_size_x"], info["cell_size_y"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
