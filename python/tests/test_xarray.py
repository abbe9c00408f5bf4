"""DataArrays: georeferencing in (rioxarray's transform and CRS, bare coordinates, latitude /
longitude grids, nodata), results on the input's grid with its coordinates, spatial_ref and CRS,
and units and method in their attributes; equal to the CLI's on the same GeoTIFF."""

import numpy as np
import pytest
import rioxarray
import xarray as xr

import hfvis

from conftest import read_bands, run_cli


def equal(a, b):
    np.testing.assert_array_equal(np.asarray(a, np.float32), np.asarray(b, np.float32))


def test_projected_geotiff_round_trip(tmp_path, projected_tif):
    dem = rioxarray.open_rasterio(projected_tif)  # (band, y, x), nodata -9999 kept as values
    svf = hfvis.sky_view_factor(dem, directions=16, max_distance=1200)
    run_cli("sky-view-factor", projected_tif, "-o", tmp_path / "svf.tif", "-k", "16", "--max-distance", "1200")
    (cli,), _ = read_bands(tmp_path / "svf.tif")
    equal(svf, cli)
    assert svf.dims == ("y", "x") and svf.name == "sky_view_factor"
    np.testing.assert_array_equal(svf.x, dem.x)
    np.testing.assert_array_equal(svf.y, dem.y)
    assert svf.rio.crs == dem.rio.crs and "spatial_ref" in svf.coords
    assert svf.rio.transform() == dem.rio.transform()
    assert svf.attrs["hfvis_method"] == "sweep" and svf.attrs["hfvis_directions"] == 16
    assert svf.attrs["units"].startswith("1")
    # Written and read back, it overlays the input.
    svf.rio.to_raster(tmp_path / "again.tif")
    again = rioxarray.open_rasterio(tmp_path / "again.tif").squeeze("band", drop=True)
    assert again.rio.crs == dem.rio.crs and again.rio.transform() == dem.rio.transform()
    equal(again, cli)
    # NaN declared as the nodata (as the command line's bands): the GeoTIFF tags it (it had none)
    assert np.isnan(svf.rio.nodata) and np.isnan(again.rio.nodata)


def test_masked_read_and_fill_value(projected_tif):
    masked = rioxarray.open_rasterio(projected_tif, masked=True).squeeze("band", drop=True)
    plain = rioxarray.open_rasterio(projected_tif).squeeze("band", drop=True)
    a = hfvis.ambient_occlusion(masked, directions=8, max_distance=600)
    b = hfvis.ambient_occlusion(plain, directions=8, max_distance=600)
    equal(a, b)
    assert np.isnan(a[100, 150])
    # Without rioxarray's accessor: the _FillValue attribute and bare coordinates.
    bare = xr.DataArray(plain.values, dims=("y", "x"), coords={"y": plain.y.values, "x": plain.x.values},
                        attrs={"_FillValue": -9999.0})
    equal(hfvis.ambient_occlusion(bare, directions=8, max_distance=600), a)


def test_latitude_longitude_grid_as_the_cli(tmp_path, geographic_tif):
    dem = rioxarray.open_rasterio(geographic_tif)
    run_cli("sky-view-factor", geographic_tif, "-o", tmp_path / "svf.tif", "-k", "8")
    (cli,), _ = read_bands(tmp_path / "svf.tif")
    equal(hfvis.sky_view_factor(dem, directions=8), cli)
    run_cli("intervisibility", geographic_tif, "-o", tmp_path / "iv.tif", "-k", "4", "--max-distance", "2000")
    (count, area), _ = read_bands(tmp_path / "iv.tif")
    result = hfvis.intervisibility(dem, directions=4, max_distance=2000)
    assert isinstance(result, xr.Dataset) and set(result) == {"visible_count", "visible_area"}
    equal(result.visible_count, count)
    equal(result.visible_area, area)
    assert "metres" in result.visible_area.attrs["units"]


