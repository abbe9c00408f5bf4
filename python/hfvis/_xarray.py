"""DataArrays in and out: a DataArray's georeferencing as the library's field (cell sizes from its
coordinates or rioxarray's transform, latitude / longitude grids converted row by row as the
CLI's GeoTIFF reader does, nodata as NaN), and results that carry the input's coordinates,
spatial_ref and CRS, with units and method in their attributes."""

import math
import re

import numpy as np
import xarray as xr

from . import _arrays, _core
from ._errors import InputTypeError, InvalidArgumentError

AZIMUTH_CONVENTION = ("phi_k = 360*k/K deg + azimuth_offset, on the ground from the +x (column) axis toward "
                      "+row; compass azimuth = 90 + phi_k deg when row 0 is north")


# Dim names that say which axis is which: a DataArray given as (x, y), as after .T, was read with
# its columns as rows (its sun and observers turned, a latitude / longitude grid not seen as one).
_X_NAMES = ("x", "lon", "long", "longitude", "easting")
_Y_NAMES = ("y", "lat", "latitude", "northing")
_COLUMN_NAMES, _ROW_NAMES = ("col", "cols", "column", "columns"), ("row", "rows")  # (pixel dims: no coordinates)


class Grid:
    """A DataArray's 2-D grid: its dims, geotransform (GDAL's order: x0, dx, 0, y0, 0, dy, of the
    pixel corners; None without coordinates or a transform), whether its CRS is geographic, and
    its nodata values."""

    def __init__(self, array):
        if "band" in array.dims and array.sizes["band"] == 1 and array.ndim == 3:
            array = array.squeeze("band", drop=True)  # rioxarray's open_rasterio: (band, y, x)
        if array.ndim != 2:
            raise InputTypeError(f"a DataArray of heights must be 2-D (y, x), got dims {array.dims}")
        first, second = (str(d).lower() for d in array.dims)
        if first in _X_NAMES + _COLUMN_NAMES or second in _Y_NAMES + _ROW_NAMES:
            raise InvalidArgumentError(f"the DataArray's dims are {array.dims}: hfvis takes rows then columns (y, x); "
                                       f"transpose it first (array.transpose({array.dims[1]!r}, {array.dims[0]!r}))")
        self.array = array
        self.y_dim, self.x_dim = array.dims
        self.transform = _geotransform(array)
        if self.transform is not None and (self.transform[2] != 0.0 or self.transform[4] != 0.0):
            raise InvalidArgumentError(f"rotated or sheared transforms are not supported (terms {self.transform[2]}, "
                                       f"{self.transform[4]}); warp the raster north-up first")
        self.geographic = _is_geographic(array)
        self.nodata = _nodata(array)

    def geometry(self, cell_size, z_scale):
        """The field's cell sizes: given, else from the transform (degrees to metres per row on a
        geographic CRS, by the library's own conversion), else (no coordinates at all) 1."""
        if cell_size is None and self.transform is None:
            for dim in (self.y_dim, self.x_dim):
                if dim in self.array.coords and self.array.sizes[dim] == 1:
                    # (a 1 x N field took a cell size of 1, whatever its x coordinates said)
                    raise InvalidArgumentError(f"the {dim} coordinates hold one value, which gives no spacing: give "
                                               "cell_size")
                if dim not in self.array.coords and any(d in self.array.coords for d in (self.y_dim, self.x_dim)):
                    raise InvalidArgumentError(f"the DataArray has coordinates along one axis but none along {dim}: "
                                               "give both, or cell_size")
        if cell_size is not None or self.transform is None:
            if cell_size is None and self.geographic:
                raise InvalidArgumentError("a geographic DataArray without coordinates or a transform has no cell "
                                           "size in metres; give cell_size")
            if cell_size is None:
                # (each ran with cells of 1, without a word: 30 m cells gave horizons 30 times too near)
                rio = _rio(self.array)
                if rio is not None and rio.crs is not None:
                    raise InvalidArgumentError("the DataArray has a CRS but no x / y coordinates or transform to take "
                                               "its cell size from: give cell_size, or its coordinates")
                spatial = [str(n) for n in self.array.coords if str(n).lower() in _X_NAMES + _Y_NAMES
                           and n not in (self.y_dim, self.x_dim) and self.array.coords[n].ndim > 0]
                if spatial:
                    raise InvalidArgumentError(f"the DataArray's map coordinates {spatial} are not its dimensions' "
                                               f"({self.y_dim}, {self.x_dim}), and hfvis takes the cell size from "
                                               "those: give cell_size, or make them the dimensions "
                                               "(DataArray.swap_dims)")
            return _arrays.geometry(cell_size, z_scale)
        t = self.transform
        if not self.geographic:
            return _arrays.geometry((abs(t[1]), abs(t[5])), z_scale)
        rio = _rio(self.array)
        wkt = rio.crs.to_wkt() if rio is not None and rio.crs is not None else _cf_wkt(self.array)
        if wkt:
            _require_earth_degrees(wkt)
        cx, cy, rows_x, rows_y = _core.geographic_cell_sizes(list(t), self.array.shape[0])
        return _arrays.geometry((cx, cy), z_scale, (rows_x, rows_y))

    def flips(self):
        """(rows, columns): lighting and fields of view take row 0 as north and column 0 as west;
        a south-up or west-up grid is computed flipped and flipped back, as the CLI does."""
        if self.transform is None:
            return False, False
        return self.transform[5] > 0.0, self.transform[1] < 0.0

    def pixel(self, x, y):
        """The pixel (column, row) whose centre is nearest the map coordinates (x, y)."""
        if self.transform is None:
            raise InvalidArgumentError("observers as map coordinates need a DataArray with x / y coordinates or a "
                                       "transform; give pixels (column, row) with pixels=True")
        t = self.transform
        return int(math.floor((x - t[0]) / t[1])), int(math.floor((y - t[3]) / t[5]))

    def position(self, x, y):
        """The pixel position (column, row; grid points at whole numbers, fractions between them)
        of the map coordinates (x, y)."""
        if self.transform is None:
            raise InvalidArgumentError("positions as map coordinates need a DataArray with x / y coordinates or a "
                                       "transform; give pixels (column, row) with pixels=True")
        t = self.transform
        return (x - t[0]) / t[1] - 0.5, (y - t[3]) / t[5] - 0.5

    def map_position(self, col, row):
        """The map coordinates (x, y) of a pixel position (column, row), None without a transform."""
        if self.transform is None:
            return None
        t = self.transform
        return t[0] + (col + 0.5) * t[1], t[3] + (row + 0.5) * t[5]

    def coords(self):
        """The input's coordinates along y and x (and scalar ones such as spatial_ref)."""
        keep = {self.y_dim, self.x_dim}
        return {name: c for name, c in self.array.coords.items() if set(c.dims) <= keep}

    def result(self, values, name, attrs, leading=None):
        """A DataArray of `values` on the input's grid: (y, x), or (leading[0], y, x) with
        leading = (dim, coordinate values)."""
        dims = (self.y_dim, self.x_dim)
        coords = self.coords()
        if leading is not None:
            dims = (leading[0],) + dims
            coords[leading[0]] = leading[1]
        out = xr.DataArray(values, dims=dims, coords=coords, name=name)
        if "grid_mapping" in self.array.attrs:
            out.attrs["grid_mapping"] = self.array.attrs["grid_mapping"]
        out.attrs.update(attrs)
        if "spatial_ref" in self.array.coords or _has_rio(self.array):
            _copy_crs(self.array, out)
            # NaN is a float result's nodata (the command line declares it on every band): declared,
            # so that rio.to_raster tags it (the GeoTIFF had no nodata, the input's -9999 gone); the
            # bitmask words (uint32) have none
            if np.issubdtype(out.dtype, np.floating):
                try:
                    out.rio.write_nodata(np.nan, encoded=False, inplace=True)
                except AttributeError:  # rioxarray absent
                    pass
        return out


