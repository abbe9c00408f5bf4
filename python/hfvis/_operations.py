"""The public functions, one per operation, each taking a 2-D numpy array (pixels, cell_size in
ground units) or an xarray DataArray (georeferenced; Dask-backed ones chunk by chunk). Keyword
arguments are named as the C++ library's options (docs/python.md lists them)."""

import collections
import math
import warnings

import numpy as np

from . import _arrays, _core
from ._errors import InputTypeError, InvalidArgumentError

Horizons = collections.namedtuple("Horizons", "values azimuths")
Intervisibility = collections.namedtuple("Intervisibility", "visible_count visible_area")
SunShading = collections.namedtuple("SunShading", "sun direct")
Insolation = collections.namedtuple("Insolation", "sun_hours direct")
ErrorEstimate = collections.namedtuple("ErrorEstimate", "values error directions estimated_error")
HorizonEstimate = collections.namedtuple("HorizonEstimate", "values azimuths error directions estimated_error")
IntervisibilityEstimate = collections.namedtuple("IntervisibilityEstimate",
                                                 "visible_count visible_area error directions estimated_error")
RegionVisibility = collections.namedtuple("RegionVisibility", "fraction bits rgb", defaults=(None,))
RegionPairVisibility = collections.namedtuple(
    "RegionPairVisibility", "bits sources receivers source_fraction receiver_fraction clear_pairs pairs "
    "visible_fraction sources_xy receivers_xy")
Pvs = collections.namedtuple("Pvs", "sets bits computed layout samples rays entries rejected filtered pixel_error "
                                    "seconds history witnesses estimate_samples discontinuities")

# Lighting and fields of view take row 0 as north: a DataArray whose rows run south-up (or
# columns west) is computed flipped.
_LIT = ("sun_shading", "insolation", "environment_light", "viewshed", "cumulative_viewshed")

_UNITS = {
    "angles": "radians above the horizontal; -pi/2 where the ray leaves the field at once",
    "distances": "ground units (of the cell size); 0 where no point casts a horizon or the surface's own slope "
                 "is the horizon",
    "sky_view_factor": "1 (fraction of the sky visible, 0..1)",
    "ambient_occlusion": "1 (irradiance from a uniform sky of radiance 1, flat ground 1)",
    "visible_count": "visible samples summed over the directions, in 1/samples_per_unit pixel lengths",
    "visible_area": "ground units squared",
    "sun": "1 (fraction of the sun's disc above the horizon)",
    "direct": "1 (irradiance from a sun of normal irradiance 1)",
    "sun_hours": "hours",
    "visible": "1 (1 seen, 0 hidden or out of range)",
    "count": "observers",
    "irradiance": "radiance units times steradians (pi on open flat ground under radiance 1)",
    "fraction": "1 (the share of the source samples seen, 0..1)",
    "bits": "bit patterns: bit s % 32 of plane s // 32 set where source sample s is seen; 0 at nodata",
    "rgb": "the light image's values (the colours of the source samples seen, summed, / S)",
    "error": ("absolute, in the output's unit (sky-view factor, occlusion: half the difference of the even- and "
              "odd-numbered directions' results, occlusion's plus its swaths' bias from the pixel's tilt, with "
              "max_error over the Richardson divisor its runs measured; "
              "horizon angles: the estimated mean interpolation error over azimuth, radians)"),
}
_INSOLATION_DIRECT = "hours (direct irradiation from a sun of normal irradiance 1; times W/m^2 it is Wh/m^2)"
_BOUNCE_IRRADIANCE = ("radiance units times steradians (W/m^2 for W m^-2 sr^-1; flat ground receives 0); a "
                      "Lambertian surface of albedo rho re-emits rho * E / pi")


def _is_dataarray(value):
    try:
        import xarray as xr
    except ImportError:
        return False
    return isinstance(value, xr.DataArray)


def _is_dask(value):
    return type(value).__module__.startswith("dask.")


def _require_known_chunks(heights):
    """A Dask-backed DataArray's chunk sizes must be known (boolean indexing leaves them NaN: Dask's,
    xarray's or a "100 x nan field" error before)."""
    data = getattr(heights, "data", None)
    if _is_dask(data) and any(math.isnan(n) for n in data.shape):
        raise InvalidArgumentError(f"the Dask array's chunk sizes are unknown (shape {data.shape}, as after boolean "
                                   "indexing): call .compute_chunk_sizes() on the array first")


def _computed(heights):
    """A Dask-backed DataArray computed, for the operations that take the field in one piece."""
    _require_known_chunks(heights)
    return heights.compute()


def _method(operation, options):
    if operation in ("viewshed", "cumulative_viewshed"):
        return "exact sight lines on the bilinear surface"
    if operation == "intervisibility":
        return options.get("method") or "hull_tree"
    if operation == "region_visibility":
        return options.get("method") or "auto"
    if operation == "bounce":
        return "tree"
    return options.get("method") or "sweep"


def _run(operation, heights, options, common):
    """The outputs of `operation` (a dict by output name) and, for a DataArray, its Grid."""
    if _is_dask(heights):
        raise InputTypeError("a Dask array needs its grid: wrap it in an xarray DataArray "
                             "(xarray.DataArray(array, dims=('y', 'x')))")
    if not _is_dataarray(heights):
        g = _arrays.geometry(common["cell_size"], common["z_scale"])
        h = _arrays.heights_array(heights, common["nodata"], min(g["cell_size_x"], g["cell_size_y"]))
        return _arrays.compute(operation, h, g, options, common["device"], common["progress"]), None
    from . import _xarray

    _require_known_chunks(heights)
    grid = _xarray.Grid(heights)
    g = grid.geometry(common["cell_size"], common["z_scale"])
    flip_rows, flip_cols = grid.flips() if operation in _LIT else (False, False)
    options = _observers_as_pixels(operation, options, grid, flip_rows, flip_cols, common["pixels"])
    options = _places_as_pixels(operation, options, grid, common["pixels"])
    if flip_rows:
        g = dict(g, row_cell_size_x=g["row_cell_size_x"][::-1], row_cell_size_y=g["row_cell_size_y"][::-1])
    data, nodata = _marked(grid.array.data, grid.nodata + (common["nodata"],), *_xarray.scale_offset(grid.array))
    if _is_dask(data):
        from . import _dask

        if data.dtype.kind not in "fiu":
            raise InputTypeError(f"heights must hold real numbers (a float or integer dtype), got dtype {data.dtype}")
        _arrays.nodata_holes(np.zeros((1, 1), dtype=data.dtype), nodata)  # (a bad nodata refused now)
        if _arrays.float32_may_round(data.dtype):
            data = _dask.kept_in_float32(data, nodata, min(g["cell_size_x"], g["cell_size_y"]))
        elif nodata is not None and not math.isnan(float(nodata)):
            data = data.map_blocks(_nodata_as_nan, nodata, dtype=np.float32)
        data = _flipped(data.astype(np.float32), flip_rows, flip_cols)
        if common["progress"] is not None:  # (it was accepted and never called)
            warnings.warn("progress is not called for a Dask array (its chunks run as Dask's tasks): use Dask's "
                          "own progress bar (dask.diagnostics.ProgressBar)", stacklevel=3)
        if operation == "cumulative_viewshed":
            out = {"count": _dask.cumulative_viewshed(data, g, options, common["device"],
                                                       flips=(flip_rows, flip_cols))}
        elif operation == "viewshed":
            out = {"visible": _dask.viewshed(data, g, options, common["device"], flips=(flip_rows, flip_cols))}
        elif operation in _arrays.DISTANCE_LIMITED:
            out = _dask.chunked(operation, data, g, options, common["device"])
        else:
            raise InvalidArgumentError(f"{operation} does not run chunk by chunk: .compute() the Dask array first")
    else:
        h = _arrays.heights_array(data, nodata, min(g["cell_size_x"], g["cell_size_y"]))
        h = np.ascontiguousarray(_flipped(h, flip_rows, flip_cols))
        try:
            out = _arrays.compute(operation, h, g, options, common["device"], common["progress"])
        except InvalidArgumentError as error:
            raise _arrays.observer_unflipped(error, h.shape, (flip_rows, flip_cols)) from None
    if flip_rows or flip_cols:
        for name in _arrays.OUTPUTS.get(operation, ("irradiance",)):
            out[name] = _flipped(out[name], flip_rows, flip_cols)
    return out, grid