def test_horizon_angles_have_an_azimuth_coordinate(projected_tif):
    dem = rioxarray.open_rasterio(projected_tif)
    h = hfvis.horizon_angles(dem, directions=8, max_distance=600)
    assert h.dims == ("azimuth", "y", "x") and h.name == "horizon_angles"
    np.testing.assert_allclose(h.azimuth, np.arange(8) * 45.0, atol=0.5)
    assert h.azimuth.attrs["units"] == "degrees" and "compass azimuth = 90 + phi_k" in h.attrs["azimuth_convention"]
    assert h.rio.crs == dem.rio.crs


def test_south_up_grid_is_lit_as_the_cli(tmp_path, jacksboro):
    """A south-up GeoTIFF (rows running north): the sun and the viewshed's field of view take
    row 0 as north, so both flip it; the observer is a map coordinate."""
    from affine import Affine
    from conftest import write_geotiff

    tif = write_geotiff(tmp_path / "south_up.tif", jacksboro[::-1].copy(), "EPSG:32616",
                        Affine(30.0, 0.0, 700000.0, 0.0, 30.0, 4060000.0))
    dem = rioxarray.open_rasterio(tif)
    run_cli("shade", tif, "-o", tmp_path / "sun.tif", "--sun", "135,20")
    (direct, sun), _ = read_bands(tmp_path / "sun.tif")
    lit = hfvis.sun_shading(dem, 135, 20)
    equal(lit.sun, sun)
    equal(lit.direct, direct)
    run_cli("viewshed", tif, "-o", tmp_path / "seen.tif", "--observer", "200,170", "--fov", "90,200")
    (seen,), _ = read_bands(tmp_path / "seen.tif")
    x, y = float(dem.x[200]), float(dem.y[170])
    equal(hfvis.viewshed(dem, (x, y), azimuth_from_deg=90, azimuth_to_deg=200), seen)
    equal(hfvis.viewshed(dem, (200, 170), pixels=True, azimuth_from_deg=90, azimuth_to_deg=200), seen)
    assert hfvis.cumulative_viewshed(dem, [(x, y)], azimuth_from_deg=90, azimuth_to_deg=200).dims == ("y", "x")


