"""Bad input: Python exceptions under hfvis.Error (ValueError, TypeError, OSError), a clear
message, never a crash; the input untouched."""

import numpy as np
import pytest
import xarray as xr

import hfvis
from conftest import ROOT


@pytest.fixture()
def small():
    return np.random.default_rng(2).random((24, 20), dtype=np.float32)


@pytest.mark.parametrize("bad, kind, words", [
    (np.zeros(10, np.float32), TypeError, "2-D"),
    (np.zeros((2, 3, 4), np.float32), TypeError, "2-D"),
    (np.zeros((4, 4), complex), TypeError, "real numbers"),
    (np.zeros((4, 4), bool), TypeError, "real numbers"),
    (np.array([["a", "b"], ["c", "d"]]), TypeError, "real numbers"),
    (np.zeros((0, 4), np.float32), ValueError, "empty"),
    (np.full((4, 4), np.nan, np.float32), ValueError, "nodata"),
    (np.full((4, 4), 1e300), ValueError, "float32"),
    ([[1.0, 2.0], [3.0]], TypeError, "rows of different lengths"),
    (xr.Dataset({"dem": (("y", "x"), np.zeros((4, 4)))}), TypeError, "not an xarray.Dataset \\(1 variable: 'dem'\\)"),
])
def test_bad_heights(bad, kind, words):
    with pytest.raises(kind, match=words) as caught:
        hfvis.sky_view_factor(bad, directions=4)
    assert isinstance(caught.value, hfvis.Error)