def _marked(data, nodatas, scale, offset):
    """A DataArray's data, and the nodata value left for heights_array (or the Dask path) to mark:
    the data as they are with their one nodata value where there is one value and no scale or
    offset; else a new array (Dask: block by block) with every value of `nodatas` (the array's own
    and the caller's `nodata`, each compared in the data's dtype: the caller's had replaced the
    array's) as NaN and the raster's scale and offset applied in float64 (they were ignored).
    None in `nodatas` is no value."""
    values = []
    for v in nodatas:  # (the caller's nodata, the array's own: one copy of the field less)
        if v is not None and not any(v == w or (v != v and w != w) for w in values):
            values.append(v)
    if scale == 1.0 and offset == 0.0 and len(values) <= 1:
        return data, values[0] if values else None
    if data.dtype.kind not in "fiu":
        raise InputTypeError(f"heights must hold real numbers (a float or integer dtype), got dtype {data.dtype}")
    for v in values:
        _arrays.nodata_holes(np.zeros((1, 1), dtype=data.dtype), v)  # (a bad nodata refused now)
    if _is_dask(data):
        return data.map_blocks(_marked_block, values, scale, offset, dtype=np.float64), None
    return _marked_block(np.asarray(data), values, scale, offset), None


def _marked_block(block, values, scale, offset):
    holes = np.zeros(block.shape, dtype=bool)
    for v in values:
        holes |= _arrays.nodata_holes(block, v)
    wide = block.astype(np.float64)  # (one float64 copy of the block, changed in place below)
    if scale != 1.0:
        wide *= scale
    if offset != 0.0:
        wide += offset
    wide[holes] = np.nan
    return wide


def _nodata_as_nan(block, value):
    return np.where(_arrays.nodata_holes(block, value), np.float32(np.nan), block).astype(np.float32)


def _flipped(a, rows, cols):
    if rows:
        a = a[..., ::-1, :]
    if cols:
        a = a[..., :, ::-1]
    return a


def _observers_as_pixels(operation, options, grid, flip_rows, flip_cols, pixels):
    """A DataArray's observers, given as map coordinates (x, y) unless `pixels`, as the pixels of
    the field computed on (flipped with it)."""
    if operation not in ("viewshed", "cumulative_viewshed"):
        return options
    height, width = grid.array.shape

    def place(col, row):
        return _arrays.flipped_pixel(col, row, (height, width), (flip_rows, flip_cols))

    def pixel_of(x, y):
        if pixels:  # (as a numpy field's: whole numbers; (-0.5, 2.9) ran as (0, 2))
            col, row = _arrays.observer_pixel((x, y))
            if not (0 <= col < width and 0 <= row < height):  # (named here: flipped, the library's would not be)
                raise InvalidArgumentError(f"observer {col},{row} is outside the {width} x {height} field")
            return col, row
        if not (math.isfinite(float(x)) and math.isfinite(float(y))):
            raise InvalidArgumentError(f"an observer's map coordinates must be finite, got ({x!r}, {y!r})")
        col, row = grid.pixel(float(x), float(y))
        if not (0 <= col < width and 0 <= row < height):  # (far off, the pixel overflowed int64: a raw error)
            raise InvalidArgumentError(f"observer ({float(x):.10g}, {float(y):.10g}) in map coordinates lies outside "
                                       f"{_extent(grid)}")
        return col, row

    options = dict(options)
    if operation == "viewshed":
        observer = _arrays.as_array(options["observer"], "observer")
        if observer.shape != (2,):
            raise InvalidArgumentError(f"an observer is a pair (x, y), got {options['observer']!r}")
        options["observer"] = np.array(place(*pixel_of(*observer)))
    else:
        points = _arrays.as_array(options["observers"], "observers")
        if points.ndim != 2 or points.shape[1] != 2:
            raise InvalidArgumentError(f"observers must be an N x 2 array, got shape {points.shape}")
        placed = [place(*pixel_of(x, y)) for x, y in points]
        options["observers"] = np.array(placed, dtype=np.int64).reshape(-1, 2)
    return options


def _places_as_pixels(operation, options, grid, pixels):
    """A DataArray's regions and receivers, given as map coordinates (x, y) unless `pixels`, as
    pixels: a rectangle's corners and receivers the nearest pixel, points their fractional pixel
    position. These operations have no north: the field is never flipped for them."""
    if pixels:
        return options
    options = dict(options)
    for key in ("sources", "receivers"):
        if key not in options:
            continue
        a = _arrays.as_array(options[key], key)
        what = key[:-1]  # (a source, a receiver)
        if operation == "horizon_lists":
            if a.ndim != 2 or a.shape[1] != 2:
                raise InvalidArgumentError(f"receivers must be an N x 2 array, got shape {a.shape}")
            options[key] = np.array([_mapped(grid, grid.pixel, x, y, what) for x, y in a],
                                    dtype=np.int64).reshape(-1, 2)
        elif a.ndim == 1 and a.shape == (4,):
            options[key] = np.array(_mapped(grid, grid.pixel, a[0], a[1], f"{what} rectangle's corner") +
                                    _mapped(grid, grid.pixel, a[2], a[3], f"{what} rectangle's corner"))
        elif a.ndim == 2 and a.shape[1] in (2, 3):
            placed = np.array(a, dtype=np.float64)
            for point in placed:
                point[0], point[1] = _mapped(grid, grid.position, point[0], point[1], f"{what} point")
            options[key] = placed
    return options


def _mapped(grid, convert, x, y, what):
    """The pixel (or pixel position) of map coordinates (x, y): refused, naming them as given, where
    they are not finite or lie so far outside the field that the pixel would not be a number the
    library takes (NaN and inf raised Python's own ValueError and OverflowError; 1e300 a message
    about an array of 300 digits)."""
    try:
        x, y = float(x), float(y)
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"a {what}'s map coordinates must be numbers, got ({x!r}, {y!r})") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise InvalidArgumentError(f"a {what}'s map coordinates must be finite, got ({x!r}, {y!r})")
    col, row = convert(x, y)
    if not (abs(col) < 2 ** 30 and abs(row) < 2 ** 30):
        raise InvalidArgumentError(f"{what} ({x:.10g}, {y:.10g}) in map coordinates lies outside {_extent(grid)}")
    return col, row