def _has_rio(array):
    try:
        return array.rio.crs is not None
    except Exception:  # no rioxarray (no .rio), or no CRS it can read
        return False


def _copy_crs(source, out):
    try:
        crs = source.rio.crs
        if crs is not None and out.rio.crs is None:
            out.rio.write_crs(crs, inplace=True)
    except AttributeError:  # rioxarray absent: the spatial_ref coordinate came with the coords
        pass


def _rio(array):
    try:
        return array.rio
    except AttributeError:
        return None


def _geotransform(array):
    """GDAL's geotransform: rioxarray's (its stored GeoTransform, as GDAL read it) where the array
    has a spatial_ref, else from the 1-D coordinates (which must be evenly spaced), else None."""
    y_dim, x_dim = array.dims
    for dim in (y_dim, x_dim):
        if dim in array.coords and array[dim].dtype.kind not in "fiu":
            # (datetimes ran as cells of 86400, complex numbers without their imaginary part)
            raise InvalidArgumentError(f"the {dim} coordinates hold {array[dim].dtype}, not map coordinates: drop "
                                       f"them (array.drop_vars({dim!r})) and give cell_size")
    from_coords = None
    if x_dim in array.coords and y_dim in array.coords:
        xs, ys = np.asarray(array[x_dim].values, float), np.asarray(array[y_dim].values, float)
        if len(xs) >= 2 and len(ys) >= 2:
            dx, dy = _spacing(xs, x_dim, array[x_dim].dtype), _spacing(ys, y_dim, array[y_dim].dtype)
            from_coords = (xs[0] - dx / 2, dx, 0.0, ys[0] - dy / 2, 0.0, dy)
    rio = _rio(array)
    if rio is None or "spatial_ref" not in array.coords:
        return from_coords
    if from_coords is None and "GeoTransform" not in array.coords["spatial_ref"].attrs:
        return None  # (rioxarray's fallback for an axis it cannot measure is the identity)
    try:
        stored = tuple(float(v) for v in rio.transform(recalc=False).to_gdal())
    except Exception:  # rioxarray finds no spatial dims or transform: the coordinates'
        return from_coords
    # rioxarray's where it describes these coordinates (it falls back to the identity for dims it
    # does not know), with GDAL's exact numbers rather than ones recomputed from the coordinates.
    if from_coords is None or np.allclose(stored, from_coords, rtol=1e-6, atol=1e-9 * max(map(abs, from_coords))):
        return stored
    return from_coords