@pytest.mark.parametrize("call, words", [
    (lambda h: hfvis.sky_view_factor(h, directions=0), "K"),
    (lambda h: hfvis.sky_view_factor(h, cell_size=-1.0), "cell size"),
    (lambda h: hfvis.sky_view_factor(h, cell_size=(1.0, 2.0, 3.0)), "pair"),
    (lambda h: hfvis.sky_view_factor(h, z_scale=0.0), "z_scale must lie in 1e-12 .. 1e12"),
    (lambda h: hfvis.sky_view_factor(h, max_distance=-5.0), "distance"),
    (lambda h: hfvis.sky_view_factor(h, method="ray"), "method"),
    (lambda h: hfvis.viewshed(h, (20, 3)), "outside"),
    (lambda h: hfvis.viewshed(h, (-1, 3)), "outside"),
    (lambda h: hfvis.viewshed(h, (1.5, 3)), "integers"),
    (lambda h: hfvis.cumulative_viewshed(h, np.array([[1, 2], [30, 2]])), "outside"),
    (lambda h: hfvis.cumulative_viewshed(h, np.zeros((0, 2), int)), "N x 2"),
    (lambda h: hfvis.sun_shading(h, 100, 20, size_deg=20), "size"),
    (lambda h: hfvis.insolation(h, 46, 8, "2026-06-21T00:00", "2026-06-22T00:00Z"), "zone"),
    (lambda h: hfvis.insolation(h, 46, 8, "2026-06-22T00:00Z", "2026-06-21T00:00Z"), "forward"),
    (lambda h: hfvis.environment_light(h, np.ones((4, 5), np.float32)), "twice as wide"),
    (lambda h: hfvis.sun_position("yesterday", 46, 8), "ISO|time"),
    (lambda h: hfvis.sky_view_factor(h, max_error=1e-9), "4096"),
    (lambda h: hfvis.sky_view_factor(h, cell_size=1e300), "1e-06 .. 1e\\+09"),
    (lambda h: hfvis.sky_view_factor(h, cell_size=1e-30), "1e-06 .. 1e\\+09"),
    (lambda h: hfvis.sky_view_factor(h, azimuth_offset=1e20), "azimuth offset"),
    (lambda h: hfvis.sky_view_factor(h, nodata="x"), "nodata"),
    (lambda h: hfvis.sky_view_factor(h, directions=8.5), "whole number"),
    (lambda h: hfvis.sky_view_factor(h, directions="8"), "whole number"),
    (lambda h: hfvis.sky_view_factor(h, directions=2**40), "directions must be at most"),
    (lambda h: hfvis.sky_view_factor(h, memory_budget_bytes=-1), "memory_budget_bytes must lie"),
    (lambda h: hfvis.sky_view_factor(h.astype(np.float64) + 1e10), "rounds them"),
    (lambda h: hfvis.sky_view_factor((h * 100).astype(np.int64) + 2**40), "rounds them"),
    (lambda h: hfvis.sky_view_factor(h, max_error=-0.1), "error"),
    (lambda h: hfvis.region_visibility(h, (0, 0, 20, 3)), "outside"),
    (lambda h: hfvis.region_visibility(h, (0, 0, 1.5, 3)), "integer"),
    (lambda h: hfvis.region_visibility(h, (0, 0, 3, 3), samples=0), "samples"),
    (lambda h: hfvis.region_visibility(h, (0, 0, 3, 3), samples=5000), "samples"),
    (lambda h: hfvis.region_visibility(h, [(3.0, 30.0)]), "outside"),
    (lambda h: hfvis.region_visibility(h, np.zeros((0, 2))), "rectangle"),
    (lambda h: hfvis.region_visibility(h, (0, 0, 3, 3), method="bogus"), "method"),
    (lambda h: hfvis.region_visibility(h, (0, 0, 3, 3), target_height=-1), "target_height must lie in 0"),
    (lambda h: hfvis.region_pair_visibility(h, (0, 0, 3, 3), (5, 5, 6, 6), method="viewsheds"), "viewsheds"),
    (lambda h: hfvis.region_pair_visibility(h, (0, 0, 3, 3), (5, 5, 6, 60)), "outside"),
    (lambda h: hfvis.pvs(h), "budget"),
    (lambda h: hfvis.pvs(h, samples=100, view_cell=0), "view"),
    (lambda h: hfvis.pvs(h, samples=100, mask=np.ones((3, 3))), "mask"),
    (lambda h: hfvis.pvs(h, samples=100, method="best"), "method"),
    (lambda h: hfvis.horizon_lists(h, [(20, 3)]), "outside"),
    (lambda h: hfvis.horizon_lists(h, [(1.5, 3)]), "integer"),
    (lambda h: hfvis.bounce(h, np.ones((4, 4), np.float32)), "one value per height"),
    (lambda h: hfvis.bounce(h, -np.ones((24, 20), np.float32)), "radiance"),
    (lambda h: hfvis.bounce(h, np.ones((5, 24, 20), np.float32)), "channel"),
    # (beyond int32: nanobind's bare TypeError; a bool or "no" as a flag: bool() took them)
    (lambda h: hfvis.region_visibility(h, np.array([0, 0, 2**40, 3])), "2\\*\\*31"),
    (lambda h: hfvis.region_pair_visibility(h, (0, 0, 3, 3), np.array([0, 0, 2**63, 3], np.uint64)), "2\\*\\*31"),
    (lambda h: hfvis.horizon_lists(h, np.array([[2**31, 3]])), "outside"),
    (lambda h: hfvis.viewshed(h, (True, 3)), "integers"),
    (lambda h: hfvis.viewshed(h, (3, 3), absolute="no"), "absolute must be True or False"),
    (lambda h: hfvis.region_visibility(h, (0, 0, 3, 3), decorrelate="yes"), "decorrelate"),
    (lambda h: hfvis.sky_view_factor(h, directions=8, error_estimate="no"), "error_estimate"),
    (lambda h: hfvis.sun_position("2026-06-21T12:00Z", 46, 8, apparent=2), "apparent"),
    (lambda h: hfvis.read_height_field("dem.tif\0.exr"), "NUL"),
])
def test_bad_arguments_are_value_errors(small, call, words):
    before = small.copy()
    with pytest.raises(ValueError, match=words) as caught:
        call(small)
    assert isinstance(caught.value, hfvis.InvalidArgumentError)
    np.testing.assert_array_equal(small, before)


def test_a_call_from_a_progress_callback_is_refused_not_hung(small):
    # (the callback runs while its call holds the device: calling hfvis there waited for good)
    inner = []

    def progress(done, total):
        with pytest.raises(hfvis.Error, match="progress callback"):
            hfvis.sky_view_factor(small, directions=4)
        inner.append(done)

    outer = hfvis.sky_view_factor(small, directions=8, progress=progress)
    assert inner and np.array_equal(outer, hfvis.sky_view_factor(small, directions=8))