def _extent(grid):
    """The field's extent in map coordinates, as messages give it."""
    t, (height, width) = grid.transform, grid.array.shape
    xs, ys = sorted((t[0], t[0] + width * t[1])), sorted((t[3], t[3] + height * t[5]))
    return f"the field's extent, x {xs[0]:.10g} .. {xs[1]:.10g}, y {ys[0]:.10g} .. {ys[1]:.10g}"


_COUNT_ERROR = ("relative to the field's mean count (the even- and odd-numbered directions' counts' difference); "
                "the area is not estimated")


def _attrs(operation, name, options, grid):
    attrs = {"units": _UNITS[name], "hfvis_operation": operation, "hfvis_method": _method(operation, options)}
    if operation == "insolation" and name == "direct":
        attrs["units"] = _INSOLATION_DIRECT
    if operation == "bounce":
        attrs["units"] = _BOUNCE_IRRADIANCE
    if name in ("distances", "visible_area") and grid.geographic:
        attrs["units"] = attrs["units"].replace("ground units", "metres")
    for key, value in options.items():
        if key in ("observers", "environment", "progress", "radiance", "mask"):
            continue
        if isinstance(value, (bool, np.bool_)):
            value = int(value)
        if isinstance(value, (int, float, str)):
            attrs["hfvis_" + key] = value
    return attrs


def _single(operation, name, heights, options, common):
    out, grid = _run(operation, heights, options, common)
    if grid is None:
        return out[name]
    return grid.result(out[name], name, _attrs(operation, name, options, grid))


def _pair(operation, kind, heights, options, common):
    out, grid = _run(operation, heights, options, common)
    names = _arrays.OUTPUTS[operation]
    if grid is None:
        return kind(*(out[n] for n in names))
    import xarray as xr

    return xr.Dataset({n: grid.result(out[n], n, _attrs(operation, n, options, grid)) for n in names})


def _whole(name, value, least, most):
    """An integer option: a whole number (8.0 is 8; 8.5 or "8" is refused, as int() would truncate
    or parse them) within least .. most (None: the library judges the least and says why)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)) or \
            not float(value).is_integer():
        raise InvalidArgumentError(f"{name} must be a whole number, got {value!r}")
    whole = int(value)
    if (least is not None and whole < least) or whole > most:
        bound = f"lie in {least} .. {most}" if least is not None else f"be at most {most}"
        raise InvalidArgumentError(f"{name} must {bound}, got {whole}")
    return whole


def _real(name, value, least=None, most=None):
    """A number option as a float; anything else refused with its name (None, text or a list gave
    float()'s bare TypeError or ValueError); within least .. most where given (the CLI's ranges)."""
    if np.ndim(value) != 0 or np.asarray(value).dtype.kind not in "iuf":
        raise InvalidArgumentError(f"{name} must be a number, got {value!r}")
    number = float(value)
    if least is not None and not (least <= number <= most):
        raise InvalidArgumentError(f"{name} must lie in {least:g} .. {most:g}, what the kernels' single precision "
                                   f"holds, got {number:g}")
    return number


# The CLI's limits of lengths and heights (ground units): within them distances, their squares and
# the sums over a field stay inside single precision.
_MOST_LENGTH = 1e12


def _height(name, value, absolute, what):
    """A height above the surface (absolute: above 0): within the CLI's range, and >= 0 unless
    absolute, as the CLI's (a negative one put the eye or sample below the surface: `what`)."""
    number = _real(name, value, -_MOST_LENGTH, _MOST_LENGTH)
    if number < 0 and not absolute:
        raise InvalidArgumentError(f"{name} {number:g}: {what}; give a height >= 0 (or absolute=True)")
    return number


def _heights(name, value, absolute, what):
    """A height or one per point (an array, left as given for the library's own checks of its
    shape), its least and greatest each as _height's."""
    if np.ndim(value) == 0:
        return _height(name, value, absolute, what)
    values = np.asarray(value)
    if values.dtype.kind in "iuf" and values.size:
        _height(name, np.nanmin(values), absolute, what)
        _height(name, np.nanmax(values), absolute, what)
    return value


def _max_distance(value):
    return _real("max_distance", value, 0.0, _MOST_LENGTH)


def _target_height(value):
    return _real("target_height", value, 0.0, _MOST_LENGTH)


def _points(name, value, absolute, what):
    """A region: a rectangle (4 numbers, left to the library) or N x 2 / N x 3 points, whose
    heights (the third column) _heights checks."""
    try:
        values = np.asarray(value) if not isinstance(value, (str, bytes)) else None
    except ValueError:  # (ragged: the library's own message names it)
        values = None
    if values is not None and values.ndim == 2 and values.shape[1] == 3 and values.dtype.kind in "iuf":
        _heights(f"{name}' heights", values[:, 2], absolute, what)
    return value


_EYE_BELOW = "an eye below the surface sees nothing"
_SAMPLE_BELOW = "a sample below the surface is hidden from everything"


def _flag(name, value):
    """A yes / no option: True or False, numpy's too (a 0-d array among them), or the integers 1
    and 0; anything else refused (bool() took absolute="no" for True)."""
    kind = np.asarray(value).dtype.kind if isinstance(value, (bool, int, np.generic, np.ndarray)) else ""
    if np.ndim(value) == 0 and (kind == "b" or kind in "iu" and kind and value in (0, 1)):
        return bool(value)
    raise InvalidArgumentError(f"{name} must be True or False, got {value!r}")


def _budget(memory_budget_bytes):
    return _whole("memory_budget_bytes", memory_budget_bytes, 0, 2**63 - 1)


def _common(cell_size, z_scale, nodata, device, progress, pixels=False):
    if progress is not None and not callable(progress):  # (5 gave "'int' object is not callable" mid-run)
        raise InvalidArgumentError(f"progress must be a callable or None, got {progress!r}")
    # (an int, as devices()'s "index", was nanobind's bare TypeError)
    if device is not None and not isinstance(device, (str, int, np.integer)) or isinstance(device, bool) or \
            isinstance(device, (int, np.integer)) and device < 0:
        raise InvalidArgumentError(f"device must be a selector string (\"cpu\", \"gpu\", a name) or an index of "
                                   f"hfvis.devices(), got {device!r}")
    return {"cell_size": cell_size, "z_scale": z_scale, "nodata": nodata,
            "device": str(int(device)) if isinstance(device, (int, np.integer)) else device or "",
            "progress": progress, "pixels": pixels}


def _horizon(directions, azimuth_offset, samples_per_unit, curvature, max_distance, memory_budget_bytes, method,
             azimuth_tolerance, strip_rows):
    return {"directions": _whole("directions", directions, None, 2**31 - 1),
            "azimuth_offset": _real("azimuth_offset", azimuth_offset),
            "samples_per_unit": _real("samples_per_unit", samples_per_unit),
            "curvature": _real("curvature", curvature), "max_distance": _max_distance(max_distance),
            "memory_budget_bytes": _budget(memory_budget_bytes), "method": method,
            "azimuth_tolerance": None if azimuth_tolerance is None else _real("azimuth_tolerance", azimuth_tolerance),
            "strip_rows": _whole("strip_rows", strip_rows, 0, 2**31 - 1)}


def _horizon_maps(operation, name, heights, options, common):
    out, grid = _run(operation, heights, options, common)
    if grid is None:
        return Horizons(out[name], out["azimuths"])
    azimuths = np.degrees(np.asarray(out["azimuths"])) if "azimuths" in out else \
        _azimuths_deg(options, grid.geometry(common["cell_size"], common["z_scale"]))
    attrs = _attrs(operation, name, options, grid)
    attrs["azimuth_convention"] = _xarray_convention()
    result = grid.result(out[name], "horizon_" + name, attrs, leading=("azimuth", azimuths))
    result["azimuth"].attrs.update(units="degrees", long_name="azimuth as computed",
                                   convention=_xarray_convention())
    return result