def test_region_visibility_and_pairs_take_map_coordinates(projected_tif):
    dem = rioxarray.open_rasterio(projected_tif)
    plain = dem.squeeze("band", drop=True).values
    x0, y0, x1, y1 = float(dem.x[200]), float(dem.y[170]), float(dem.x[206]), float(dem.y[175])
    lit = hfvis.region_visibility(dem, (x0, y0, x1, y1), samples=40, height=10, max_distance=3000)
    ours = hfvis.region_visibility(plain, (200, 170, 206, 175), samples=40, height=10, max_distance=3000,
                                   cell_size=30, nodata=-9999.0)
    assert isinstance(lit, xr.Dataset) and set(lit) == {"fraction", "bits"} and lit.attrs["hfvis_samples"] == 40
    assert lit.fraction.dims == ("y", "x") and lit.bits.dims == ("word", "y", "x")
    assert lit.fraction.rio.crs == dem.rio.crs and lit.bits.rio.crs == dem.rio.crs
    assert lit.fraction.attrs["hfvis_method"] == "culled" and lit.fraction.attrs["hfvis_height"] == 10.0
    # The default ("auto") takes the bitmask scatter for a planar light of 64 or more samples, and
    # names it; the bits are the culled march's.
    top = float(np.nanmax(np.where(plain == -9999.0, np.nan, plain)))
    planar = dict(samples=64, height=top + 100, absolute=True, max_distance=3000)
    auto = hfvis.region_visibility(dem, (x0, y0, x1, y1), **planar)
    culled = hfvis.region_visibility(dem, (x0, y0, x1, y1), method="culled", **planar)
    assert auto.fraction.attrs["hfvis_method"] == "bitmask" and culled.fraction.attrs["hfvis_method"] == "culled"
    np.testing.assert_array_equal(auto.bits.values, culled.bits.values)
    np.testing.assert_array_equal(lit.x, dem.x)
    equal(lit.fraction, ours.fraction)
    np.testing.assert_array_equal(lit.bits.values, ours.bits)
    # A point between pixel centres, as map coordinates, and pixels=True.
    x, y = float(dem.x[100]) + 7.5, float(dem.y[50]) - 15.0
    a = hfvis.region_visibility(dem, [(x, y, 5.0)], max_distance=2000)
    b = hfvis.region_visibility(plain, [(100.25, 50.5, 5.0)], max_distance=2000, cell_size=30, nodata=-9999.0)
    equal(a.fraction, b.fraction)
    c = hfvis.region_visibility(dem.chunk(100), (200, 170, 206, 175), pixels=True, samples=40, height=10,
                                max_distance=3000)  # Dask: computed in one piece
    equal(c.fraction, ours.fraction)
    colours = np.arange(12, dtype=np.float32).reshape(3, 2, 2)
    lit = hfvis.region_visibility(dem, (x0, y0, x1, y1), samples=40, height=10, max_distance=3000, light_image=colours)
    ours = hfvis.region_visibility(plain, (200, 170, 206, 175), samples=40, height=10, max_distance=3000,
                                   cell_size=30, nodata=-9999.0, light_image=colours)
    assert lit.rgb.dims == ("channel", "y", "x") and lit.rgb.channel.values.tolist() == ["R", "G", "B"]
    equal(lit.rgb, ours.rgb)
    pair = hfvis.region_pair_visibility(dem, (x0, y0, x1, y1), [(x, y)], samples=8)
    assert pair.receivers_xy.tolist() == [[x, y]] and pair.sources_xy.shape == (8, 2)
    np.testing.assert_allclose(pair.receivers[0, :2], (100.25, 50.5))


def test_max_error_on_dataarrays(projected_tif):
    dem = rioxarray.open_rasterio(projected_tif)
    svf = hfvis.sky_view_factor(dem, max_error=0.01, max_distance=900)
    numpy_run = hfvis.sky_view_factor(dem.squeeze("band", drop=True).values, max_error=0.01, max_distance=900,
                                      cell_size=30, nodata=-9999.0)
    equal(svf, numpy_run.values)
    assert svf.attrs["hfvis_directions"] == numpy_run.directions and svf.attrs["hfvis_max_error"] == 0.01
    assert svf.attrs["hfvis_estimated_error"] == numpy_run.estimated_error <= 0.01
    # The Richardson divisor (1 .. 2^1.1 - 1) and each run's K, the first 16, the last the K chosen.
    assert 1.0 <= svf.attrs["hfvis_richardson_divisor"] <= 2.0 ** 1.1 - 1.0 + 1e-12
    assert svf.attrs["hfvis_runs"][0] == 16 and svf.attrs["hfvis_runs"][-1] == svf.attrs["hfvis_directions"]
    both = hfvis.ambient_occlusion(dem.chunk(100), max_error=0.02, error_estimate=True, max_distance=900)
    assert isinstance(both, xr.Dataset) and set(both) == {"ambient_occlusion", "error"}
    assert both.error.rio.crs == dem.rio.crs and both.error.attrs["hfvis_directions"] > 16
    equal(both.ambient_occlusion, hfvis.ambient_occlusion(dem, max_error=0.02, max_distance=900))