def test_a_nodata_no_integer_dtype_holds_marks_nothing(small):
    heights = (small * 100).astype(np.int16)
    plain = hfvis.sky_view_factor(heights, directions=4)
    for nodata in (2**70, -2**70, 2**64 - 1, 1e300, float("inf"), 0.5):  # (2**70: a bare OverflowError)
        assert np.array_equal(hfvis.sky_view_factor(heights, directions=4, nodata=nodata), plain), nodata
    heights[3, 4] = 7
    assert np.isnan(hfvis.sky_view_factor(heights, directions=4, nodata=7.0)[3, 4])
    assert np.isnan(hfvis.sky_view_factor(heights, directions=4, nodata=np.int64(7))[3, 4])
    assert np.array_equal(hfvis.sky_view_factor(small, directions=4, nodata=2**1100),
                          hfvis.sky_view_factor(small, directions=4))


def test_region_over_nodata_and_wrong_types(small):
    holed = small.copy()
    holed[2, 2] = np.nan
    with pytest.raises(hfvis.InvalidArgumentError, match="nodata"):
        hfvis.region_visibility(holed, (0, 0, 3, 3))
    with pytest.raises(hfvis.InputTypeError, match="radiance"):
        hfvis.bounce(small, np.ones((24, 20), complex))
    with pytest.raises(hfvis.InputTypeError, match="real numbers"):
        hfvis.region_visibility(small.astype(complex), (0, 0, 3, 3))


def test_files_are_os_errors(tmp_path, small):
    with pytest.raises(OSError, match="missing.exr") as caught:
        hfvis.read_height_field(tmp_path / "missing.exr")
    assert isinstance(caught.value, hfvis.IoError)
    with pytest.raises(hfvis.IoError):
        hfvis.environment_light(small, str(tmp_path / "no_sky.exr"))


def test_a_channel_is_a_name_or_an_index():
    dem = ROOT / "data" / "jacksboro_fault_dem.exr"
    by_index = hfvis.read_height_field(dem, channel=0).heights  # (an int raised nanobind's TypeError)
    assert np.array_equal(by_index, hfvis.read_height_field(dem, channel="0").heights, equal_nan=True)
    assert np.array_equal(by_index, hfvis.read_height_field(dem).heights, equal_nan=True)
    with pytest.raises(hfvis.InvalidArgumentError, match="channel"):
        hfvis.read_height_field(dem, channel=0.5)
    with pytest.raises(hfvis.IoError):
        hfvis.read_height_field(dem, channel=3)


def test_dataarrays(small):
    with pytest.raises(TypeError, match="2-D"):
        hfvis.sky_view_factor(xr.DataArray(np.zeros((2, 3, 4)), dims=("a", "y", "x")))
    uneven = xr.DataArray(small, dims=("y", "x"), coords={"y": np.arange(24.0) ** 2, "x": np.arange(20.0)})
    with pytest.raises(ValueError, match="evenly spaced"):
        hfvis.sky_view_factor(uneven)
    import dask.array as da

    with pytest.raises(TypeError, match="DataArray"):
        hfvis.sky_view_factor(da.from_array(small))


def test_progress_callback_errors_stop_the_run(small):
    def fail(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        hfvis.sky_view_factor(small, directions=16, progress=fail)
    assert np.isfinite(hfvis.sky_view_factor(small, directions=16)).all()  # the context still works


def test_region_visibility_reports_progress_and_stops_on_an_error(small):
    calls = []
    hfvis.region_visibility(small, (2, 2, 6, 6), samples=8, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1][0] == calls[-1][1], calls  # the last launch's receivers: all of them
    calls = []
    points = np.array([[3, 4], [10, 5], [15, 20]])
    hfvis.region_visibility(small, points, method="viewsheds", progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 3), (2, 3), (3, 3)]  # one viewshed per source sample

    def fail(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        hfvis.region_visibility(small, (2, 2, 6, 6), samples=8, progress=fail)
    with pytest.raises(RuntimeError, match="stop here"):
        hfvis.region_pair_visibility(small, (2, 2, 6, 6), (10, 10, 14, 14), samples=8, progress=fail)
    assert np.isfinite(hfvis.region_visibility(small, (2, 2, 6, 6), samples=8).fraction).all()


def test_ctrl_c_stops_a_run():
    """SIGINT during a long run: KeyboardInterrupt at the next batch of directions, not a hang or
    a crash."""
    import signal
    import subprocess
    import sys

    script = ("import sys, numpy as np, hfvis\n"
              "h = np.random.default_rng(3).random((64, 64), dtype=np.float32)\n"
              "def tell(done, total):\n"
              "    print('progress', done, flush=True)\n"
              "try:\n"
              "    hfvis.sky_view_factor(h, directions=4096, progress=tell)\n"
              "except KeyboardInterrupt:\n"
              "    print('interrupted', flush=True)\n"
              "    sys.exit(3)\n")
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().startswith("progress")
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)
    assert child.returncode == 3 and "interrupted" in out
    done = [int(line.split()[1]) for line in out.splitlines() if line.startswith("progress")]
    assert max(done, default=0) < 4096, "stopped at a batch, not run to the end"