def _xarray_convention():
    from ._xarray import AZIMUTH_CONVENTION

    return AZIMUTH_CONVENTION


def _azimuths_deg(options, geometry):
    """The azimuths a chunked run computes (each chunk takes the whole field's: they depend on K,
    the tolerance and the cell sizes), from the sweep of a field two pixels wide with the field's
    geometry (its rows' spacing too, on a latitude / longitude grid)."""
    rows = max(2, len(geometry["row_cell_size_x"]))
    probe = _arrays.compute("horizon_angles", np.zeros((rows, 2), np.float32), dict(geometry, origin=[]), options)
    return np.degrees(np.asarray(probe["azimuths"]))


def _max_error(value):
    """max_error as a float, or None where it asks for none (None, False or 0)."""
    if value in (None, False):
        return None
    return _real("max_error", value) or None  # ("x" was float()'s bare ValueError)


def _with_estimate(options, heights, max_error, error_estimate):
    """Adds max_error and error_estimate to the options; a Dask-backed DataArray is computed, since
    K and the estimate's mean or percentile are the whole field's: it runs in one piece."""
    error = _max_error(max_error)
    if error is not None:
        options["max_error"] = error
    if error_estimate:
        options["error_estimate"] = True
    if _is_dataarray(heights) and _is_dask(heights.data):
        heights = _computed(heights)
    return heights


def horizon_angles(heights, *, directions=64, azimuth_offset=0.0, samples_per_unit=1.0, curvature=0.0,
                   max_distance=0.0, method="sweep", azimuth_tolerance=None, strip_rows=0, memory_budget_bytes=0,
                   max_error=0.0, error_estimate=False, cell_size=None, z_scale=1.0, nodata=None, device="",
                   progress=None):
    """The horizon elevation angle (radians) of every pixel in K directions. numpy: Horizons(values
    K x H x W, azimuths in radians); DataArray: dims (azimuth, y, x), azimuth in degrees.
    max_error=E (radians) chooses K (directions ignored) so that the estimated mean horizon angle
    error (the K planes interpolated in azimuth against the true horizon, as the CLI's horizon
    --max-error in degrees) is at most E; with it or error_estimate=True (K >= 5): numpy
    HorizonEstimate(values, azimuths, error, directions, estimated_error), the error per pixel in
    radians; a DataArray with the K and the estimate in its attrs (and a Dataset with the per-pixel
    error under error_estimate=True)."""
    error_estimate = _flag("error_estimate", error_estimate)
    options = _horizon(directions, azimuth_offset, samples_per_unit, curvature, max_distance, memory_budget_bytes,
                       method, azimuth_tolerance, strip_rows)
    common = _common(cell_size, z_scale, nodata, device, progress)
    if not max_error and not error_estimate:
        return _horizon_maps("horizon_angles", "angles", heights, options, common)
    heights = _with_estimate(options, heights, max_error, error_estimate)
    out, grid = _run("horizon_angles", heights, options, common)
    if grid is None:
        return HorizonEstimate(out["angles"], out["azimuths"], out["error"], out["directions"],
                               out["estimated_error"])
    options = dict(options, directions=out["directions"])
    attrs = _attrs("horizon_angles", "angles", options, grid)
    attrs["azimuth_convention"] = _xarray_convention()
    attrs["hfvis_estimated_error"] = out["estimated_error"]
    values = grid.result(out["angles"], "horizon_angles", attrs,
                         leading=("azimuth", np.degrees(np.asarray(out["azimuths"]))))
    values["azimuth"].attrs.update(units="degrees", long_name="azimuth as computed", convention=_xarray_convention())
    if not error_estimate:
        return values
    import xarray as xr

    error = grid.result(out["error"], "error", dict(_attrs("horizon_angles", "error", options, grid),
                                                    hfvis_estimated_error=out["estimated_error"],
                                                    hfvis_directions=out["directions"]))
    return xr.Dataset({"horizon_angles": values, "error": error})


def horizon_distances(heights, *, directions=64, azimuth_offset=0.0, samples_per_unit=1.0, curvature=0.0,
                      max_distance=0.0, method="sweep", azimuth_tolerance=None, strip_rows=0, memory_budget_bytes=0,
                      cell_size=None, z_scale=1.0, nodata=None, device="", progress=None):
    """The ground distance to the point casting each horizon (as horizon_angles)."""
    options = _horizon(directions, azimuth_offset, samples_per_unit, curvature, max_distance, memory_budget_bytes,
                       method, azimuth_tolerance, strip_rows)
    return _horizon_maps("horizon_distances", "distances", heights, options,
                         _common(cell_size, z_scale, nodata, device, progress))


def sky_view_factor(heights, *, directions=64, azimuth_offset=0.0, samples_per_unit=1.0, curvature=0.0,
                    max_distance=0.0, method="sweep", azimuth_tolerance=None, strip_rows=0, memory_budget_bytes=0,
                    max_error=0.0, error_estimate=False, cell_size=None, z_scale=1.0, nodata=None, device="",
                    progress=None):
    """The sky-view factor 1 - sum_k w_k sin(max(0, e_k)) (Zaksek, Ostir & Kokalj 2011), 0..1.
    max_error=E chooses K (directions ignored) so that the 99th percentile of the error estimate
    is at most E; with it or error_estimate=True: numpy ErrorEstimate(values, error, directions,
    estimated_error); a DataArray with the K and the estimate in its attrs (and a Dataset with
    the per-pixel error under error_estimate=True)."""
    options = _horizon(directions, azimuth_offset, samples_per_unit, curvature, max_distance, memory_budget_bytes,
                       method, azimuth_tolerance, strip_rows)
    return _swept_quantity("sky_view_factor", heights, options, max_error, error_estimate,
                           _common(cell_size, z_scale, nodata, device, progress))


def ambient_occlusion(heights, *, directions=64, azimuth_offset=0.0, samples_per_unit=1.0, curvature=0.0,
                      max_distance=0.0, method="sweep", azimuth_tolerance=None, strip_rows=0, memory_budget_bytes=0,
                      max_error=0.0, error_estimate=False, cell_size=None, z_scale=1.0, nodata=None, device="",
                      progress=None):
    """Ambient occlusion under a uniform sky (Timonen & Westerholm 2010, Eq. 5), flat ground 1.
    max_error and error_estimate as sky_view_factor's."""
    options = _horizon(directions, azimuth_offset, samples_per_unit, curvature, max_distance, memory_budget_bytes,
                       method, azimuth_tolerance, strip_rows)
    return _swept_quantity("ambient_occlusion", heights, options, max_error, error_estimate,
                           _common(cell_size, z_scale, nodata, device, progress))