def _spacing(values, dim, dtype):
    if not np.all(np.isfinite(values)):  # (numpy's allclose warned of its tolerance first)
        raise InvalidArgumentError(f"the {dim} coordinates hold a NaN or an infinity: hfvis needs a regular grid")
    steps = np.diff(values)
    step = (values[-1] - values[0]) / (len(values) - 1)
    # (the coordinates' own rounding allowed for: float32 latitudes of a 3-arc-second grid step
    # unevenly by 3e-3 of a step, and were refused). Each coordinate rounds by half a unit in the
    # last place of the largest, or a unit where it was computed as start + i * step, so a step by
    # two; three allowed. (4 eps times the largest, 4 - 8 units, took float32 northings near 4e6
    # stepping 1 and 3 for a grid of 2.)
    rounding = 3 * float(np.spacing(np.max(np.abs(values)).astype(dtype))) if dtype.kind == "f" else 0.0
    if step == 0 or not np.allclose(steps, step, rtol=1e-6, atol=rounding):
        raise InvalidArgumentError(f"the {dim} coordinates are not evenly spaced: hfvis needs a regular grid")
    return step


def _is_geographic(array):
    rio = _rio(array)
    if rio is not None:
        try:
            crs = rio.crs
        except Exception:
            crs = None
        if crs is not None:
            return bool(crs.is_geographic)
    # Without rioxarray: CF's grid mapping, or the coordinates' names or units.
    wkt = _cf_wkt(array)
    if wkt:
        return _wkt_is_geographic(wkt)
    ref = array.coords.get("spatial_ref")
    if ref is not None and ref.attrs.get("grid_mapping_name") == "latitude_longitude":
        return True
    y_dim, x_dim = (str(d).lower() for d in array.dims[-2:])
    if x_dim in _LONGITUDE_NAMES and y_dim in _LATITUDE_NAMES:
        return True
    # (CF's units of latitude and longitude, whatever the dims are called)
    units = [str(array.coords[d].attrs.get("units", "")).lower() if d in array.coords else ""
             for d in array.dims[-2:]]
    return units[0] in _LATITUDE_UNITS and units[1] in _LONGITUDE_UNITS


_LONGITUDE_NAMES = ("lon", "long", "longitude")
_LATITUDE_NAMES = ("lat", "latitude")
_LATITUDE_UNITS = ("degrees_north", "degree_north", "degree_n", "degrees_n", "degreen", "degreesn")
_LONGITUDE_UNITS = ("degrees_east", "degree_east", "degree_e", "degrees_e", "degreee", "degreese")

# The CRS keywords of WKT 1 and 2 that name a horizontal (or other) CRS; wrappers (COMPOUNDCRS,
# COMPD_CS, BOUNDCRS and its SOURCECRS) are not among them, so that the first one found is the
# horizontal part of a compound CRS (EPSG:4326+5773, SRTM's and Copernicus' declaration) or the
# source of a bound one (a +towgs84 CRS): both had been taken as projected, degrees as ground units.
_WKT_CRS = re.compile(r"\b(PROJCS|PROJCRS|PROJECTEDCRS|GEOGCS|GEOGCRS|GEOGRAPHICCRS|GEODCRS|GEODETICCRS|GEOCCS|"
                      r"VERT_CS|VERTCRS|VERTICALCRS|ENGCRS|ENGINEERINGCRS|LOCAL_CS)\s*\[", re.IGNORECASE)


def _cf_wkt(array):
    """The WKT of CF's grid mapping (the spatial_ref coordinate's crs_wkt or spatial_ref), or ''."""
    ref = array.coords.get("spatial_ref")
    if ref is None:
        return ""
    return str(ref.attrs.get("crs_wkt") or ref.attrs.get("spatial_ref") or "")


def _wkt_is_geographic(wkt):
    first = _WKT_CRS.search(wkt)
    return first is not None and first.group(1).upper() in ("GEOGCS", "GEOGCRS", "GEOGRAPHICCRS", "GEODCRS",
                                                              "GEODETICCRS")


