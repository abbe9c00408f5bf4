"""numpy in, numpy out: heights checked and converted, the library's options filled from keyword
arguments, and one operation run on hfvis._core. compute() takes and returns only plain values
(arrays, dicts, strings, numbers), so that a Dask graph can carry its calls to other processes."""

import datetime
import math
import os
import re

import numpy as np

from . import _core
from ._errors import InputTypeError, InvalidArgumentError

# The operations whose options include a maximum distance that bounds what a point's result
# depends on (Dask runs them chunk by chunk with a halo), and each one's planes.
HORIZON_OPERATIONS = ("horizon_angles", "horizon_distances", "sky_view_factor", "ambient_occlusion")
DISTANCE_LIMITED = HORIZON_OPERATIONS + ("intervisibility", "sun_shading", "insolation", "environment_light")
OUTPUTS = {
    "horizon_angles": ("angles",),
    "horizon_distances": ("distances",),
    "sky_view_factor": ("sky_view_factor",),
    "ambient_occlusion": ("ambient_occlusion",),
    "intervisibility": ("visible_count", "visible_area"),
    "sun_shading": ("sun", "direct"),
    "insolation": ("sun_hours", "direct"),
    "viewshed": ("visible",),
    "cumulative_viewshed": ("count",),
    "region_visibility": ("fraction", "bits"),
    "bounce": ("irradiance",),
    "environment_light": ("irradiance",),
}


def nodata_holes(a, nodata):
    """Where the array `a` holds `nodata` (None or NaN: nowhere), compared in a's own dtype, as a
    file's nodata is compared in its band's type: a float64 -9999.9 is float32 -9999.9's nodata (it
    had marked nothing). A value the dtype cannot hold marks nothing; a nodata that is not a real
    number is refused."""
    if nodata is not None and (isinstance(nodata, (bool, np.bool_)) or
                               not isinstance(nodata, (int, float, np.integer, np.floating))):
        raise InvalidArgumentError(f"nodata must be a real number (or None), got {nodata!r}")
    if nodata is None or isinstance(nodata, (float, np.floating)) and math.isnan(nodata):
        return np.zeros(a.shape, dtype=bool)
    nowhere = np.zeros(a.shape, dtype=bool)
    if a.dtype.kind in "iu":
        # (compared as Python numbers: a nodata beyond int64, 2**70, was numpy's bare OverflowError)
        if isinstance(nodata, (float, np.floating)) and not float(nodata).is_integer():
            return nowhere
        whole = int(nodata)
        limits = np.iinfo(a.dtype)
        return nowhere if not limits.min <= whole <= limits.max else np.asarray(a == a.dtype.type(whole))
    try:
        value = float(nodata)
    except OverflowError:  # an integer beyond any float: no height holds it
        return nowhere
    with np.errstate(over="ignore", invalid="ignore"):
        typed = np.asarray(value).astype(a.dtype)
    return np.asarray(a == typed)


def float32_may_round(dtype):
    """Whether float32, in which hfvis computes, may round heights of this dtype: it keeps an
    integer exactly only to 2^24, and a double's digits to about 7 (heights near 1e10 lost their
    walls, came out flat, without a word)."""
    return dtype.itemsize > 4 or dtype.kind in "iu" and dtype.itemsize == 4


def file_path(path, what):
    """A file's path (str, bytes or os.PathLike) as the str the library opens; one holding a NUL
    refused (the library's C string ended there: "dem.tif\\0.exr" opened dem.tif)."""
    text = os.fsdecode(os.fspath(path))
    if "\0" in text:
        raise InvalidArgumentError(f"{what} {text!r} holds a NUL character, which no file name can")
    return text


def as_array(value, what):
    """np.asarray(value), or hfvis's InputTypeError naming `what` where numpy cannot make an array of
    it (a ragged list: numpy's own ValueError) or where it is an xarray.Dataset (several variables:
    xarray's TypeError)."""
    if hasattr(value, "data_vars"):  # an xarray.Dataset (not imported here: xarray is optional)
        names = [str(n) for n in value.data_vars]
        listed = ", ".join(repr(n) for n in names[:5]) + (", ..." if len(names) > 5 else "")
        counted = f"{len(names)} variable{'' if len(names) == 1 else 's'}" + (f": {listed}" if names else "")
        raise InputTypeError(f"{what} must be an array, not an xarray.Dataset ({counted}): give one of its "
                             "variables, a DataArray (dataset['name'])")
    try:
        return np.asarray(value)
    except ValueError as e:  # numpy's for a ragged list
        raise InputTypeError(f"{what} must be an array; numpy could not make one of the {type(value).__name__} "
                             f"given (rows of different lengths?): {e}") from None
    except TypeError as e:
        raise InputTypeError(f"{what} must be an array; numpy could not make one of the {type(value).__name__} "
                             f"given: {e}") from None