def _swept_quantity(operation, heights, options, max_error, error_estimate, common):
    """The sky-view factor or occlusion; with max_error or error_estimate, the K run and the error
    estimate too, as the CLI's --max-error and --error-out give them."""
    error_estimate = _flag("error_estimate", error_estimate)
    if not max_error and not error_estimate:
        return _single(operation, operation, heights, options, common)
    heights = _with_estimate(options, heights, max_error, error_estimate)
    out, grid = _run(operation, heights, options, common)
    if grid is None:
        return ErrorEstimate(out[operation], out["error"], out["directions"], out["estimated_error"])
    attrs = _attrs(operation, operation, dict(options, directions=out["directions"]), grid)
    attrs["hfvis_estimated_error"] = out["estimated_error"]
    if "richardson_divisor" in out:  # max_error: the divisor and each run's K (the CLI's attributes)
        attrs["hfvis_richardson_divisor"] = out["richardson_divisor"]
        attrs["hfvis_runs"] = list(out["runs"])
    values = grid.result(out[operation], operation, attrs)
    if not error_estimate:
        return values
    import xarray as xr

    error = grid.result(out["error"], "error", dict(_attrs(operation, "error", options, grid),
                                                    hfvis_estimated_error=out["estimated_error"],
                                                    hfvis_directions=out["directions"]))
    return xr.Dataset({operation: values, "error": error})


def intervisibility(heights, *, directions=64, azimuth_offset=0.0, samples_per_unit=1.0, curvature=0.0,
                    max_distance=0.0, method="hull_tree", strip_rows=0, memory_budget_bytes=0, max_error=0.0,
                    error_estimate=False, cell_size=None, z_scale=1.0, nodata=None, device="", progress=None):
    """How much of the surface each point sees (Timonen 2013's convex hull tree): visible samples
    and visible ground area. numpy: Intervisibility(visible_count, visible_area); DataArray: a
    Dataset of the two. max_error=E (hull tree only) chooses K (directions ignored) so that the
    99th percentile of the count's error estimate, relative to the field's mean count, is at most
    E, as the CLI's --max-error; with it or error_estimate=True: numpy
    IntervisibilityEstimate(visible_count, visible_area, error, directions, estimated_error); a
    Dataset with the K and the estimate in its variables' attrs (and the per-pixel error as the
    variable "error" under error_estimate=True)."""
    error_estimate = _flag("error_estimate", error_estimate)
    options = _horizon(directions, azimuth_offset, samples_per_unit, curvature, max_distance, memory_budget_bytes,
                       method, None, strip_rows)
    del options["azimuth_tolerance"]
    common = _common(cell_size, z_scale, nodata, device, progress)
    if not max_error and not error_estimate:
        return _pair("intervisibility", Intervisibility, heights, options, common)
    heights = _with_estimate(options, heights, max_error, error_estimate)
    out, grid = _run("intervisibility", heights, options, common)
    if grid is None:
        return IntervisibilityEstimate(out["visible_count"], out["visible_area"], out["error"], out["directions"],
                                       out["estimated_error"])
    import xarray as xr

    attrs = dict(hfvis_directions=out["directions"], hfvis_estimated_error=out["estimated_error"])
    chosen = dict(options, directions=out["directions"])
    names = _arrays.OUTPUTS["intervisibility"] + (("error",) if error_estimate else ())
    variables = {n: grid.result(out[n], n, dict(_attrs("intervisibility", n, chosen, grid), **attrs)) for n in names}
    if error_estimate:
        variables["error"].attrs["units"] = _COUNT_ERROR
    return xr.Dataset(variables)


def _field_of_view(azimuth_from_deg, azimuth_to_deg):
    """The azimuths of a field of view (both None: the whole circle). The library takes FROM = TO
    for the whole circle, so equal ones given are refused, as the CLI's --fov (90, 90 saw
    everything)."""
    if azimuth_from_deg is None and azimuth_to_deg is None:
        return {"azimuth_from_deg": 0.0, "azimuth_to_deg": 0.0}
    if azimuth_from_deg is None or azimuth_to_deg is None:
        raise InvalidArgumentError("give both azimuth_from_deg and azimuth_to_deg (or neither, for the whole circle)")
    start, end = _real("azimuth_from_deg", azimuth_from_deg), _real("azimuth_to_deg", azimuth_to_deg)
    if start == end:
        raise InvalidArgumentError(f"azimuth_from_deg = azimuth_to_deg = {start:g} is no field of view; leave both out, "
                                   "or give 0 and 360, for the whole circle")
    return {"azimuth_from_deg": start, "azimuth_to_deg": end}


def _sight(absolute, target_height, max_distance, curvature, azimuth_from_deg, azimuth_to_deg, elevation_min_deg,
           elevation_max_deg, memory_budget_bytes):
    """The options a viewshed and a cumulative viewshed share."""
    return {"absolute": _flag("absolute", absolute), "target_height": _target_height(target_height),
            "max_distance": _max_distance(max_distance), "curvature": _real("curvature", curvature),
            **_field_of_view(azimuth_from_deg, azimuth_to_deg),
            "elevation_min_deg": _real("elevation_min_deg", elevation_min_deg),
            "elevation_max_deg": _real("elevation_max_deg", elevation_max_deg),
            "memory_budget_bytes": _budget(memory_budget_bytes)}


def viewshed(heights, observer, *, observer_height=2.0, absolute=False, target_height=0.0, max_distance=0.0,
             curvature=0.0, azimuth_from_deg=None, azimuth_to_deg=None, elevation_min_deg=-90.0,
             elevation_max_deg=90.0, memory_budget_bytes=0, pixels=False, cell_size=None, z_scale=1.0, nodata=None,
             device=""):
    """What an observer sees: 1 visible, 0 hidden or out of range, NaN at nodata. `observer`: a
    pixel (column, row) for a numpy array; map coordinates (x, y) for a DataArray (a pixel with
    pixels=True)."""
    options = {"observer": observer,
               "observer_height": _height("observer_height", observer_height, _flag("absolute", absolute), _EYE_BELOW),
               **_sight(absolute, target_height, max_distance, curvature, azimuth_from_deg, azimuth_to_deg,
                        elevation_min_deg, elevation_max_deg, memory_budget_bytes)}
    return _single("viewshed", "visible", heights, options, _common(cell_size, z_scale, nodata, device, None, pixels))


def cumulative_viewshed(heights, observers, *, observer_height=2.0, absolute=False, target_height=0.0,
                        max_distance=0.0, curvature=0.0, azimuth_from_deg=None, azimuth_to_deg=None,
                        elevation_min_deg=-90.0, elevation_max_deg=90.0, memory_budget_bytes=0, pixels=False,
                        cell_size=None, z_scale=1.0, nodata=None, device="", progress=None):
    """How many of the observers (an N x 2 array: pixels (column, row), or map coordinates (x, y)
    for a DataArray) see each point; observer_height a number or one per observer. A Dask-backed
    DataArray splits the observers into groups computed as separate tasks and sums them."""
    options = {"observers": observers, "observer_height": _heights("observer_height", observer_height,
                                                                   _flag("absolute", absolute), _EYE_BELOW),
               **_sight(absolute, target_height, max_distance, curvature, azimuth_from_deg, azimuth_to_deg,
                        elevation_min_deg, elevation_max_deg, memory_budget_bytes)}
    return _single("cumulative_viewshed", "count", heights, options,
                   _common(cell_size, z_scale, nodata, device, progress, pixels))