def test_intervisibility_max_error_on_dataarrays(projected_tif):
    dem = rioxarray.open_rasterio(projected_tif)
    both = hfvis.intervisibility(dem.chunk(100), max_error=0.3, error_estimate=True, max_distance=1500)
    numpy_run = hfvis.intervisibility(dem.squeeze("band", drop=True).values, max_error=0.3, max_distance=1500,
                                      cell_size=30, nodata=-9999.0)
    assert isinstance(both, xr.Dataset) and set(both) == {"visible_count", "visible_area", "error"}
    equal(both.visible_count, numpy_run.visible_count)
    equal(both.error, numpy_run.error)
    assert both.error.rio.crs == dem.rio.crs
    for name in both:
        assert both[name].attrs["hfvis_directions"] == numpy_run.directions
        assert both[name].attrs["hfvis_estimated_error"] == numpy_run.estimated_error <= 0.3
    assert both.visible_count.attrs["hfvis_max_error"] == 0.3


def test_pvs_horizon_lists_and_bounce_on_dataarrays(projected_tif):
    dem = rioxarray.open_rasterio(projected_tif)
    plain = dem.squeeze("band", drop=True).values
    a = hfvis.pvs(dem.chunk(128), samples=5000, view_cell=64, tile=64)
    b = hfvis.pvs(plain, samples=5000, view_cell=64, tile=64, cell_size=30, nodata=-9999.0)
    assert [s.tolist() for s in a.sets] == [s.tolist() for s in b.sets] and a.entries == b.entries > 0
    x, y = float(dem.x[200]), float(dem.y[170])
    assert hfvis.horizon_lists(dem, [(x, y)], directions=4) == \
        hfvis.horizon_lists(plain, [(200, 170)], directions=4, cell_size=30, nodata=-9999.0)
    radiance = xr.full_like(dem.squeeze("band", drop=True), 1.0, dtype=np.float32)
    lit = hfvis.bounce(dem.chunk(100), radiance, directions=4)  # Dask: computed in one piece
    assert lit.dims == ("y", "x") and lit.rio.crs == dem.rio.crs and lit.attrs["hfvis_method"] == "tree"
    assert "re-emits" in lit.attrs["units"]
    equal(lit, hfvis.bounce(plain, np.ones(plain.shape, np.float32), directions=4, cell_size=30, nodata=-9999.0))


def test_geographic_crs_not_in_degrees_on_the_earth_is_refused():
    """Degrees become metres on the Earth, as the file reader converts them: a CRS in radians, or
    on Mars, got cells of the wrong size without a word; cell_size still runs them."""
    heights = xr.DataArray(np.random.default_rng(3).random((8, 8), dtype=np.float32), dims=("y", "x"))
    radians = ('GEOGCS["radians",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],'
               'PRIMEM["Greenwich",0],UNIT["radian",1]]')
    mars = ('GEOGCS["Mars 2000",DATUM["D_Mars_2000",SPHEROID["Mars_2000_IAU_IAG",3396190,169.894447223612]],'
            'PRIMEM["Reference_Meridian",0],UNIT["degree",0.0174532925199433]]')
    from affine import Affine
    for crs, words in ((radians, "not degrees"), (mars, "not the Earth")):
        da = heights.rio.write_crs(crs).rio.write_transform(Affine(1e-5, 0, 0, 0, -1e-5, 0.5))
        with pytest.raises(hfvis.Error, match=words):
            hfvis.sky_view_factor(da, directions=8)
        assert np.isfinite(hfvis.sky_view_factor(da, directions=8, cell_size=2.0)).all()


def _grid(values, **attrs):
    rows, cols = values.shape
    return xr.DataArray(values, dims=("y", "x"), attrs=attrs,
                        coords={"y": 1200.0 - 30.0 * (np.arange(rows) + 0.5), "x": 30.0 * (np.arange(cols) + 0.5)})


def _relief(rows=30, cols=40):
    return np.random.default_rng(4).normal(size=(rows, cols)).cumsum(0).cumsum(1) * 3