def test_nodata_in_the_heights_dtype_and_masked_arrays(small):
    """A float64 nodata on float32 heights marks the float32 value (it marked nothing: the holes were
    computed as pits), and a masked array's mask is nodata (its values were taken as heights)."""
    h = small.copy()
    h[3:6, 4:8] = np.float32(-9999.9)
    result = hfvis.sky_view_factor(h, directions=8, nodata=np.float64(-9999.9))
    assert np.isnan(result[3:6, 4:8]).all() and np.isnan(result).sum() == 12
    masked = np.ma.masked_greater(small, 0.9)
    out = hfvis.sky_view_factor(masked, directions=8)
    assert np.array_equal(np.isnan(out), np.ma.getmaskarray(masked))
    # heights far from 0 whose float32 rounding stays small against a cell pass
    assert np.isfinite(hfvis.sky_view_factor(small.astype(np.float64) + 4000.0, directions=8)).all()


@pytest.mark.parametrize("call, words", [
    (lambda h: hfvis.horizon_angles(h, azimuth_tolerance="x"), "azimuth_tolerance must be a number"),
    (lambda h: hfvis.horizon_angles(h, azimuth_tolerance=[0.01]), "azimuth_tolerance must be a number"),
    (lambda h: hfvis.sky_view_factor(h, max_error="x"), "max_error must be a number"),
    (lambda h: hfvis.intervisibility(h, max_error=[0.1]), "max_error must be a number"),
    (lambda h: hfvis.environment_light(h, np.ones((4, 8)), rotation_deg="x"), "rotation_deg must be a number"),
    (lambda h: hfvis.environment_light(h, np.ones((4, 8)), rotation_deg=None), "rotation_deg must be a number"),
    (lambda h: hfvis.sky_view_factor(h, device=3.5), "device must be a selector string"),
    (lambda h: hfvis.sky_view_factor(h, device=99), "99"),
])
def test_more_options_of_the_wrong_kind_are_refused_naming_them(small, call, words):
    """nanobind's bare TypeError or float()'s ValueError before; an int device is an index."""
    with pytest.raises(hfvis.Error, match=words):
        call(small)


def test_a_device_index_as_an_int_is_taken(small):
    assert np.array_equal(hfvis.sky_view_factor(small, directions=4, device=0),
                          hfvis.sky_view_factor(small, directions=4))


def test_observers_far_outside_in_map_coordinates_are_refused_naming_the_extent():
    """An OverflowError (cumulative) or a message about pixels with a 30-digit array before."""
    z = (100 + 20 * np.random.default_rng(0).random((60, 50))).astype(np.float32)
    a = xr.DataArray(z, dims=("y", "x"), coords={"y": 46e5 - 10 * np.arange(60) - 5.0,
                                                 "x": 5e5 + 10 * np.arange(50) + 5.0})
    for call in (lambda: hfvis.cumulative_viewshed(a, [(1e30, 1e30)]), lambda: hfvis.viewshed(a, (1e30, 1e30)),
                 lambda: hfvis.viewshed(a, (5e5 - 1.0, 46e5 - 5.0))):
        with pytest.raises(hfvis.InvalidArgumentError, match="outside the field's extent, x 500000 .. 500500"):
            call()
    assert hfvis.viewshed(a, (5e5 + 1.0, 46e5 - 5.0)).shape == (60, 50)


