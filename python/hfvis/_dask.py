"""Dask-backed DataArrays: the distance-limited operations chunk by chunk with a halo of the
maximum distance (dask.array.overlap.overlap, then map_blocks), and cumulative viewsheds split into
groups of observers summed. The graph carries module-level functions and plain values only (the
operation's name, its options, the geometry), so that distributed workers can unpickle it; each
worker process makes its own OpenCL context (hfvis._core keeps one per process)."""

import functools
import math

import numpy as np

from . import _arrays, _core
from ._errors import InvalidArgumentError

# Beyond the maximum distance, what a point's result reads: the bilinear surface's cell around a
# sample at that distance (one more pixel) and the receiver's own normal (its neighbours).
SURFACE_PIXELS = 2


def halo(geometry, max_distance, operation):
    """The halo in pixels that holds everything the results of a chunk depend on."""
    if max_distance and not math.isfinite(max_distance):
        raise InvalidArgumentError(f"{operation} on a Dask array needs a finite max_distance (the halo around each "
                                   f"chunk), got {max_distance!r}")
    if not max_distance or max_distance <= 0:
        raise InvalidArgumentError(
            f"{operation} on a Dask array needs max_distance > 0 (ground units): each chunk is computed with a halo "
            "of that distance around it, and without one every point depends on the whole field. Pass "
            "max_distance=..., or .compute() the array to run it in memory")
    sizes = [geometry["cell_size_x"], geometry["cell_size_y"], *geometry["row_cell_size_x"],
             *geometry["row_cell_size_y"]]
    return int(math.ceil(max_distance / min(sizes))) + SURFACE_PIXELS