def test_a_rasters_scale_and_offset_are_applied(tmp_path):
    """rioxarray's open_rasterio keeps a band's scale_factor and add_offset in the attributes
    (mask_and_scale=False, its default): they were ignored (decimetres taken as metres); the CLI
    applies them. Nodata is compared before scaling, in the raw dtype."""
    raw = np.round(_relief() * 10).astype(np.int16)
    raw[3, 4] = -32768
    scaled = hfvis.sky_view_factor(_grid(raw, scale_factor=0.1, add_offset=5.0, _FillValue=-32768), directions=8,
                                   cell_size=30)
    metres = (raw * 0.1 + 5.0).astype(np.float32)
    metres[3, 4] = np.nan
    equal(scaled, hfvis.sky_view_factor(metres, directions=8, cell_size=30))
    with pytest.raises(hfvis.InvalidArgumentError, match="scale_factor"):
        hfvis.sky_view_factor(_grid(raw, scale_factor=0.0), directions=8)
    # chunk by chunk, the same bits
    chunked = hfvis.sky_view_factor(_grid(raw, scale_factor=0.1, add_offset=5.0, _FillValue=-32768).chunk(7),
                                    directions=8, cell_size=30, max_distance=1e6)
    equal(chunked, hfvis.sky_view_factor(metres, directions=8, cell_size=30, max_distance=1e6))
    # over floats the scale may be applied already (dem * dem.scale_factor keeps the attributes:
    # it was applied again), and per-band scales name no band: refused
    with pytest.raises(hfvis.InvalidArgumentError, match="may be applied already"):
        hfvis.sky_view_factor(_grid(raw * 0.1, scale_factor=0.1), directions=8)
    with pytest.raises(hfvis.InvalidArgumentError, match="per-band scales"):
        hfvis.sky_view_factor(_grid(raw, scales=(0.1, 0.2), offsets=(0.0, 0.0)), directions=8)
    assert np.isfinite(hfvis.sky_view_factor(_grid(raw, scales=(1.0,), offsets=(0.0,)), directions=8).values).any()


def test_nodata_is_marked_besides_the_arrays_own():
    """`nodata=` marks its value besides the DataArray's own _FillValue (it replaced it: the
    -9999 cell was computed as a pit)."""
    z = _relief().astype(np.float32)
    z[5, 5], z[10, 10] = -9999, -32768
    out = hfvis.sky_view_factor(_grid(z, _FillValue=-9999.0), directions=8, nodata=-32768)
    assert np.isnan(out.values[5, 5]) and np.isnan(out.values[10, 10])
    # GDAL's and ArcGIS's float64 nodata, -1.797e308, is nodata, not a height beyond float32
    deep = _relief()
    deep[3:6, 3:6] = -np.finfo(np.float64).max
    out = hfvis.sky_view_factor(_grid(deep), directions=8, nodata=-np.finfo(np.float64).max)
    assert np.isnan(out.values[3:6, 3:6]).all() and np.isfinite(out.values[10:, 10:]).all()