@pytest.mark.parametrize("call, words", [
    (lambda h: hfvis.cumulative_viewshed(h, [(1, 2), (3,)]), "observers must be an array"),
    (lambda h: hfvis.region_visibility(h, [(1.0, 2.0, 3.0), (3.0, 4.0)]), "a region must be an array"),
    (lambda h: hfvis.bounce(h, [[1.0, 2.0], [3.0]]), "radiance must be an array"),
    (lambda h: hfvis.bounce(h, xr.Dataset({"r": (("y", "x"), np.ones(h.shape))})), "radiance must be an array, not"),
    (lambda h: hfvis.cumulative_viewshed(h, [(1, 2), (3, 4)], observer_height=[1.0, 2.0, 3.0]), "one per observer"),
])
def test_ragged_lists_and_datasets_besides_the_heights_are_refused(small, call, words):
    """numpy's bare ValueError (a ragged list) or xarray's TypeError (a Dataset) before."""
    with pytest.raises(hfvis.Error, match=words):
        call(small)


def test_integer_options_and_dask_edges_are_refused_clearly():
    """Integer options beyond their type or not whole gave nanobind's bare TypeError or ran
    truncated (seed=1.5 as 1, tile=2.5 as 2); a Dask field's infinite or NaN max_distance, empty
    field or all-nodata one gave numpy's and Python's own errors, or NaN everywhere."""
    import dask.array as da
    import xarray as xr

    z = np.random.default_rng(0).normal(size=(30, 40)).cumsum(0).cumsum(1).astype(np.float32)
    for call in (lambda: hfvis.region_visibility(z, (0, 0, 3, 3), seed=-1),
                 lambda: hfvis.region_visibility(z, (0, 0, 3, 3), seed=1.5),
                 lambda: hfvis.pvs(z, samples=100, tile=2.5),
                 lambda: hfvis.pvs(z, samples=100, batch=2**40),
                 lambda: hfvis.viewshed(z, (2**40, 0))):
        with pytest.raises(hfvis.InvalidArgumentError):
            call()
    a = xr.DataArray(da.from_array(z, chunks=10), dims=("y", "x"),
                     coords={"y": -30.0 * np.arange(30), "x": 30.0 * np.arange(40)})
    for size in (0.0, float("nan"), -1.0, 1e-30):  # (before the halo: raw errors, or the field as one chunk)
        with pytest.raises(hfvis.InvalidArgumentError, match="cell size"):
            hfvis.sky_view_factor(a, directions=8, max_distance=100, cell_size=size)
    far = a.astype(np.float64)
    far[3, 3] = 1e39
    with pytest.raises(hfvis.InvalidArgumentError, match="beyond float32's range"):
        hfvis.sky_view_factor(far, directions=8, max_distance=100).compute()
    for distance in (float("nan"), float("inf")):
        with pytest.raises(hfvis.InvalidArgumentError, match="max_distance must lie in 0 .. 1e\\+12"):
            hfvis.sky_view_factor(a, directions=8, max_distance=distance).compute()
    with pytest.raises(hfvis.InvalidArgumentError, match="empty"):
        hfvis.sky_view_factor(a[:0], directions=8, max_distance=100).compute()
    with pytest.raises(hfvis.InvalidArgumentError, match="every height is nodata"):
        hfvis.sky_view_factor(a * np.nan, directions=8, max_distance=100).compute()
    # A viewshed's observer outside the field is refused at the call, and one on nodata named in
    # the field's pixels (the window's were given: "observer 6,6", "outside the 7 x 13 field")
    with pytest.raises(hfvis.InvalidArgumentError, match="observer 100,6 is outside the 40 x 30 field"):
        hfvis.viewshed(a, (100, 6), max_distance=100, pixels=True)
    holed = a.where(~((a.x == 600) & (a.y == -600)))
    with pytest.raises(hfvis.InvalidArgumentError, match="observer 20,20 stands on nodata"):
        hfvis.viewshed(holed, (20, 20), max_distance=100, pixels=True).compute()