def _base_of(sample, lowest):
    """The library's heightBase from its lattice of heights (`sample`) and the whole field's lowest
    finite height: the lower of the lattice's two middle finite heights, else the lowest."""
    finite = np.sort(sample[np.isfinite(sample)], kind="stable")
    base = finite[(finite.size - 1) // 2] if finite.size else lowest.flat[0]
    return np.full((1, 1), base, np.float64)


def _block(block, base, operation, geometry, options, device, depth, chunks, block_id=None):
    """One chunk with its halo (overlap, boundary 'none': no halo beyond the field's own edges,
    which stay edges) -> its planes, the halo trimmed, stacked along a leading axis. The library is
    told where the block lies in the whole field and the whole field's base height (`base`, a 1 x 1
    block; HeightField::origin), so that it samples every line where the whole field's run does
    and holds the same floats: the results inside the halo are that run's bit for bit."""
    if not math.isfinite(float(base.flat[0])):  # (as the whole field in memory is refused)
        raise InvalidArgumentError("every height is nodata (NaN or infinite)")
    i, j = block_id[-2], block_id[-1]
    top = depth if i > 0 else 0
    left = depth if j > 0 else 0
    bottom = depth if i < len(chunks[0]) - 1 else 0
    right = depth if j < len(chunks[1]) - 1 else 0
    first_row = sum(chunks[0][:i]) - top
    first_col = sum(chunks[1][:j]) - left
    g = dict(geometry)
    g["origin"] = [first_col, first_row, sum(chunks[1]), sum(chunks[0]), float(base.flat[0])]
    if g["row_cell_size_x"]:  # a latitude / longitude grid: the block's own rows' spacing, and the
        # whole field's rows, along which positions are counted
        g["origin_row_cell_size_x"] = g["row_cell_size_x"]
        g["origin_row_cell_size_y"] = g["row_cell_size_y"]
        g["row_cell_size_x"] = g["row_cell_size_x"][first_row:first_row + block.shape[0]]
        g["row_cell_size_y"] = g["row_cell_size_y"][first_row:first_row + block.shape[0]]
    planes = _arrays.planes_of(operation, options)
    names = _arrays.OUTPUTS[operation]
    heights = np.ascontiguousarray(block, dtype=np.float32)
    if not np.isfinite(heights).any():  # all nodata: NaN, as the whole field's run gives there
        out = np.full((len(names) * planes,) + heights.shape, np.nan, np.float32)
    else:
        result = _arrays.compute(operation, heights, g, options, device)
        out = np.concatenate([result[name].reshape((-1,) + heights.shape) for name in names])
    return out[:, top:out.shape[1] - bottom, left:out.shape[2] - right]


def _through_float32(block):
    with np.errstate(over="ignore"):  # (beyond float32's range: refused in _kept_block, with a message)
        return block.astype(np.float32).astype(np.float64)


def _kept_block(block, rounding, low, high, nodata, cell_size):
    if high.flat[0] > np.finfo(np.float32).max or low.flat[0] < -np.finfo(np.float32).max:
        # (as heights_array says it in memory: they would turn into infinities, that is nodata)
        raise InvalidArgumentError("heights beyond float32's range (about 3.4e38): scale them first")
    if high.flat[0] >= low.flat[0]:
        _core.require_heights_kept_in_float32(float(rounding.flat[0]), float(low.flat[0]),
                                              float(high.flat[0]), cell_size)
    with np.errstate(over="ignore"):  # (infinities only at nodata here: the range is checked above)
        narrow = block.astype(np.float32)
    return np.where(_arrays.nodata_holes(block, nodata), np.float32(np.nan), narrow)


def kept_in_float32(data, nodata, cell_size):
    """The Dask array `data` of a dtype float32 may round (_arrays.float32_may_round) as float32,
    `nodata` as NaN, each block refused, as heights_array refuses an array in memory, where float32
    rounds the whole field's heights too far: lazily, the field's largest rounding and its range
    are reductions that every block takes (as the base height in chunked)."""
    import dask.array as da

    wide = data.astype(np.float64)
    keep = da.isfinite(wide) & ~data.map_blocks(_arrays.nodata_holes, nodata, dtype=bool)
    rounding = da.where(keep, abs(wide - data.map_blocks(_through_float32, dtype=np.float64)), 0.0).max()
    low = da.where(keep, wide, np.inf).min()
    high = da.where(keep, wide, -np.inf).max()
    each = [da.broadcast_to(x, data.numblocks, chunks=1) for x in (rounding, low, high)]
    return da.map_blocks(_kept_block, data, *each, nodata=nodata, cell_size=cell_size, dtype=np.float32)


def chunked(operation, heights, geometry, options, device=""):
    """`operation` over the 2-D Dask array `heights` (float32, nodata NaN): its outputs by name,
    Dask arrays chunked as the input (rechunked where a chunk is smaller than the halo)."""
    import dask.array as da
    from dask.array.overlap import ensure_minimum_chunksize

    if 0 in heights.shape:
        raise InvalidArgumentError(f"heights are empty ({heights.shape[0]} x {heights.shape[1]})")
    depth = halo(geometry, options.get("max_distance"), operation)
    # Every chunk at least the halo deep, so that each block's halo comes from its neighbours alone.
    chunks = tuple(c if len(c) == 1 else (sum(c),) if sum(c) <= depth else ensure_minimum_chunksize(depth, c)
                   for c in heights.chunks)
    if chunks != heights.chunks:
        heights = heights.rechunk(chunks)
    names = _arrays.OUTPUTS[operation]
    planes = _arrays.planes_of(operation, options)
    body = functools.partial(_block, operation=operation, geometry=geometry, options=options, device=device,
                             depth=depth, chunks=chunks)
    # (no halo along an axis of one chunk: it has no neighbours, and dask refuses a depth beyond
    # the array, as for a field 30 rows high with a halo of 52)
    overlapped = da.overlap.overlap(heights, depth={a: depth if len(chunks[a]) > 1 else 0 for a in (0, 1)},
                                    boundary="none")
    # The whole field's base (the library's heightBase: the median of the finite heights at up to
    # 64 x 64 pixels spread evenly over it, else its lowest finite height), the base of every
    # block's heights: handed to each block as a 1 x 1 block of its own (infinite where every
    # height is nodata, and then no block reads it).
    rows, cols = ((2 * np.arange(min(n, 64)) + 1) * n // (2 * min(n, 64)) for n in heights.shape)
    sample = heights[rows, :][:, cols].rechunk(-1)
    lowest = da.where(da.isfinite(heights), heights, np.float32(np.inf)).min().reshape(1, 1)
    base = da.map_blocks(_base_of, sample, lowest, chunks=((1,), (1,)), dtype=np.float64)
    base = da.broadcast_to(base[0, 0], overlapped.numblocks, chunks=1)
    stacked = da.map_blocks(body, overlapped, base, dtype=np.float32, new_axis=0,
                            chunks=((len(names) * planes,),) + chunks, meta=np.empty((0, 0, 0), np.float32))
    out = {}
    for n, name in enumerate(names):
        part = stacked[n * planes:(n + 1) * planes]
        leading = operation in ("horizon_angles", "horizon_distances", "environment_light")
        out[name] = part if planes > 1 or leading else part[0]
    return out


def _viewshed_window(window, geometry, options, device, first_col, first_row, shape, flips):
    o = dict(options)
    col, row = _arrays.observer_pixel(options["observer"])
    o["observer"] = np.array([col - first_col, row - first_row])
    if not np.isfinite(window[row - first_row, col - first_col]):  # (named in the window's pixels, it misled)
        raise _arrays.observer_unflipped(InvalidArgumentError(f"observer {col},{row} stands on nodata"), shape,
                                         flips)
    return _arrays.compute("viewshed", np.ascontiguousarray(window, dtype=np.float32), geometry, o, device)["visible"]


def _viewshed_block(block, window, first_col, first_row, block_info=None):
    """One chunk of the viewshed: 0 (out of range) and NaN at nodata, the window's values where it
    overlaps the window."""
    (r0, r1), (c0, c1) = block_info[0]["array-location"]
    out = np.where(np.isfinite(block), np.float32(0), np.float32(np.nan)).astype(np.float32)
    top, left = max(r0, first_row), max(c0, first_col)
    bottom, right = min(r1, first_row + window.shape[0]), min(c1, first_col + window.shape[1])
    if top < bottom and left < right:
        out[top - r0:bottom - r0, left - c0:right - c0] = window[top - first_row:bottom - first_row,
                                                                 left - first_col:right - first_col]
    return out


def viewshed(heights, geometry, options, device="", flips=(False, False)):
    """One observer's viewshed over a Dask array, chunked as the input: within a maximum distance
    computed on the window it reaches (a task of its own), the rest out of range (0, NaN at
    nodata). The viewshed's heights count from zero and its rays from the observer, so the window's
    result is the whole field's there bit for bit. Without a maximum distance the window is the
    whole field. Latitude / longitude grids are refused now, as the library refuses them. `flips`
    (rows, columns): how the field was flipped from the caller's, whose pixel an error names."""
    import dask
    import dask.array as da

    _refuse_rows_spacing(geometry)
    col, row = _arrays.observer_pixel(options["observer"])
    height, width = heights.shape
    if not (0 <= col < width and 0 <= row < height):  # (now, not at compute, in the window's pixels)
        raise InvalidArgumentError(f"observer {col},{row} is outside the {width} x {height} field")
    first_row, first_col, last_row, last_col = 0, 0, height, width
    if options.get("max_distance"):
        depth = halo(geometry, options["max_distance"], "viewshed")
        first_row, first_col = max(0, min(row, height - 1) - depth), max(0, min(col, width - 1) - depth)
        last_row, last_col = min(height, max(row, 0) + depth + 1), min(width, max(col, 0) + depth + 1)
    window = dask.delayed(_viewshed_window)(heights[first_row:last_row, first_col:last_col], geometry, options,
                                            device, first_col, first_row, heights.shape, flips)
    return da.map_blocks(_viewshed_block, heights, window, first_col, first_row, dtype=np.float32,
                         meta=np.empty((0, 0), np.float32))


def _refuse_rows_spacing(geometry):
    """The library's refusal of viewsheds on latitude / longitude grids, when the graph is built
    rather than when it is computed."""
    if geometry["row_cell_size_x"]:
        raise InvalidArgumentError("viewsheds on latitude / longitude grids (per-row spacing) are not supported; "
                                   "reproject the DEM to a projected CRS")


def _observer_group(heights, geometry, options, device, group, flips):
    o = dict(options, observers=group[0], observer_height=group[1])
    try:
        return _arrays.compute("cumulative_viewshed", np.ascontiguousarray(heights, dtype=np.float32), geometry, o,
                               device)["count"]
    except InvalidArgumentError as error:
        raise _arrays.observer_unflipped(error, heights.shape, flips) from None


def cumulative_viewshed(heights, geometry, options, device="", group_size=None, flips=(False, False)):
    """The cumulative viewshed of many observers over a Dask array: groups of observers, each a
    task over the whole field, and their counts summed (whole numbers: the sum is exact)."""
    import dask
    import dask.array as da

    _refuse_rows_spacing(geometry)
    cols, rows, eyes = _arrays.observer_pixels(options["observers"], options["observer_height"])
    pixels = np.stack([cols, rows], axis=1)
    eyes = np.asarray(eyes)
    if group_size is None:
        group_size = max(1, math.ceil(len(pixels) / 8))
    whole = heights.rechunk(-1)
    counts = []
    for start in range(0, len(pixels), group_size):
        group = (pixels[start:start + group_size], eyes[start:start + group_size])
        task = dask.delayed(_observer_group)(whole, geometry, options, device, group, flips)
        counts.append(da.from_delayed(task, shape=heights.shape, dtype=np.float32))
    total = functools.reduce(lambda a, b: a + b, counts)
    return total.rechunk(heights.chunks)