def test_grids_hfvis_cannot_read_right_are_refused():
    """Each of these ran with exit 0 and a wrong answer: dims given as (x, y) (columns taken as
    rows), an axis of one coordinate or none beside another's (a cell size of 1), coordinates that
    are no map coordinates (datetimes as cells of 86400), a radiance on another grid."""
    z = _relief().astype(np.float32)
    a = _grid(z)
    with pytest.raises(hfvis.InvalidArgumentError, match=r"transpose it first"):
        hfvis.sky_view_factor(a.T, directions=8)
    with pytest.raises(hfvis.InvalidArgumentError, match="transpose"):
        hfvis.sky_view_factor(xr.DataArray(z.T, dims=("lon", "lat")), directions=8)
    with pytest.raises(hfvis.InvalidArgumentError, match="one value"):
        hfvis.horizon_distances(a[:1], directions=4)
    with pytest.raises(hfvis.InvalidArgumentError, match="none along y"):
        hfvis.sky_view_factor(xr.DataArray(z, dims=("y", "x"), coords={"x": 30.0 * np.arange(40)}), directions=8)
    days = a.assign_coords(x=np.datetime64("2020-01-01") + np.arange(40).astype("timedelta64[D]"))
    with pytest.raises(hfvis.InvalidArgumentError, match="not map coordinates"):
        hfvis.sky_view_factor(days, directions=8)
    # (a 1 x N field with its cell size given runs; one with no coordinates at all takes 1)
    assert hfvis.horizon_distances(a[:1], directions=4, cell_size=30).shape[1:] == (1, 40)
    # Map coordinates or a CRS that are not the dimensions' coordinates: each ran with cells of 1.
    rows, cols = z.shape
    for array, words in (
            (xr.DataArray(z, dims=("y", "x")).rio.write_crs("EPSG:32633"), "has a CRS but no x / y coordinates"),
            (xr.DataArray(z, dims=("y", "x"), coords={"lat": (("y", "x"), np.zeros(z.shape)),
                                                      "lon": (("y", "x"), np.zeros(z.shape))}), r"\['lat', 'lon'\]"),
            (xr.DataArray(z, dims=("row", "col"), coords={"y": ("row", 30.0 * np.arange(rows)),
                                                          "x": ("col", 30.0 * np.arange(cols))}), "swap_dims"),
            (xr.DataArray(z, dims=("r", "c"), coords={"northing": ("r", 30.0 * np.arange(rows)),
                                                      "easting": ("c", 30.0 * np.arange(cols))}), "swap_dims")):
        with pytest.raises(hfvis.InvalidArgumentError, match=words):
            hfvis.sky_view_factor(array, directions=4)
        assert hfvis.sky_view_factor(array, directions=4, cell_size=30.0).shape == z.shape
    with pytest.raises(hfvis.InvalidArgumentError, match="transpose"):
        hfvis.sky_view_factor(xr.DataArray(z.T, dims=("col", "row")), directions=8)
    radiance = _grid(np.ones_like(z))
    hfvis.bounce(a, radiance, directions=8)
    with pytest.raises(hfvis.InvalidArgumentError, match="coordinates are not the heights'"):
        hfvis.bounce(a, radiance.isel(y=slice(None, None, -1)), directions=8)


def test_an_encoded_fill_value_counts_with_rioxarray_imported_too():
    """rioxarray (imported here) gives nodata NaN where the encoding holds a fill value; the value
    itself still marks nodata, as it does without rioxarray's accessor. So does a fill value given
    as a one-element array, as netCDF backends give attributes."""
    heights = _relief(20, 20)
    heights[5, 5] = -9999.0
    encoded = xr.DataArray(heights, dims=("y", "x"))
    encoded.encoding["_FillValue"] = -9999.0
    assert np.isnan(encoded.rio.nodata)
    assert np.isnan(hfvis.sky_view_factor(encoded, directions=8).values[5, 5])
    listed = xr.DataArray(heights, dims=("y", "x"), attrs={"_FillValue": np.array([-9999.0])})
    assert np.isnan(hfvis.sky_view_factor(listed, directions=8).values[5, 5])


def test_an_observers_pixel_is_named_as_the_caller_gave_it():
    """A south-up or west-up grid is computed flipped; errors name the caller's pixel, not the
    flipped field's."""
    heights = np.ones((20, 24), np.float32)
    heights[5, 3] = np.nan
    south_up = xr.DataArray(heights, dims=("y", "x"),
                            coords={"y": 10.0 * np.arange(20) + 5.0, "x": 10.0 * np.arange(24) + 5.0})
    with pytest.raises(hfvis.InvalidArgumentError, match="observer 3,5 stands on nodata"):
        hfvis.viewshed(south_up, (3, 5), pixels=True)
    with pytest.raises(hfvis.InvalidArgumentError, match="observer 3,25 is outside the 24 x 20 field"):
        hfvis.viewshed(south_up, (3, 25), pixels=True)
    west_up = south_up.isel(x=slice(None, None, -1))
    with pytest.raises(hfvis.InvalidArgumentError, match="observer 20,5 stands on nodata"):
        hfvis.viewshed(west_up, (20, 5), pixels=True)
    with pytest.raises(hfvis.InvalidArgumentError, match="observer 3,5 stands on nodata"):
        hfvis.cumulative_viewshed(south_up, [(1, 1), (3, 5)], pixels=True)
    # A Dask array's (when computed: the heights are read then).
    lazy = south_up.chunk(10)
    with pytest.raises(hfvis.InvalidArgumentError, match="observer 3,5 stands on nodata"):
        hfvis.viewshed(lazy, (3, 5), pixels=True, max_distance=50.0).values
    with pytest.raises(hfvis.InvalidArgumentError, match="observer 3,5 stands on nodata"):
        hfvis.cumulative_viewshed(lazy, [(1, 1), (3, 5)], pixels=True).values