def test_observers_and_suns_beyond_what_they_can_be_are_refused():
    """A DataArray's observer pixels that are not whole numbers ran truncated ((-0.5, 2.9) as
    (0, 2)), map coordinates of NaN gave a raw ValueError, a sun at azimuth 1e20 lit as another."""
    import xarray as xr

    z = np.random.default_rng(0).normal(size=(30, 40)).cumsum(0).cumsum(1).astype(np.float32)
    a = xr.DataArray(z, dims=("y", "x"), coords={"y": -30.0 * np.arange(30), "x": 30.0 * np.arange(40)})
    with pytest.raises(hfvis.InvalidArgumentError, match="two integers"):
        hfvis.viewshed(a, (-0.5, 2.9), pixels=True)
    with pytest.raises(hfvis.InvalidArgumentError, match="finite"):
        hfvis.viewshed(a, (float("nan"), 0.0))
    assert hfvis.viewshed(a, (3, 2), pixels=True).values[2, 3] == 1
    with pytest.raises(hfvis.InvalidArgumentError, match="-720 .. 720"):
        hfvis.sun_shading(z, 1e20, 10)
    # (taken as their plain kinds are: np.int64 seconds, a pathlib.Path environment)
    typed = hfvis.insolation(z, 32.9, -98.1, np.int64(1718978400), 1718985600.0)
    plain = hfvis.insolation(z, 32.9, -98.1, 1718978400, 1718985600.0)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(typed, plain))


def test_float32_coordinates_of_a_regular_grid_are_taken():
    """A 3-arc-second latitude / longitude grid with float32 coordinates (as NetCDF often holds
    them) steps unevenly by their rounding: it was refused as not evenly spaced."""
    import xarray as xr

    step = 1 / 1200
    z = np.random.default_rng(1).normal(size=(40, 50)).cumsum(0).cumsum(1).astype(np.float32)
    lat = (45 - step * (np.arange(40) + 0.5)).astype(np.float32)
    lon = (7 + step * (np.arange(50) + 0.5)).astype(np.float32)
    out = hfvis.sky_view_factor(xr.DataArray(z, dims=("lat", "lon"), coords={"lat": lat, "lon": lon}), directions=8)
    assert np.isfinite(out.values).all()
    uneven = lat.copy()
    uneven[5] += step / 10
    with pytest.raises(hfvis.InvalidArgumentError, match="not evenly spaced"):
        hfvis.sky_view_factor(xr.DataArray(z, dims=("lat", "lon"), coords={"lat": uneven, "lon": lon}), directions=8)
    # float32 northings near 4e6 (steps of 0.25) stepping 1 and 3 in turn are no grid of 2: the
    # allowance for their rounding had been about 2 (four float32 epsilons of the largest)
    north = (4e6 - np.r_[0, np.cumsum(np.where(np.arange(39) % 2, 3.0, 1.0))]).astype(np.float32)
    east = (5e5 + 2.0 * np.arange(50)).astype(np.float32)
    with pytest.raises(hfvis.InvalidArgumentError, match="not evenly spaced"):
        hfvis.sky_view_factor(xr.DataArray(z, dims=("y", "x"), coords={"y": north, "x": east}), directions=8)
    regular = (4e6 - 2.0 * np.arange(40)).astype(np.float32)
    assert np.isfinite(hfvis.sky_view_factor(xr.DataArray(z, dims=("y", "x"), coords={"y": regular, "x": east}),
                                             directions=8).values).all()


@pytest.mark.parametrize("call", [
    lambda h: hfvis.sky_view_factor(h, max_distance=None),
    lambda h: hfvis.sky_view_factor(h, samples_per_unit="x"),
    lambda h: hfvis.sky_view_factor(h, z_scale=None),
    lambda h: hfvis.sky_view_factor(h, cell_size={}),
    lambda h: hfvis.sky_view_factor(h, cell_size=(1, 2, 3)),
    lambda h: hfvis.sky_view_factor(h, progress=5),
    lambda h: hfvis.viewshed(h, (2, 2), observer_height=[1, 2]),
    lambda h: hfvis.sun_shading(h, "south", 10),
])
def test_options_of_the_wrong_kind_are_named(call):
    """An option of the wrong kind is an InvalidArgumentError naming it (float()'s bare TypeError
    and ValueError, or a failure mid-run, before)."""
    with pytest.raises(hfvis.InvalidArgumentError):
        call(np.random.default_rng(2).random((24, 20), dtype=np.float32))