def _require_earth_degrees(wkt):
    """The degrees-to-metres conversion takes degrees on the Earth (as the file reader does): a
    geographic CRS (given as WKT) in radians or grads, or on another body, got cells of the wrong
    size. Checked with pyproj where it is installed (rioxarray brings it)."""
    try:
        import pyproj

        geodetic = pyproj.CRS.from_wkt(wkt)
        if geodetic.is_compound:
            geodetic = geodetic.sub_crs_list[0]
        if geodetic.is_bound:
            geodetic = geodetic.source_crs
        unit = geodetic.axis_info[0].unit_name if geodetic.axis_info else "degree"
        axis = geodetic.ellipsoid.semi_major_metre if geodetic.ellipsoid else 6378137.0
    except ImportError:
        return
    if "degree" not in unit.lower():
        raise InvalidArgumentError(f"the geographic CRS counts angles in {unit}, not degrees: reproject it "
                                   "(rio.reproject('EPSG:4326')), or give cell_size")
    if abs(axis - 6378137.0) > 6378.137:
        raise InvalidArgumentError(f"the geographic CRS lies on a body of semi-major axis {axis:g} m, not the Earth: "
                                   "give cell_size, or reproject it to a projected CRS")


def scale_offset(array):
    """A raster's scale and offset not yet applied: (1, 0) where there are none. rioxarray's
    open_rasterio (mask_and_scale=False, its default) keeps a band's scale_factor and add_offset in
    the attributes over its integers; the CLI applies them, as GDAL's band does. Over floats they
    may be applied already (dem * dem.scale_factor keeps the attributes), and per-band `scales` /
    `offsets` name no band once one is selected: refused, with the ways out. (Those in the
    encoding were applied when the data were decoded.)"""
    attrs = array.attrs
    scale, offset = attrs.get("scale_factor", 1.0), attrs.get("add_offset", 0.0)
    try:
        scale, offset = float(scale), float(offset)
        per_band = any(float(v) != 1.0 for v in np.ravel(attrs.get("scales", 1.0))) or \
            any(float(v) != 0.0 for v in np.ravel(attrs.get("offsets", 0.0)))
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"the DataArray's scale_factor {scale!r} and add_offset {offset!r} (or scales and "
                                   "offsets) must be numbers")
    if per_band:
        raise InvalidArgumentError("the DataArray's attributes hold per-band scales / offsets: open it with "
                                   "rioxarray.open_rasterio(..., mask_and_scale=True), or apply them and drop them")
    if (scale, offset) == (1.0, 0.0):
        return scale, offset
    if not (math.isfinite(scale) and math.isfinite(offset) and scale != 0.0):
        raise InvalidArgumentError(f"the DataArray's scale_factor {scale!r} and add_offset {offset!r} must be finite, "
                                   "the scale not 0")
    if array.dtype.kind != "i" and array.dtype.kind != "u":
        raise InvalidArgumentError(f"the DataArray holds {array.dtype} values and a scale_factor {scale!r} / "
                                   f"add_offset {offset!r} in its attributes, which may be applied already: open it "
                                   "with rioxarray.open_rasterio(..., mask_and_scale=True), or drop the attributes "
                                   "once they are applied")
    return scale, offset


def _nodata(array):
    """The values that mark nodata (a tuple, empty where there is none: NaN is nodata anyway):
    rioxarray's nodata, and every _FillValue, nodata and missing_value in the attributes or the
    encoding (CF allows _FillValue and missing_value side by side; only the first had counted, the
    other's cells taken as heights). rioxarray's nodata is NaN wherever the encoding holds a fill
    value (it takes the data for masked on reading): the encoding is read then too, so that a fill
    value counts whether rioxarray is imported or not. But not an encoding that also holds a
    scale_factor or add_offset: its fill values are raw, the data decoded (and masked) from them,
    and a decoded height equal to the raw fill value had become nodata."""
    found = []
    rio = _rio(array)
    if rio is not None:
        try:
            value = rio.nodata
        except Exception:
            value = None
        if value is not None and not _is_nan(value):
            found.append(_one_value(value))
    decoded = any(key in array.encoding for key in ("scale_factor", "add_offset"))
    for where in (array.attrs,) + (() if decoded else (array.encoding,)):
        for key in ("_FillValue", "nodata", "missing_value"):
            if key in where and where[key] is not None:
                found.append(_one_value(where[key]))
    return tuple(found)


def _one_value(value):
    """A fill value as one number where it comes as a one-element array (netCDF backends give
    attributes so)."""
    return np.asarray(value).item() if np.ndim(value) > 0 and np.size(value) == 1 else value


def _is_nan(value):
    try:
        return bool(np.isnan(value))
    except (TypeError, ValueError):
        return False