def sun_shading(heights, azimuth_deg, elevation_deg, *, size_deg=0.53, samples_per_unit=1.0, curvature=0.0,
                max_distance=0.0, memory_budget_bytes=0, cell_size=None, z_scale=1.0, nodata=None, device="",
                progress=None):
    """The sun's light with cast shadows: the fraction of its disc each point sees (sun) and the
    direct irradiance that brings (direct). The sun at compass azimuth and elevation (degrees),
    row 0 north. numpy: SunShading(sun, direct); DataArray: a Dataset."""
    options = {"azimuth_deg": _real("azimuth_deg", azimuth_deg),
               "elevation_deg": _real("elevation_deg", elevation_deg), "size_deg": _real("size_deg", size_deg),
               "samples_per_unit": _real("samples_per_unit", samples_per_unit),
               "curvature": _real("curvature", curvature),
               "max_distance": _max_distance(max_distance), "memory_budget_bytes": _budget(memory_budget_bytes)}
    return _pair("sun_shading", SunShading, heights, options, _common(cell_size, z_scale, nodata, device, progress))


def insolation(heights, latitude_deg, longitude_deg, start, end, *, step_minutes=10.0, size_deg=0.53,
               azimuth_bucket_deg=0.25, apparent=False, samples_per_unit=1.0, curvature=0.0, max_distance=0.0,
               memory_budget_bytes=0, cell_size=None, z_scale=1.0, nodata=None, device="", progress=None):
    """Hours of sun and direct irradiation from `start` to `end` (ISO 8601 texts with a zone, aware
    datetimes, or seconds since 1970) at a place. numpy: Insolation(sun_hours, direct)."""
    options = {"latitude_deg": _real("latitude_deg", latitude_deg),
               "longitude_deg": _real("longitude_deg", longitude_deg),
               "start": start if isinstance(start, str) else _arrays.utc_seconds(start),
               "end": end if isinstance(end, str) else _arrays.utc_seconds(end),
               "step_minutes": _real("step_minutes", step_minutes), "size_deg": _real("size_deg", size_deg),
               "azimuth_bucket_deg": _real("azimuth_bucket_deg", azimuth_bucket_deg),
               "apparent": _flag("apparent", apparent),
               "samples_per_unit": _real("samples_per_unit", samples_per_unit),
               "curvature": _real("curvature", curvature),
               "max_distance": _max_distance(max_distance), "memory_budget_bytes": _budget(memory_budget_bytes)}
    return _pair("insolation", Insolation, heights, options, _common(cell_size, z_scale, nodata, device, progress))


def environment_light(heights, environment, *, rotation_deg=0.0, table_rows=0, directions=64, azimuth_offset=0.0,
                      samples_per_unit=1.0, curvature=0.0, max_distance=0.0, method="sweep", azimuth_tolerance=None,
                      memory_budget_bytes=0, max_error=0.0, cell_size=None, z_scale=1.0, nodata=None, device="",
                      progress=None):
    """The irradiance an HDR environment gives each point through its horizons (Timonen &
    Westerholm 2010, Sec. 6.2). `environment`: a file (EXR, HDR, ...) or radiance as an
    equirectangular (rows, 2 rows) or (channels, rows, 2 rows) array, row 0 at the zenith, the
    left edge north. Returns (channels, H, W), or (H, W) for one channel. max_error=E chooses K
    (directions ignored) as the CLI's shade --env --max-error (|irradiance at K - at K / 2|, the
    larger of K / 2 on K's even and on its odd directions, over the mean, relative): numpy ErrorEstimate(values, error, directions, estimated_error); a
    DataArray with the K and the estimate in its attrs."""
    options = _horizon(directions, azimuth_offset, samples_per_unit, curvature, max_distance, memory_budget_bytes,
                       method, azimuth_tolerance, 0)
    options.update(environment=environment, rotation_deg=_real("rotation_deg", rotation_deg),
                   table_rows=_whole("table_rows", table_rows, 0, 2**31 - 1))
    common = _common(cell_size, z_scale, nodata, device, progress)
    error = _max_error(max_error)
    if error is not None:
        options["max_error"] = error
        if _is_dataarray(heights) and _is_dask(heights.data):
            heights = _computed(heights)  # K and the estimate's percentile are the whole field's: in one piece
    if _is_dataarray(heights) and _is_dask(heights.data):
        # Chunk by chunk within the maximum distance: the channels, which each block's planes
        # follow, from a one-cell field's run (they depend on the environment alone).
        options["channels"] = list(_arrays.compute("environment_light", np.zeros((2, 2), np.float32),
                                                   _arrays.geometry(), options)["channels"])
    out, grid = _run("environment_light", heights, options, common)
    irradiance, channels = out["irradiance"], list(out.get("channels", options.get("channels", [])))
    if grid is None:
        values = irradiance[0] if len(channels) == 1 else irradiance
        return ErrorEstimate(values, out["error"], out["directions"], out["estimated_error"]) if max_error else values
    attrs = _attrs("environment_light", "irradiance", options, grid)
    if max_error:
        attrs.update(hfvis_directions=out["directions"], hfvis_estimated_error=out["estimated_error"])
    if len(channels) == 1:
        return grid.result(irradiance[0], "irradiance", attrs)
    return grid.result(irradiance, "irradiance", attrs, leading=("channel", channels))


def region_visibility(heights, sources, *, samples=16, height=2.0, absolute=False, target_height=0.0,
                      method="auto", seed=1, decorrelate=False, max_distance=0.0, curvature=0.0, light_image=None,
                      pixels=False, cell_size=None, z_scale=1.0, nodata=None, device="", progress=None):
    """Which samples of a source region (an area light) every point sees, standing target_height
    above the surface (after Eisemann & Decoret 2007). `sources`: a rectangle (col0, row0, col1,
    row1) of grid points, corners inclusive, sampled `samples` times `height` above the surface
    (absolute=True: at that height); or an N x 2 (col, row) or N x 3 (col, row, height) array of
    points. A DataArray takes map coordinates (x0, y0, x1, y1) or (x, y[, height]) unless
    pixels=True. numpy: RegionVisibility(fraction H x W, 0..1, NaN at nodata; bits ceil(S/32) x
    H x W uint32, bit s % 32 of plane s // 32 for sample s); DataArray: a Dataset of the two.
    Computed in one piece (a Dask array is computed first). progress(done, total) hears each launch
    of receivers (method "viewsheds": each source sample). light_image (a rectangle's light only):
    its colours, 3 x rows x columns (R, G, B) or rows x columns (grey), finite and >= 0, stretched
    over the rectangle (row 0 along its lowest row), each sample taking the bilinear colour at its
    position (as arealight --light-image); then rgb (3 x H x W; DataArray: a Dataset variable
    "rgb" over "channel" R, G, B): per point the colours of the samples it sees, summed, / S."""
    is_absolute = _flag("absolute", absolute)
    options = {"sources": _points("sources", sources, is_absolute, _SAMPLE_BELOW),
               "samples": _whole("samples", samples, None, 2**31 - 1),
               "height": _height("height", height, is_absolute, _SAMPLE_BELOW),
               "absolute": is_absolute,
               "target_height": _target_height(target_height), "method": method,
               "seed": _whole("seed", seed, 0, 2**32 - 1),
               "decorrelate": _flag("decorrelate", decorrelate), "max_distance": _max_distance(max_distance),
               "curvature": _real("curvature", curvature),
               "light_image": light_image}
    if _is_dataarray(heights) and _is_dask(heights.data):
        heights = _computed(heights)  # the sources are shared by every point: the field in one piece
    out, grid = _run("region_visibility", heights, options,
                     _common(cell_size, z_scale, nodata, device, progress, pixels))
    if grid is None:
        return RegionVisibility(out["fraction"], out["bits"], out.get("rgb"))
    import xarray as xr

    options["method"] = out["method"]  # the one that ran ("auto" picks bitmask or culled)
    fraction = grid.result(out["fraction"], "fraction", _attrs("region_visibility", "fraction", options, grid))
    bits = grid.result(out["bits"], "bits", _attrs("region_visibility", "bits", options, grid),
                       leading=("word", np.arange(out["bits"].shape[0])))
    variables = {"fraction": fraction, "bits": bits}
    if "rgb" in out:
        variables["rgb"] = grid.result(out["rgb"], "rgb", _attrs("region_visibility", "rgb", options, grid),
                                       leading=("channel", ["R", "G", "B"]))
    return xr.Dataset(variables, attrs={"hfvis_samples": out["samples"]})