@pytest.mark.parametrize("call, words", [
    (lambda h: hfvis.viewshed(h, (5, 5), observer_height=-1), "an eye below the surface sees nothing"),
    (lambda h: hfvis.cumulative_viewshed(h, [(5, 5), (6, 6)], observer_height=[1.0, -3.0]), "observer_height -3"),
    (lambda h: hfvis.region_visibility(h, (5, 5, 10, 10), samples=8, height=-1), "a sample below the surface"),
    (lambda h: hfvis.region_pair_visibility(h, (1, 1, 4, 4), (12, 12, 15, 15), samples=8, receiver_height=-1),
     "receiver_height -1"),
    (lambda h: hfvis.region_pair_visibility(h, np.array([[5.0, 5.0, -1.0]]), (12, 12, 15, 15), samples=8),
     "sources' heights -1"),
    (lambda h: hfvis.viewshed(h, (5, 5), azimuth_from_deg=90, azimuth_to_deg=90), "is no field of view"),
    (lambda h: hfvis.cumulative_viewshed(h, [(5, 5)], azimuth_from_deg=90), "give both azimuth_from_deg"),
    (lambda h: hfvis.sky_view_factor(h, z_scale=1e13), "z_scale must lie in 1e-12 .. 1e12"),
    (lambda h: hfvis.viewshed(h, (5, 5), observer_height=1e13), "observer_height must lie in"),
    (lambda h: hfvis.viewshed(h, (5, 5), target_height=1e13), "target_height must lie in 0 .. 1e\\+12"),
    (lambda h: hfvis.sky_view_factor(h, directions=2**40), "directions must be at most 2147483647"),
    (lambda h: hfvis.pvs(h, samples=-1), "samples must lie in 0 .."),
    (lambda h: hfvis.pvs(h, samples=100, start="junk"), "start must be an earlier run's bits"),
    (lambda h: hfvis.pvs(h, samples=100, view_cell=8, tile=4, start=np.zeros((3, 3), np.uint32)),
     "start holds 3 x 3 words, where this field and grid have 9 view cells of 1 words"),
    (lambda h: hfvis.pvs(h, samples=100, view_cell=8, tile=4, start=np.zeros((9, 1))), "2-D float64"),
])
def test_what_the_cli_refuses_python_refuses_too(small, call, words):
    """A probe's finds (2026-12-07): these ran, the CLI refusing each (a negative eye height saw
    one point, equal azimuths the whole circle), or gave nanobind's or int()'s bare errors."""
    with pytest.raises(hfvis.InvalidArgumentError, match=words):
        call(small)


def test_heights_below_zero_run_when_absolute_and_the_whole_circle_by_default(small):
    assert hfvis.viewshed(small, (5, 5), observer_height=-1, absolute=True).shape == small.shape
    whole = hfvis.viewshed(small, (5, 5))
    assert np.array_equal(whole, hfvis.viewshed(small, (5, 5), azimuth_from_deg=0, azimuth_to_deg=360))
    assert hfvis.viewshed(small, (5, 5), azimuth_from_deg=90, azimuth_to_deg=91).sum() < whole.sum()


def test_an_earlier_runs_bits_resume_a_pvs_and_a_dask_progress_is_warned_of(small):
    first = hfvis.pvs(small, samples=200, view_cell=8, tile=4)
    assert hfvis.pvs(small, samples=200, view_cell=8, tile=4, start=first.bits, seed=2).bits.shape == first.bits.shape
    import dask.array as da

    a = xr.DataArray(da.from_array(small, chunks=8), dims=("y", "x"))
    with pytest.warns(UserWarning, match="progress is not called for a Dask array"):
        hfvis.sky_view_factor(a, directions=4, max_distance=3, progress=lambda *args: None).compute()


def test_a_nan_coordinate_is_named():
    z = np.zeros((4, 5), np.float32)
    a = xr.DataArray(z, dims=("y", "x"), coords={"y": np.arange(4.0), "x": np.r_[np.arange(4.0), np.nan]})
    with pytest.raises(hfvis.InvalidArgumentError, match="the x coordinates hold a NaN"):
        hfvis.sky_view_factor(a, directions=4)
