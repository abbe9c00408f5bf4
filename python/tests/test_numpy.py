"""numpy in, numpy out: each operation equals the CLI's output on the same GeoTIFF bit for bit
(nodata from the file's nodata value), and the inputs' dtype, byte order and strides change
nothing."""

import numpy as np
import pytest

import hfvis

from conftest import NODATA, read_bands, run_cli


@pytest.fixture(scope="module")
def dem(projected_tif):
    """The GeoTIFF's heights as a reader without hfvis gives them: nodata as its value."""
    import rasterio

    with rasterio.open(projected_tif) as f:
        return f.read(1)


def cli(tmp_path, tif, command, *options):
    out = tmp_path / "out.tif"
    run_cli(command, tif, "-o", out, *options)
    return read_bands(out)


def equal(a, b):
    np.testing.assert_array_equal(np.asarray(a, np.float32), np.asarray(b, np.float32))


def test_sky_view_factor_and_ambient_occlusion(tmp_path, projected_tif, dem):
    (svf,), _ = cli(tmp_path, projected_tif, "sky-view-factor", "-k", "16")
    ours = hfvis.sky_view_factor(dem, directions=16, cell_size=30.0, nodata=NODATA)
    assert ours.shape == dem.shape and ours.dtype == np.float32
    assert np.isnan(ours[100, 150]) and np.isfinite(ours[200, 200])
    equal(ours, svf)
    (ao,), _ = cli(tmp_path, projected_tif, "ambient-occlusion", "-k", "16", "--max-distance", "900")
    equal(hfvis.ambient_occlusion(dem, directions=16, max_distance=900, cell_size=30, nodata=NODATA), ao)


def test_horizon_angles_and_distances(tmp_path, projected_tif, dem):
    distances_tif = tmp_path / "d.tif"
    angles, names = cli(tmp_path, projected_tif, "horizon", "-k", "8", "--distance-out", distances_tif)
    assert names[:2] == ["h000", "h001"]
    result = hfvis.horizon_angles(dem, directions=8, cell_size=30.0, nodata=NODATA)
    assert result.values.shape == (8,) + dem.shape
    np.testing.assert_allclose(result.azimuths, 2 * np.pi * np.arange(8) / 8, atol=0.01)
    equal(result.values, angles)
    distances, _ = read_bands(distances_tif)
    equal(hfvis.horizon_distances(dem, directions=8, cell_size=30.0, nodata=NODATA).values, distances)


def test_intervisibility(tmp_path, projected_tif, dem):
    (count, area), names = cli(tmp_path, projected_tif, "intervisibility", "-k", "8", "--max-distance", "1500")
    assert names == ["count", "visible_area"]
    r = hfvis.intervisibility(dem, directions=8, max_distance=1500, cell_size=30.0, nodata=NODATA)
    equal(r.visible_count, count)
    equal(r.visible_area, area)


def test_viewsheds(tmp_path, projected_tif, dem):
    (visible,), _ = cli(tmp_path, projected_tif, "viewshed", "--observer", "200,170", "--observer-height", "10")
    equal(hfvis.viewshed(dem, (200, 170), observer_height=10, cell_size=30, nodata=NODATA), visible)
    observers = np.array([[200, 170], [50, 60], [390, 300]])
    (count,), _ = cli(tmp_path, projected_tif, "viewshed", "--observer", "200,170", "--observer", "50,60",
                      "--observer", "390,300", "--max-distance", "4000", "--target-height", "1.5")
    calls = []
    ours = hfvis.cumulative_viewshed(dem, observers, max_distance=4000, target_height=1.5, cell_size=30,
                                     nodata=NODATA, progress=lambda done, total: calls.append((done, total)))
    equal(ours, count)
    assert calls[-1] == (3, 3)


def test_sun_shading_and_insolation(tmp_path, projected_tif, dem):
    (direct, sun), names = cli(tmp_path, projected_tif, "shade", "--sun", "135,20")
    assert names == ["direct", "sun"]
    r = hfvis.sun_shading(dem, 135, 20, cell_size=30, nodata=NODATA)
    equal(r.sun, sun)
    equal(r.direct, direct)
    (direct, hours), names = cli(tmp_path, projected_tif, "insolation", "--lat", "36.6", "--lon", "-84.2", "--from",
                                 "2026-12-21T00:00:00-05:00", "--to", "2026-12-22T00:00:00-05:00", "--step", "30")
    assert names == ["direct", "sun_hours"]
    r = hfvis.insolation(dem, 36.6, -84.2, "2026-12-21T00:00:00-05:00", "2026-12-22T00:00:00-05:00",
                         step_minutes=30, cell_size=30, nodata=NODATA)
    equal(r.sun_hours, hours)
    equal(r.direct, direct)


def test_environment_light_and_sun_position(tmp_path, projected_tif, dem):
    from conftest import ROOT

    sky = ROOT / "data" / "clear_sky.exr"
    (r, g, b), names = cli(tmp_path, projected_tif, "shade", "--env", sky, "-k", "8")
    assert names == ["R", "G", "B"]
    ours = hfvis.environment_light(dem, str(sky), directions=8, cell_size=30, nodata=NODATA)
    assert ours.shape == (3,) + dem.shape
    equal(ours, np.stack([r, g, b]))
    azimuth, elevation = hfvis.sun_position("2026-06-21T12:00:00Z", 46.6, 8.0)
    done = run_cli("sun-position", "--at", "2026-06-21T12:00:00Z", "--lat", "46.6", "--lon", "8.0", quiet=False)
    printed = dict(item.split("=") for item in done.stdout.split())
    assert abs(float(printed["azimuth"]) - azimuth) < 1e-4 and abs(float(printed["elevation"]) - elevation) < 1e-4


def test_any_float_dtype_strides_and_byte_order_give_the_same(dem):
    heights = np.where(dem == NODATA, np.nan, dem).astype(np.float32)
    reference = hfvis.sky_view_factor(heights, directions=4, max_distance=600, cell_size=30)
    before = heights.copy()
    variants = {
        "float64": heights.astype(np.float64),
        "big-endian": heights.astype(">f4"),
        "big-endian float64": heights.astype(">f8"),
        "Fortran order": np.asfortranarray(heights),
        "strided": np.repeat(np.repeat(heights, 2, axis=0), 2, axis=1)[::2, ::2],
        "read-only": np.frombuffer(heights.tobytes(), np.float32).reshape(heights.shape),
    }
    for name, variant in variants.items():
        equal(hfvis.sky_view_factor(variant, directions=4, max_distance=600, cell_size=30), reference)
    equal(heights, before)  # the input is never modified
    ints = np.nan_to_num(heights, nan=NODATA).round().astype(np.int16)
    out = hfvis.sky_view_factor(ints, directions=4, max_distance=600, cell_size=30, nodata=NODATA)
    assert np.isnan(out[100, 150]) and (ints == np.nan_to_num(heights, nan=NODATA).round()).all()


def test_devices_and_context_reuse():
    found = hfvis.devices()
    assert found and {"index", "name", "type", "platform"} <= set(found[0])
    small = np.random.default_rng(1).random((32, 32), dtype=np.float32)
    first = hfvis.sky_view_factor(small, directions=8)
    equal(hfvis.sky_view_factor(small, directions=8, device="cpu"), first)
    with pytest.raises(hfvis.NoDeviceError):
        hfvis.sky_view_factor(small, device="no such device")