def region_pair_visibility(heights, sources, receivers, *, samples=16, source_height=2.0, receiver_height=2.0,
                           absolute=False, method="auto", seed=1, decorrelate=False, max_distance=0.0,
                           curvature=0.0, pixels=False, cell_size=None, z_scale=1.0, nodata=None, device="",
                           progress=None):
    """Visibility between two regions, each a rectangle or points as region_visibility's
    `sources` (a rectangle sampled `samples` times): which source samples each receiver sample
    sees. Returns RegionPairVisibility: bits (R x ceil(S/32) uint32, bit s % 32 of word s // 32),
    sources and receivers (N x 3: col, row, absolute z-scaled height), source_fraction and
    receiver_fraction (the share of the other region's samples each sees), clear_pairs, pairs,
    visible_fraction, and sources_xy / receivers_xy (map coordinates of a georeferenced
    DataArray, else None). progress as region_visibility's."""
    is_absolute = _flag("absolute", absolute)
    options = {"sources": _points("sources", sources, is_absolute, _SAMPLE_BELOW),
               "receivers": _points("receivers", receivers, is_absolute, _SAMPLE_BELOW),
               "samples": _whole("samples", samples, None, 2**31 - 1),
               "source_height": _height("source_height", source_height, is_absolute, _SAMPLE_BELOW),
               "receiver_height": _height("receiver_height", receiver_height, is_absolute, _SAMPLE_BELOW),
               "absolute": is_absolute, "method": method, "seed": _whole("seed", seed, 0, 2**32 - 1),
               "decorrelate": _flag("decorrelate", decorrelate),
               "max_distance": _max_distance(max_distance), "curvature": _real("curvature", curvature)}
    if _is_dataarray(heights) and _is_dask(heights.data):
        heights = _computed(heights)
    out, grid = _run("region_pair_visibility", heights, options,
                     _common(cell_size, z_scale, nodata, device, progress, pixels))

    def xy(points):
        if grid is None or grid.transform is None:
            return None
        return np.array([grid.map_position(c, r) for c, r, _ in points], dtype=np.float64).reshape(-1, 2)

    pairs = int(out["pairs"])
    return RegionPairVisibility(out["bits"], out["sources"], out["receivers"], out["source_fraction"],
                                out["receiver_fraction"], int(out["clear_pairs"]), pairs,
                                int(out["clear_pairs"]) / pairs if pairs else 0.0, xy(out["sources"]),
                                xy(out["receivers"]))


def _pvs_start(start):
    """An earlier run's bits (its Pvs.bits: view cells x words) as uint32; their shape is checked
    against the grid's when the field's size is known (_arrays). Another dtype, a shape other than
    2-D or values outside uint32 are refused (text gave int()'s bare ValueError; float64 or a square
    of the right count passed)."""
    bits = np.asarray(start)
    if bits.dtype.kind not in "iu" or bits.ndim != 2:
        raise InvalidArgumentError(f"start must be an earlier run's bits (Pvs.bits: a 2-D uint32 array, view cells x "
                                   f"words), got {bits.ndim}-D {bits.dtype}")
    if bits.size and (int(bits.min()) < 0 or int(bits.max()) > 0xFFFFFFFF):
        raise InvalidArgumentError("start must be an earlier run's bits (Pvs.bits): values outside uint32")
    return np.ascontiguousarray(bits, dtype=np.uint32)


def pvs(heights, *, samples=0, pixel_error=0.0, seconds=0.0, view_cell=32, band_low=1.7, band_high=1.7, tile=16,
        mask=None, method="agvs", batch=1 << 16, seed=1, resolution=1e6, filter=0.0, view_filter=0, estimate_entries=20,
        witnesses=False, memory_budget_bytes=0, start=None, curvature=0.0, max_distance=0.0, cell_size=None,
        z_scale=1.0, nodata=None, device="", progress=None):
    """Potentially visible sets (Bittner, Mattausch, Wonka, Havran & Wimmer 2009): the tiles of tile
    x tile cells each view cell of view_cell x view_cell cells (its volume band_low .. band_high
    above the surface) sees, by sampling; stops at the first budget reached (samples, pixel_error,
    seconds; one at least), or once every view cell holds every tile (nodata aside). mask: the view cells to
    compute, per view cell or per pixel (as the CLI's --view-mask). method: "agvs", "sgvs",
    "per_cell". progress is called as progress(samples, pixel_error) after each batch. Returns Pvs:
    sets (per view cell, row-major: the visible tiles' row-major indices, None where not computed),
    bits (view cells x words uint32), computed, layout (a dict of the grid's sizes), the run's
    counts, history (per batch) and witnesses (with witnesses=True). DataArrays: the same (the sets
    are not on the pixel grid); computed in one piece. start: an earlier run's bits (its Pvs.bits)
    on the same field and grid (and band, curvature, max_distance), to go on from; its entries
    stay (give another seed, or its samples repeat; no object-space filter, and not the bits of a
    filtered run). filter: its k;
    view_filter: the view-space filter's neighbours, 0 to 8 (both add entries without witness,
    counted in filtered). estimate_entries: when a budget leaves the estimate on fewer entries found
    once (one at least), uniform view rays go on until that many carry it, at most as many samples
    (and seconds) as the run took before them (estimate_samples counts them, history rows say
    "settling"; 0: off). curvature: the drop coefficient c (a drop c d^2), (1 - k) / (2 R) per ground unit
    (about 6.7e-8 per m for the Earth, as the CLI's --curvature; 0: flat), every sight line the
    straight one over the curved surface. max_distance: the largest ground distance between an eye
    and what it sees (0: none)."""
    if not (isinstance(estimate_entries, (int, np.integer)) and 0 <= estimate_entries <= 1_000_000):
        raise InvalidArgumentError(f"estimate_entries must be a whole number in 0 .. 1e6, got {estimate_entries!r}")
    options = {"samples": _whole("samples", samples, 0, 2**31 - 1), "pixel_error": _real("pixel_error", pixel_error),
               "seconds": _real("seconds", seconds), "view_cell": _whole("view_cell", view_cell, None, 2**31 - 1),
               "band_low": _real("band_low", band_low), "band_high": _real("band_high", band_high),
               "tile": _whole("tile", tile, None, 2**31 - 1),
               "mask": None if mask is None else _arrays.as_array(mask, "mask"),
               "method": method, "batch": _whole("batch", batch, None, 2**31 - 1),
               "seed": _whole("seed", seed, 0, 2**32 - 1), "resolution": _real("resolution", resolution),
               "filter": _real("filter", filter), "view_filter": _whole("view_filter", view_filter, 0, 8),
               "estimate_entries": int(estimate_entries), "witnesses": _flag("witnesses", witnesses),
               "memory_budget_bytes": _budget(memory_budget_bytes), "curvature": _real("curvature", curvature),
               "max_distance": _max_distance(max_distance),
               "start": None if start is None else _pvs_start(start)}
    if _is_dataarray(heights) and _is_dask(heights.data):
        heights = _computed(heights)
    out, _ = _run("pvs", heights, options, _common(cell_size, z_scale, nodata, device, progress))
    bits, computed = out["bits"], out["computed"]
    tiles = out["layout"]["tiles_x"] * out["layout"]["tiles_y"]
    sets = []
    for v in range(len(computed)):
        if not computed[v]:
            sets.append(None)
            continue
        seen = np.unpackbits(bits[v].view(np.uint8), bitorder="little")[:tiles]
        sets.append(np.nonzero(seen)[0])
    return Pvs(sets, bits, computed.astype(bool), out["layout"], int(out["samples"]), int(out["rays"]),
               int(out["entries"]), int(out["rejected"]), int(out["filtered"]), float(out["pixel_error"]),
               float(out["seconds"]), list(out["history"]), out["witnesses"] if witnesses else None,
               int(out["estimate_samples"]), int(out["discontinuities"]))