def test_a_decoded_rasters_raw_fill_value_is_no_height(tmp_path):
    """Opened decoded (mask_and_scale=True), a scaled raster's encoding keeps its raw fill value
    (0 here, over heights 0.5 raw - 10): the decoded heights of 0.0 m (raw 20) had become nodata.
    The decoded data hold NaN where the raw value was the fill value; that pixel alone is nodata,
    in memory and chunk by chunk, as the file reader has it."""
    raw = np.full((16, 16), 60, np.uint16)
    raw[4:8, 4:8] = 20  # 0.0 m: valid ground at sea level
    raw[12, 12] = 0
    written = _grid(raw).rio.write_crs("EPSG:32633").rio.write_nodata(0, encoded=False)
    written.attrs.update(scale_factor=0.5, add_offset=-10.0)
    written.rio.to_raster(tmp_path / "scaled.tif")
    dem = rioxarray.open_rasterio(tmp_path / "scaled.tif", mask_and_scale=True).squeeze("band", drop=True)
    assert dem.encoding["_FillValue"] == 0 and float(dem[5, 5]) == 0.0
    svf = hfvis.sky_view_factor(dem, directions=8)
    assert int(svf.isnull().sum()) == 1 and np.isnan(svf[12, 12])
    chunked = hfvis.sky_view_factor(dem.chunk(8), directions=8, max_distance=100.0)
    assert int(chunked.isnull().sum()) == 1
    assert int(np.isnan(hfvis.read_height_field(tmp_path / "scaled.tif").heights).sum()) == 1


def test_every_nodata_marker_counts():
    """CF lets _FillValue and missing_value stand side by side (undecoded netCDF): only the first
    key found had counted, the other's cells taken as heights (a pit of 10 km beside the field)."""
    heights = (100 + 20 * np.random.default_rng(0).random((16, 16))).astype(np.float32)
    heights[8, 8] = -9999.0
    for attrs in ({"missing_value": -9999.0}, {"_FillValue": np.float32(np.nan), "missing_value": -9999.0},
                  {"_FillValue": -32768.0, "missing_value": -9999.0}, {"nodata": -32768.0, "_FillValue": -9999.0}):
        ao = hfvis.ambient_occlusion(_grid(heights, **attrs), directions=8)
        assert np.isnan(ao[8, 8]) and int(ao.isnull().sum()) == 1, attrs


