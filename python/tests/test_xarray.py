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