def horizon_lists(heights, receivers, *, directions=64, azimuth_offset=0.0, samples_per_unit=1.0, curvature=0.0,
                  pixels=False, cell_size=None, z_scale=1.0, nodata=None):
    """The visibility horizons (Timonen 2013) of chosen receivers (an N x 2 array of pixels
    (column, row), or map coordinates (x, y) for a DataArray unless pixels=True), computed on the
    host: a list, per receiver, of dicts keyed as the CLI's JSON (`hfvis horizon-lists -o
    OUT.json`'s "receivers"): col, row, height, nodata, directions (per direction k: azimuth_rad,
    sample_spacing, ray_samples, visible_samples, horizons (nearest first: sample, distance,
    elevation_rad, segment_begin, segment_end, near_distance, visible_samples))). The library's
    lists take no maximum distance."""
    options = {"receivers": receivers, "directions": _whole("directions", directions, None, 2**31 - 1),
               "azimuth_offset": _real("azimuth_offset", azimuth_offset),
               "samples_per_unit": _real("samples_per_unit", samples_per_unit),
               "curvature": _real("curvature", curvature)}
    if _is_dataarray(heights) and _is_dask(heights.data):
        heights = _computed(heights)  # a few rays per receiver: the field in one piece
    out, _ = _run("horizon_lists", heights, options, _common(cell_size, z_scale, nodata, "", None, pixels))
    return list(out["lists"])


def bounce(heights, radiance, *, directions=64, azimuth_offset=0.0, samples_per_unit=1.0, curvature=0.0,
           memory_budget_bytes=0, cell_size=None, z_scale=1.0, nodata=None, device="", progress=None):
    """The incident irradiance of one diffuse bounce of the exit radiance `radiance` (H x W, or C x
    H x W for 1 to 4 channels; finite and >= 0 where the heights are valid) gathered over the
    visible segments of each sweep line (Timonen 2013, Sec. 10.1). Returns the radiance's shape;
    NaN at nodata. The library's bounce takes no maximum distance: a Dask array is computed in one
    piece."""
    options = {"directions": _whole("directions", directions, None, 2**31 - 1),
               "azimuth_offset": _real("azimuth_offset", azimuth_offset),
               "samples_per_unit": _real("samples_per_unit", samples_per_unit),
               "curvature": _real("curvature", curvature),
               "memory_budget_bytes": _budget(memory_budget_bytes)}
    if _is_dataarray(heights) and _is_dask(heights.data):
        heights = _computed(heights)
    radiance_values = _arrays.as_array(radiance.values if _is_dataarray(radiance) else radiance, "radiance")
    one_channel = radiance_values.ndim == 2
    if _is_dataarray(radiance) and _is_dataarray(heights):
        _require_grid_of(radiance, heights)
    options["radiance"] = radiance_values
    out, grid = _run("bounce", heights, options, _common(cell_size, z_scale, nodata, device, progress))
    irradiance = out["irradiance"]
    if grid is not None and grid.geographic and cell_size is None:  # (the CLI warns too; Python had not)
        warnings.warn("bounce takes the centre latitude's cell size for the whole latitude / longitude grid "
                      "(the other operations follow each row's spacing)", stacklevel=2)
    if grid is None:
        return irradiance[0] if one_channel else irradiance
    attrs = _attrs("bounce", "irradiance", options, grid)
    if one_channel:
        return grid.result(irradiance[0], "irradiance", attrs)
    channels = radiance[radiance.dims[0]].values if _is_dataarray(radiance) and radiance.dims[0] in radiance.coords \
        else np.arange(irradiance.shape[0])
    return grid.result(irradiance, "irradiance", attrs, leading=("channel", channels))


def _require_grid_of(radiance, heights):
    """A radiance DataArray lies on the heights' grid: its last two dims are theirs, with the same
    coordinates where both have them (it was taken by position: flipped or on another grid, it lit
    the wrong places)."""
    want = [d for d in heights.dims if not (d == "band" and heights.sizes[d] == 1)]
    got = list(radiance.dims[-2:])
    if got != want:
        raise InvalidArgumentError(f"the radiance's dims {tuple(radiance.dims)} must end with the heights' "
                                   f"{tuple(want)}")
    for dim in want:
        if dim in radiance.coords and dim in heights.coords and \
                not np.array_equal(radiance[dim].values, heights[dim].values):
            raise InvalidArgumentError(f"the radiance's {dim} coordinates are not the heights': put it on their grid "
                                       "(radiance.interp_like(heights), or reindex it)")


def sun_position(time, latitude_deg, longitude_deg, *, apparent=False):
    """Where the sun stands (Meeus 1998, ch. 25): (compass azimuth, elevation) in degrees, at a
    time (ISO 8601 text with a zone, aware datetime, or seconds since 1970) and place."""
    return _core.sun_position(_arrays.utc_seconds(time), float(latitude_deg), float(longitude_deg),
                              _flag("apparent", apparent))


def devices():
    """The OpenCL devices: a list of dicts (index, platform, name, type, memory, ...)."""
    return _core.devices()


HeightFieldFile = collections.namedtuple("HeightFieldFile", "heights cell_size row_cell_sizes geotransform crs_wkt")


def read_height_field(path, *, channel=""):
    """Reads a height field as the CLI does (GeoTIFF and the rasters GDAL reads, EXR, PNG, ...),
    through the library (no Python GDAL): HeightFieldFile(heights (H x W float32, nodata NaN),
    cell_size (x, y) in ground units, row_cell_sizes ((x, y) per row on latitude / longitude
    grids, else None), geotransform (GDAL's 6 numbers or None), crs_wkt ("" when none)).
    `channel`: a channel's (band's) name or zero-based index, as the CLI's --channel."""
    if isinstance(channel, (int, np.integer)) and not isinstance(channel, bool):
        channel = str(int(channel))
    elif not isinstance(channel, str):
        raise InvalidArgumentError(f"channel is a name or a zero-based index, got {channel!r}")
    # (a pathlib.Path or bytes path as the text it names: str() had written "b'dem.tif'")
    path = _arrays.file_path(path, "the file")
    heights, cx, cy, rows_x, rows_y, transform, wkt = _core.read_height_field(path, channel)
    rows = (np.asarray(rows_x), np.asarray(rows_y)) if rows_x else None
    return HeightFieldFile(heights, (cx, cy), rows, None if transform is None else tuple(transform), wkt)