def test_a_geographic_grid_is_seen_without_rioxarray():
    """Without rioxarray's accessor (xarray alone, a CF spatial_ref as xr.open_dataset gives it), a
    latitude / longitude grid declared by a compound CRS (WGS 84 with EGM96 heights, as SRTM and
    Copernicus DEMs are) or a bound one (+towgs84), or without a CRS by dims named in any case or
    by CF's units, had its degrees taken as ground units (cells of 0.00083 against heights in
    metres). Each now gives EPSG:4326's result; a projected CRS stays projected."""
    script = r'''
import sys
import numpy as np, pyproj, xarray as xr
import hfvis
assert "rioxarray" not in sys.modules
z = (100 + 50 * np.random.default_rng(0).random((24, 28))).astype(np.float32)
lon, lat = 7 + (np.arange(28) + 0.5) / 1200, 46.1 - (np.arange(24) + 0.5) / 1200
def with_crs(crs):
    ref = xr.Variable((), 0, {"crs_wkt": pyproj.CRS(crs).to_wkt()})
    return xr.DataArray(z, dims=("y", "x"), coords={"y": lat, "x": lon, "spatial_ref": ref})
want = hfvis.sky_view_factor(with_crs("EPSG:4326"), directions=8).values
assert 0.8 < np.nanmean(want) < 0.9, np.nanmean(want)
arrays = [with_crs("EPSG:4326+5773"), with_crs("+proj=longlat +ellps=WGS84 +towgs84=0,0,0 +no_defs")]
for dims in (("Lat", "Lon"), ("LATITUDE", "LONGITUDE"), ("latitude", "long")):
    arrays.append(xr.DataArray(z, dims=dims, coords={dims[0]: lat, dims[1]: lon}))
arrays.append(xr.DataArray(z, dims=("j", "i"), coords={"j": ("j", lat, {"units": "degrees_north"}),
                                                       "i": ("i", lon, {"units": "degrees_east"})}))
for array in arrays:
    np.testing.assert_array_equal(hfvis.sky_view_factor(array, directions=8).values, want)
metres = dict(y=4600000 - 30.0 * np.arange(24), x=30.0 * np.arange(28))
compound, plain = (with_crs(c).assign_coords(**metres) for c in ("EPSG:32633+5773", "EPSG:32633"))
np.testing.assert_array_equal(hfvis.sky_view_factor(compound, directions=8).values,
                              hfvis.sky_view_factor(plain, directions=8).values)
assert not np.array_equal(hfvis.sky_view_factor(plain, directions=8).values, want)
print("ok")
'''
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-2000:]


def test_map_coordinates_not_finite_or_far_off_are_named():
    """A region's rectangle and points and horizon_lists' receivers in map coordinates that are not
    finite or lie far off raised Python's own ValueError or OverflowError (or a message about an
    array of 300 digits): each is an hfvis error naming what was given."""
    heights = _relief(12, 14).astype(np.float32)
    dem = _grid(heights)
    x, y = float(dem.x[5]), float(dem.y[3])
    for call, words in ((lambda: hfvis.horizon_lists(dem, [[np.nan, y]], directions=4), "must be finite"),
                        (lambda: hfvis.horizon_lists(dem, [[np.inf, y]], directions=4), "must be finite"),
                        (lambda: hfvis.horizon_lists(dem, [[1e300, y]], directions=4), "outside the field's extent"),
                        (lambda: hfvis.region_visibility(dem, (np.nan, y, x, y)), "must be finite"),
                        (lambda: hfvis.region_visibility(dem, (1e300, y, x, y)), "lies outside the field's extent"),
                        (lambda: hfvis.region_pair_visibility(dem, (x, y, x, y), [[np.inf, y]]), "must be finite")):
        with pytest.raises(hfvis.InvalidArgumentError, match=words):
            call()


def test_a_path_may_be_bytes(tmp_path, projected_tif):
    """read_height_field took str() of a bytes path ("b'dem.tif'": no such file)."""
    assert hfvis.read_height_field(str(projected_tif).encode()).heights.shape == \
        hfvis.read_height_field(projected_tif).heights.shape


def test_bounce_on_a_latitude_longitude_grid_warns(geographic_tif):
    """bounce takes the centre latitude's cell size for a whole latitude / longitude grid, as the
    CLI does; the CLI says so, and now Python too (it was silent)."""
    dem = rioxarray.open_rasterio(geographic_tif).squeeze("band", drop=True)
    radiance = xr.ones_like(dem, dtype=np.float32)
    with pytest.warns(UserWarning, match="centre latitude"):
        hfvis.bounce(dem, radiance, directions=4)