def heights_array(heights, nodata=None, cell_size=1.0):
    """The heights as a new or unmodified C-contiguous native float32 2-D array, nodata (and
    `nodata`'s value, compared in the heights' own dtype, and a masked array's mask) as NaN. Any
    real dtype (float16..float128, integers), either byte order, any strides; refused: other
    dimensions, complex, bool, object, and heights that float32 rounds by more than a thousandth of
    their range and a hundredth of `cell_size` (as the file readers refuse them)."""
    mask = np.ma.getmaskarray(heights) if np.ma.isMaskedArray(heights) else None
    a = as_array(np.ma.getdata(heights) if mask is not None else heights, "heights")
    if a.ndim != 2:
        raise InputTypeError(f"heights must be a 2-D array (rows, columns), got {a.ndim} dimension(s) {a.shape}")
    if a.dtype.kind not in "fiu":
        raise InputTypeError(f"heights must hold real numbers (a float or integer dtype), got dtype {a.dtype}")
    if a.shape[0] == 0 or a.shape[1] == 0:
        raise InvalidArgumentError(f"heights are empty ({a.shape[0]} x {a.shape[1]})")
    with np.errstate(over="ignore"):  # refused just below, with a message
        converted = np.ascontiguousarray(a, dtype=np.float32)
    holes = nodata_holes(a, nodata)
    if mask is not None:
        holes |= mask
    if a.dtype.kind == "f" and a.dtype.itemsize > 4:
        # Heights beyond float32's range would turn into infinities, that is nodata, unseen. (Not
        # nodata itself: GDAL's and ArcGIS's -1.797e308 was refused.)
        overflow = np.isinf(converted) & np.isfinite(a) & ~holes
        if overflow.any():
            raise InvalidArgumentError("heights beyond float32's range (about 3.4e38): scale them first")
    if float32_may_round(a.dtype):
        # (In blocks of about a million values: a float64 copy of the whole field would double its
        # memory.)
        rounding, low, high = 0.0, math.inf, -math.inf
        step = max(1, (1 << 20) // a.shape[1])
        for r in range(0, a.shape[0], step):
            block = a[r:r + step].astype(np.float64)
            keep = np.isfinite(block) & ~holes[r:r + step]
            if keep.any():
                wide = block[keep]
                rounding = max(rounding, float(np.max(np.abs(wide - converted[r:r + step][keep]))))
                low, high = min(low, float(wide.min())), max(high, float(wide.max()))
        if high >= low:
            _core.require_heights_kept_in_float32(rounding, low, high, cell_size)
    if holes.any():
        converted = np.where(holes, np.float32(np.nan), converted)  # a new array: the input stays
    return converted


def pvs_start(bits, shape, view_cell, tile):
    """An earlier run's bits (2-D uint32) flat, once their shape is the grid's: view cells x words
    (hfvis/pvs.hpp's PvsLayout: view cells and tiles over the W - 1 x H - 1 cells; the library
    checks the count alone)."""
    cells_y, cells_x = shape[0] - 1, shape[1] - 1
    most = max(cells_x, cells_y)  # (beyond, the library refuses the grid itself, naming it)
    if 1 <= view_cell <= most and 1 <= tile <= most and cells_x >= 1 and cells_y >= 1:
        views = -(-cells_x // view_cell) * -(-cells_y // view_cell)
        words = -(-(-(-cells_x // tile) * -(-cells_y // tile)) // 32)
        if bits.shape != (views, words):
            raise InvalidArgumentError(f"start holds {bits.shape[0]} x {bits.shape[1]} words, where this field and grid "
                                       f"have {views} view cells of {words} words: give the bits of a run on the same "
                                       "field and grid")
    return bits.ravel()


def geometry(cell_size=None, z_scale=1.0, row_cell_sizes=None):
    """The field's cell sizes and z-scale as hfvis._core.height_field takes them. cell_size: a
    number (square cells), a pair (x, y), or None (1). row_cell_sizes: None, or a pair of
    per-row sequences (x, y) for latitude / longitude grids."""
    if cell_size is None:
        cx = cy = 1.0
    else:
        pair = np.asarray(cell_size, dtype=object).ravel() if np.ndim(cell_size) <= 1 else ()
        if len(pair) not in (1, 2) or not all(np.ndim(v) == 0 and np.asarray(v).dtype.kind in "iuf" for v in pair):
            raise InvalidArgumentError(f"cell_size must be a number or a pair (x, y), got {cell_size!r}")
        cx, cy = float(pair[0]), float(pair[-1])
    rows_x, rows_y = ([], []) if row_cell_sizes is None else (list(map(float, row_cell_sizes[0])),
                                                               list(map(float, row_cell_sizes[1])))
    # The range the kernels' single precision holds, the library's (its validate refuses the same):
    # checked here too, as the Dask path divides by the cell sizes before the library sees them.
    for size in [cx, cy] + rows_x + rows_y:
        if not (_core.least_cell_size <= size <= _core.most_cell_size):
            raise InvalidArgumentError(f"the cell size {size:g} is outside {_core.least_cell_size:g} .. "
                                       f"{_core.most_cell_size:g} ground units, what the kernels' single precision "
                                       "holds")
    if np.ndim(z_scale) != 0 or np.asarray(z_scale).dtype.kind not in "iuf":
        raise InvalidArgumentError(f"z_scale must be a number, got {z_scale!r}")
    if not (1e-12 <= float(z_scale) <= 1e12):  # (the CLI's --z-scale range)
        raise InvalidArgumentError(f"z_scale must lie in 1e-12 .. 1e12, what the kernels' single precision holds, "
                                   f"got {float(z_scale):g}")
    return {"cell_size_x": cx, "cell_size_y": cy, "row_cell_size_x": rows_x, "row_cell_size_y": rows_y,
            "z_scale": float(z_scale), "origin": []}


def _set(target, options, names):
    for name in names:
        value = options.get(name)
        if value is not None:
            setattr(target, name, value)


_SWEEP = ("directions", "azimuth_offset", "samples_per_unit", "curvature", "max_distance", "memory_budget_bytes")


def _sweep_options(options):
    o = _core.SweepOptions()
    _set(o, options, _SWEEP)
    return o


def _horizon_options(options):
    o = _core.HorizonOptions()
    _set(o, options, _SWEEP + ("azimuth_tolerance", "strip_rows", "max_error"))
    o.method = _enum(_core.HorizonMethod, options.get("method", "sweep"), "method")
    return o


def _enum(kind, name, what):
    try:
        return getattr(kind, name)
    except (AttributeError, TypeError):
        choices = ", ".join(k for k in dir(kind) if not k.startswith("_") and k.islower())
        raise InvalidArgumentError(f"{what} must be one of {choices}, got {name!r}") from None


def _viewshed_options(options):
    o = _core.ViewshedOptions()
    _set(o, options, ("absolute", "target_height", "max_distance", "curvature", "azimuth_from_deg",
                      "azimuth_to_deg", "elevation_min_deg", "elevation_max_deg", "memory_budget_bytes"))
    return o


def utc_seconds(when):
    """Seconds since 1970 (UTC) from an ISO 8601 text with a zone (the library parses it), an
    aware datetime, a numpy datetime64 (taken as UTC) or a number."""
    if isinstance(when, str):
        return _core.parse_utc_time(when)
    if isinstance(when, datetime.datetime):
        if when.tzinfo is None:
            raise InvalidArgumentError(f"the time {when} has no time zone: give an aware datetime")
        return when.timestamp()
    if isinstance(when, np.datetime64):
        return float((when - np.datetime64(0, "s")) / np.timedelta64(1, "s"))
    if isinstance(when, (int, float, np.integer, np.floating)) and not isinstance(when, (bool, np.bool_)):
        return float(when)  # (np.int64 seconds were refused where np.float64 ones were taken)
    raise InputTypeError(f"a time must be an ISO 8601 text, an aware datetime, a datetime64 or seconds, got {when!r}")


def planes_of(operation, options):
    """How many planes each output of `operation` has: K for horizon maps, the environment's
    channels (options["channels"], which the caller finds) for its light, else 1."""
    if operation == "environment_light":
        return len(options["channels"])
    return options["directions"] if operation in ("horizon_angles", "horizon_distances") else 1


def compute(operation, heights, geometry, options, device="", progress=None):
    """Runs `operation` on C-contiguous float32 heights (heights_array). Returns its outputs by
    name (OUTPUTS): (H, W) planes, K x H x W for horizon maps, and extras (azimuths, ...)."""
    field = _core.height_field(heights, **geometry)
    if operation in HORIZON_OPERATIONS:
        r = _core.horizons(field, _horizon_options(options), angles=operation == "horizon_angles",
                           distances=operation == "horizon_distances",
                           sky_view_factor=operation == "sky_view_factor",
                           ambient_occlusion=operation == "ambient_occlusion",
                           error_estimate=bool(options.get("error_estimate")), device=device, progress=progress)
        r["azimuths"] = np.asarray(r["azimuths"])
        return r
    if operation == "intervisibility":
        o = _core.IntervisibilityOptions()
        _set(o, options, _SWEEP + ("strip_rows", "max_error"))
        o.method = _enum(_core.IntervisibilityMethod, options.get("method", "hull_tree"), "method")
        r = _core.intervisibility(field, o, error_estimate=bool(options.get("error_estimate")), device=device,
                                  progress=progress)
        r["azimuths"] = np.asarray(r["azimuths"])
        return r
    if operation == "sun_shading":
        return _core.sun_shading(field, float(options["azimuth_deg"]), float(options["elevation_deg"]),
                                 float(options["size_deg"]), _sweep_options(options), device=device,
                                 progress=progress)
    if operation == "insolation":
        o = _core.InsolationOptions()
        _set(o, options, ("latitude_deg", "longitude_deg", "step_minutes", "size_deg", "azimuth_bucket_deg",
                          "apparent"))
        o.from_utc = utc_seconds(options["start"])
        o.to_utc = utc_seconds(options["end"])
        return _core.insolation(field, o, _sweep_options(options), device=device, progress=progress)
    if operation == "environment_light":
        environment = options["environment"]
        if isinstance(environment, (str, os.PathLike)):  # (a pathlib.Path was refused as "not a path")
            env = _core.read_environment_map(file_path(environment, "the environment map"),
                                             float(options["rotation_deg"]), int(options["table_rows"]))
        else:
            radiance = as_array(environment, "environment")
            if radiance.ndim == 2:
                radiance = radiance[np.newaxis]
            if radiance.ndim != 3 or radiance.dtype.kind not in "fiu":
                raise InputTypeError("environment must be a path, or radiance as a 2-D (rows, columns) or 3-D "
                                     f"(channels, rows, columns) real array, got shape {radiance.shape}")
            names = ["Y"] if radiance.shape[0] == 1 else ["R", "G", "B"][: radiance.shape[0]]
            env = _core.environment_map(np.ascontiguousarray(radiance, dtype=np.float32), names,
                                        float(options["rotation_deg"]), int(options["table_rows"]))
        irradiance, names, directions, error, estimated = _core.environment_light(
            field, env, _horizon_options(options), device=device, progress=progress)
        return {"irradiance": irradiance, "channels": names, "directions": directions, "error": error,
                "estimated_error": estimated}
    if operation == "viewshed":
        col, row = observer_pixel(options["observer"])
        return {"visible": _core.viewshed(field, col, row, float(options["observer_height"]),
                                          _viewshed_options(options), device=device)}
    if operation == "cumulative_viewshed":
        cols, rows, eyes = observer_pixels(options["observers"], options["observer_height"])
        return {"count": _core.cumulative_viewshed(field, cols, rows, eyes, _viewshed_options(options),
                                                   device=device, progress=progress)}
    if operation == "region_visibility":
        o = _region_options(options)
        light_image = options.get("light_image")
        if light_image is not None:
            light_image = as_array(light_image, "light_image")
            if light_image.ndim == 2:
                light_image = np.broadcast_to(light_image, (3,) + light_image.shape)
            if (light_image.ndim != 3 or light_image.shape[0] != 3 or light_image.dtype.kind not in "fiu" or
                    light_image.size == 0):
                raise InputTypeError("light_image must be a real, non-empty 2-D (rows, columns: grey) or 3-D (3: R, G, "
                                     f"B, rows, columns) array, got shape {light_image.shape} and dtype "
                                     f"{light_image.dtype}")
            light_image = np.ascontiguousarray(light_image, dtype=np.float32)
        r = _core.region_visibility(field, region_sampling(options["sources"], options["samples"], options["height"],
                                                           options["absolute"]), o, device=device,
                                    progress=progress, light_image=light_image)
        # Plane w: the samples 32 w .. 32 w + 31 (bit s % 32), as the horizon maps' K x H x W.
        r["bits"] = np.ascontiguousarray(np.moveaxis(r["bits"], -1, 0))
        return r
    if operation == "region_pair_visibility":
        return _core.region_pair_visibility(
            field, region_sampling(options["sources"], options["samples"], options["source_height"],
                                   options["absolute"]),
            region_sampling(options["receivers"], options["samples"], options["receiver_height"], options["absolute"]),
            _region_options(options), device=device, progress=progress)
    if operation == "pvs":
        grid = _core.PvsGrid()
        _set(grid, options, ("view_cell", "band_low", "band_high", "tile"))
        if options.get("mask") is not None:
            grid.mask = pvs_mask(options["mask"], heights.shape, grid.view_cell)
        o = _core.PvsOptions()
        _set(o, options, ("samples", "pixel_error", "seconds", "batch", "seed", "resolution", "filter", "view_filter",
                          "witnesses", "memory_budget_bytes", "estimate_entries", "curvature", "max_distance"))
        o.method = _enum(_core.PvsMethod, str(options.get("method", "agvs")).replace("-", "_"), "method")
        if options.get("start") is not None:
            o.start = pvs_start(options["start"], heights.shape, grid.view_cell, grid.tile).tolist()
        return _core.pvs(field, grid, o, device=device, progress=progress)
    if operation == "horizon_lists":
        cols, rows = receiver_pixels(options["receivers"])
        return {"lists": _core.horizon_lists(field, _sweep_options(options), cols, rows)}
    if operation == "bounce":
        radiance = as_array(options["radiance"], "radiance")
        if radiance.ndim == 2:
            radiance = radiance[np.newaxis]
        if radiance.ndim != 3 or radiance.dtype.kind not in "fiu":
            raise InputTypeError("radiance must be a real 2-D (rows, columns) or 3-D (channels, rows, columns) array, "
                                 f"got shape {radiance.shape} and dtype {radiance.dtype}")
        if radiance.shape[1:] != heights.shape:
            raise InvalidArgumentError(f"the radiance is {radiance.shape[2]} x {radiance.shape[1]}, the heights "
                                       f"{heights.shape[1]} x {heights.shape[0]}: it needs one value per height")
        o = _core.BounceOptions()
        _set(o, options, _SWEEP)
        return _core.bounce(field, np.ascontiguousarray(radiance, dtype=np.float32), o, device=device,
                            progress=progress)
    raise InvalidArgumentError(f"no operation {operation!r}")


def _region_options(options):
    o = _core.RegionVisibilityOptions()
    _set(o, options, ("target_height", "max_distance", "curvature", "seed", "decorrelate"))
    o.method = _enum(_core.RegionVisibilityMethod, options.get("method", "auto"), "method")
    return o


def region_sampling(region, samples, height, absolute):
    """A region as hfvis._core.RegionSampling: a rectangle (col0, row0, col1, row1) of grid points,
    corners inclusive, sampled `samples` times; or an N x 2 (col, row) or N x 3 (col, row, height)
    array of points, the samples themselves (a missing height is `height`)."""
    a = as_array(region, "a region")
    if a.ndim == 1 and a.shape[0] == 4:
        if a.dtype.kind not in "iu" or not all(-2**31 <= int(v) < 2**31 for v in a):
            raise InvalidArgumentError(f"a rectangle is four integer pixel corners (col0, row0, col1, row1), "
                                       f"each within -2**31 .. 2**31 - 1, got {region!r}")
        return _core.region_sampling([int(v) for v in a], [], int(samples), float(height), bool(absolute))
    if a.ndim == 2 and a.shape[1] in (2, 3) and len(a) > 0 and a.dtype.kind in "fiu":
        points = [(float(p[0]), float(p[1]), float(p[2]) if len(p) == 3 else float(height)) for p in a]
        return _core.region_sampling([0, 0, 0, 0], points, int(samples), float(height), bool(absolute))
    raise InvalidArgumentError("a region is a rectangle (col0, row0, col1, row1) or an N x 2 (col, row) or N x 3 "
                               f"(col, row, height) array of points, N >= 1; got shape {a.shape}")


def pvs_mask(mask, shape, view_cell):
    """The view cells to compute, one byte each (row-major): `mask` per view cell (view rows x view
    columns), or per pixel of the field (its shape), as the CLI's --view-mask: a view cell is
    computed when it holds a non-zero finite pixel (the last row and column count with the cells
    before them)."""
    m = as_array(mask, "mask")
    height, width = shape
    cells_x, cells_y = width - 1, height - 1
    view = view_cell if view_cell >= 1 else 1
    view_x, view_y = -(-cells_x // view), -(-cells_y // view)
    if m.ndim == 2 and m.shape == (view_y, view_x):
        return [int(v) for v in (np.nan_to_num(m.astype(np.float64)) != 0).ravel()]
    if m.ndim == 2 and m.shape == (height, width):
        on = np.isfinite(m.astype(np.float64)) & (m != 0)
        rows = np.minimum(np.arange(height), cells_y - 1) // view
        cols = np.minimum(np.arange(width), cells_x - 1) // view
        out = np.zeros((view_y, view_x), np.uint8)
        ys, xs = np.nonzero(on)
        out[rows[ys], cols[xs]] = 1
        return out.ravel().tolist()
    raise InvalidArgumentError(f"mask must be per view cell ({view_y} x {view_x}) or per pixel ({height} x {width}), "
                               f"got shape {m.shape}")


def receiver_pixels(receivers):
    """Columns and rows of an N x 2 integer array of pixels (column, row), N >= 1."""
    pixels = as_array(receivers, "receivers")
    if pixels.ndim != 2 or pixels.shape[1] != 2 or pixels.dtype.kind not in "iu" or len(pixels) == 0:
        raise InvalidArgumentError(f"receivers must be an N x 2 array of integer pixels (column, row), N >= 1, "
                                   f"got shape {pixels.shape} and dtype {pixels.dtype}")
    cols, rows = pixels[:, 0].tolist(), pixels[:, 1].tolist()
    for col, row in zip(cols, rows):
        if not (-2**31 <= col < 2**31 and -2**31 <= row < 2**31):  # (nanobind's bare TypeError)
            raise InvalidArgumentError(f"receiver {col},{row} lies outside the field")
    return cols, rows


def flipped_pixel(col, row, shape, flips):
    """The pixel (col, row) of a field of `shape` flipped by `flips` (rows, columns): the caller's
    pixel in the field as computed (flipped to north up, west left), and back."""
    height, width = shape
    return (width - 1 - col if flips[1] else col), (height - 1 - row if flips[0] else row)


def observer_unflipped(error, shape, flips):
    """The library's error naming an observer's pixel in the field as computed (flipped to north up,
    west left: `flips`, rows and columns) with the pixel as the caller's array has it."""
    if not (flips[0] or flips[1]):
        return error

    def caller(match):
        col, row = flipped_pixel(int(match.group(1)), int(match.group(2)), shape, flips)
        return f"observer {col},{row}"

    return type(error)(re.sub(r"observer (-?\d+),(-?\d+)", caller, str(error)))


def observer_pixel(observer):
    pair = as_array(observer, "observer")
    # (a bool is no pixel: numpy made (True, 3) the pixel (1, 3))
    booleans = isinstance(observer, (tuple, list)) and any(isinstance(v, (bool, np.bool_)) for v in observer)
    if booleans or pair.shape != (2,) or pair.dtype.kind not in "iu" or \
            not all(-2**31 <= int(v) < 2**31 for v in pair):
        raise InvalidArgumentError(f"an observer is a pixel (column, row) of two integers, got {observer!r}")
    return int(pair[0]), int(pair[1])


def observer_pixels(observers, observer_height):
    """Columns, rows and eye heights of an N x 2 integer array of pixels (column, row); the
    height a number or one per observer."""
    pixels = as_array(observers, "observers")
    if pixels.ndim != 2 or pixels.shape[1] != 2 or pixels.dtype.kind not in "iu" or len(pixels) == 0:
        raise InvalidArgumentError(f"observers must be an N x 2 array of integer pixels (column, row), N >= 1, "
                                   f"got shape {pixels.shape} and dtype {pixels.dtype}")
    eyes = as_array(observer_height, "observer_height")
    if eyes.ndim > 1 or eyes.ndim == 1 and len(eyes) != len(pixels) or eyes.dtype.kind not in "fiu":
        raise InvalidArgumentError(f"observer_height must be a number or one per observer ({len(pixels)}), got shape "
                                   f"{eyes.shape} and dtype {eyes.dtype}")
    eyes = np.broadcast_to(eyes.astype(np.float64), (len(pixels),))
    return pixels[:, 0].tolist(), pixels[:, 1].tolist(), eyes.tolist()
