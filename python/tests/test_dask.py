"""Dask-backed DataArrays: chunk by chunk with a halo of the maximum distance, against the
in-memory run on fixed and random chunkings (chunks smaller than the halo among them) with nodata
holes across chunk edges: bit for bit, NaN where it was (the horizon sweep's outputs,
intervisibility, environment light, viewsheds and cumulative viewsheds), on a projected grid and on a latitude /
longitude one; a LocalCluster of two worker processes."""

import dask.array as da
import numpy as np
import pytest
import xarray as xr

import hfvis

CELL = 30.0
MAX_DISTANCE = 300.0  # 10 cells: a halo of 12 pixels
# An RGB sky, 8 x 16 (equirectangular, row 0 at the zenith), brighter toward the zenith and in
# the north, so that every horizon changes the light.
SKY = np.stack([np.outer(np.linspace(3, 1, 8), np.linspace(1, 2, 16) * f) for f in (1.0, 0.7, 0.4)]).astype(
    np.float32)


@pytest.fixture(scope="module")
def field(jacksboro):
    """A 150 x 190 part of the DEM with coordinates, holes across the chunk edges used below."""
    heights = jacksboro[60:210, 120:310].copy()
    heights[35:39, :] = np.nan  # across the row edge at 37
    heights[80:90, 50:57] = np.nan  # across the column edge at 53 and at 16-pixel edges
    heights[:, 111:113] = np.nan
    y = 4000000.0 - CELL * (np.arange(heights.shape[0]) + 0.5)
    x = 700000.0 + CELL * (np.arange(heights.shape[1]) + 0.5)
    return xr.DataArray(heights, dims=("y", "x"), coords={"y": y, "x": x})


def chunkings():
    rng = np.random.default_rng(30)
    fixed = [(37, 53), (16, 16), (5, 190), (150, 7)]
    randomised = []
    for _ in range(2):
        randomised.append((tuple(_random_chunks(rng, 150)), tuple(_random_chunks(rng, 190))))
    return fixed + randomised


def _random_chunks(rng, total):
    sizes = []
    while sum(sizes) < total:
        sizes.append(int(min(rng.integers(3, 60), total - sum(sizes))))
    return sizes


# Each block is told where it lies in the whole field and the whole field's base height
# (HeightField::origin), so the sweep samples and cuts every line where the in-memory run does.
EXACT = {
    "intervisibility": lambda a: hfvis.intervisibility(a, directions=8, max_distance=MAX_DISTANCE),
    "sky_view_factor": lambda a: hfvis.sky_view_factor(a, directions=8, max_distance=MAX_DISTANCE),
    "ambient_occlusion": lambda a: hfvis.ambient_occlusion(a, directions=8, max_distance=MAX_DISTANCE),
    "horizon_angles": lambda a: hfvis.horizon_angles(a, directions=8, max_distance=MAX_DISTANCE),
    "horizon_distances": lambda a: hfvis.horizon_distances(a, directions=8, max_distance=MAX_DISTANCE,
                                                           samples_per_unit=2.5, curvature=1e-5),
    "sun_shading": lambda a: hfvis.sun_shading(a, 200, 15, max_distance=MAX_DISTANCE),
    "insolation": lambda a: hfvis.insolation(a, 32.9, -98.1, "2024-06-21T14:00:00Z", "2024-06-21T16:00:00Z",
                                             step_minutes=30, max_distance=MAX_DISTANCE),
    "environment_light": lambda a: hfvis.environment_light(a, SKY, directions=8, max_distance=MAX_DISTANCE),
}


def planes(result):
    return [result[name] for name in sorted(result)] if isinstance(result, xr.Dataset) else [result]


@pytest.mark.parametrize("operation", sorted(EXACT))
def test_chunked_equals_in_memory_bit_for_bit(field, operation):
    run = EXACT[operation]
    whole = planes(run(field))
    assert all(np.isnan(w.values).any() and not np.isnan(w.values).all() for w in whole)  # holes, and values
    for chunks in chunkings():
        chunked = planes(run(field.chunk({"y": chunks[0], "x": chunks[1]})))
        assert len(chunked) == len(whole)
        for got, want in zip(chunked, whole):
            assert got.chunks is not None, "a Dask input gives a Dask result"
            assert got.dims == want.dims
            values, wanted = got.values, want.values
            # NaN at the same pixels, the same bits everywhere else (-0 is not 0).
            holes = np.isnan(wanted)
            assert np.array_equal(np.isnan(values), holes), f"{got.name} {chunks}: nodata moved"
            assert np.array_equal(values[~holes].view(np.uint32), wanted[~holes].view(np.uint32)), \
                f"{got.name} {chunks}: largest difference {np.nanmax(np.abs(values - wanted))}"
            for name, coord in want.coords.items():
                np.testing.assert_array_equal(got[name], coord)


def test_a_height_far_below_the_rest_moves_nothing_beyond_its_reach(field):
    """An undeclared void of -1e6 at a corner: the heights count from the median of a lattice of
    them (the library's heightBase, which the chunks are told), not from the lowest, which held
    every other height to steps of 1/16: beyond the void's reach the result is the one without it,
    bit for bit, chunked as in memory."""
    pitted = field.copy()
    pitted.values[0, 0] = -1e6  # (not on the lattice: the base stays the field's)
    plain = hfvis.sky_view_factor(field, directions=8, max_distance=MAX_DISTANCE).values
    whole = hfvis.sky_view_factor(pitted, directions=8, max_distance=MAX_DISTANCE).values
    reach = 13  # the halo's 12 pixels and the cell beyond
    assert np.array_equal(whole[reach:, reach:], plain[reach:, reach:], equal_nan=True)
    assert whole[0, 0] < plain[0, 0]  # (the void is there: a well a million deep at the corner)
    chunked = hfvis.sky_view_factor(pitted.chunk({"y": 37, "x": 53}), directions=8, max_distance=MAX_DISTANCE)
    assert np.array_equal(chunked.values, whole, equal_nan=True)


def test_infinite_heights_are_nodata_as_in_memory(field):
    """+-inf are nodata (as NaN): the base of every block's heights is taken from finite ones."""
    holes = field.copy()
    holes.values[10, 10] = -np.inf
    holes.values[100, 150] = np.inf
    whole = hfvis.sky_view_factor(holes, directions=4, max_distance=MAX_DISTANCE)
    chunked = hfvis.sky_view_factor(holes.chunk(40), directions=4, max_distance=MAX_DISTANCE)
    np.testing.assert_array_equal(chunked.values, whole.values)


def test_chunks_smaller_than_the_halo_are_rechunked(field):
    svf = hfvis.sky_view_factor(field.chunk({"y": 5, "x": 5}), directions=4, max_distance=MAX_DISTANCE)
    assert min(min(c) for c in svf.chunks) >= 12  # the halo: ceil(300 / 30) + 2 pixels


def test_a_halo_beyond_the_field_along_one_axis(field):
    """A field fewer rows high than the halo (10 rows, a halo of 12) is one chunk along them, and
    none of its halo goes there: dask refused an overlap deeper than the array ("The overlapping
    depth 12 is larger than your array 10")."""
    strip = field[:10]
    whole = hfvis.sky_view_factor(strip, directions=4, max_distance=MAX_DISTANCE)
    for chunks in ({"y": 3, "x": 40}, {"y": 10, "x": 15}):
        chunked = hfvis.sky_view_factor(strip.chunk(chunks), directions=4, max_distance=MAX_DISTANCE)
        np.testing.assert_array_equal(chunked.values, whole.values)


def test_no_maximum_distance_is_refused(field):
    with pytest.raises(hfvis.InvalidArgumentError, match="max_distance"):
        hfvis.sky_view_factor(field.chunk(50), directions=4)
    with pytest.raises(hfvis.InvalidArgumentError, match="max_distance"):
        hfvis.environment_light(field.chunk(50), SKY, directions=4)


@pytest.mark.parametrize("max_distance", [MAX_DISTANCE, 0.0])
def test_viewshed_on_the_window_it_reaches(field, max_distance):
    """One observer: the window within the maximum distance is a task of its own, the rest out of
    range (0, NaN at nodata); without a maximum distance the whole field. Bit for bit."""
    x, y = float(field.x[100]), float(field.y[40])  # beside the holes across rows 35-38
    whole = hfvis.viewshed(field, (x, y), max_distance=max_distance)
    assert np.isnan(whole.values).any() and (whole.values == 1).sum() > 20
    for chunks in chunkings():
        got = hfvis.viewshed(field.chunk({"y": chunks[0], "x": chunks[1]}), (x, y), max_distance=max_distance)
        assert got.chunks is not None, "a Dask input gives a Dask result"
        values, wanted = got.values, whole.values
        assert np.array_equal(np.isnan(values), np.isnan(wanted)), f"{chunks}: nodata moved"
        assert np.array_equal(values[~np.isnan(wanted)], wanted[~np.isnan(wanted)]), f"{chunks}"


def test_cumulative_viewshed_split_and_summed(field):
    observers = np.array([[20, 30], [100, 100], [180, 10], [5, 140], [60, 70]])
    points = np.stack([field.x.values[observers[:, 0]], field.y.values[observers[:, 1]]], axis=1)
    whole = hfvis.cumulative_viewshed(field, points, max_distance=2000)
    chunked = hfvis.cumulative_viewshed(field.chunk(64), points, max_distance=2000)
    assert chunked.chunks is not None
    np.testing.assert_array_equal(chunked.values, whole.values)


def test_local_cluster_with_two_worker_processes(field):
    import distributed

    observers = np.array([[field.x.values[i], field.y.values[j]] for i, j in [(20, 30), (100, 100), (180, 10)]])
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            counts = hfvis.intervisibility(field.chunk(48), directions=4, max_distance=MAX_DISTANCE).visible_count
            seen = hfvis.cumulative_viewshed(field.chunk(75), observers)
            computed_counts, computed_seen = client.compute([counts.data, seen.data], sync=True)
            workers = client.run(lambda: __import__("os").getpid())
    assert len(set(workers.values())) == 2
    whole = hfvis.intervisibility(field, directions=4, max_distance=MAX_DISTANCE).visible_count
    np.testing.assert_array_equal(computed_counts, whole.values)
    np.testing.assert_array_equal(computed_seen, hfvis.cumulative_viewshed(field, observers).values)


LATITUDE_LONGITUDE_DISTANCE = 30000.0  # metres: a halo of ceil(30000 / 3807) + 2 = 10 pixels


@pytest.fixture(scope="module")
def latitude_longitude_field():
    """60 to 70 degrees north in 0.1 degree cells: a row's east-west spacing (3807 m to 5663 m)
    shrinks by a third over the field. Nodata holes across the chunk edges used below."""
    rng = np.random.default_rng(5)
    heights = (np.cumsum(np.cumsum(rng.normal(size=(100, 120)), 0), 1) * 20).astype(np.float32)
    heights[35:39, :] = np.nan  # across the row edge at 37
    heights[60:70, 50:57] = np.nan  # across the column edge at 53 and at 16-pixel edges
    heights[:, 79:81] = np.nan
    lat, lon = 70 - 0.1 * (np.arange(100) + 0.5), 10 + 0.1 * (np.arange(120) + 0.5)
    return xr.DataArray(heights, dims=("lat", "lon"), coords={"lat": lat, "lon": lon})


def latitude_longitude_chunkings():
    rng = np.random.default_rng(31)
    fixed = [(37, 53), (16, 16), (5, 120), (100, 7)]  # 5 and 7: smaller than the halo
    return fixed + [(tuple(_random_chunks(rng, 100)), tuple(_random_chunks(rng, 120))) for _ in range(2)]


def _latitude_longitude(operation):
    """EXACT's operation within LATITUDE_LONGITUDE_DISTANCE."""
    d = LATITUDE_LONGITUDE_DISTANCE
    return {
        "intervisibility": lambda a: hfvis.intervisibility(a, directions=8, max_distance=d),
        "sky_view_factor": lambda a: hfvis.sky_view_factor(a, directions=8, max_distance=d),
        "ambient_occlusion": lambda a: hfvis.ambient_occlusion(a, directions=8, max_distance=d),
        "horizon_angles": lambda a: hfvis.horizon_angles(a, directions=8, max_distance=d),
        "horizon_distances": lambda a: hfvis.horizon_distances(a, directions=8, max_distance=d,
                                                               samples_per_unit=2.5, curvature=1e-5),
        "sun_shading": lambda a: hfvis.sun_shading(a, 200, 15, max_distance=d),
        "insolation": lambda a: hfvis.insolation(a, 65.0, 16.0, "2024-06-21T10:00:00Z", "2024-06-21T12:00:00Z",
                                                 step_minutes=30, max_distance=d),
    }[operation]


def test_latitude_longitude_grid_takes_each_blocks_rows(latitude_longitude_field):
    """Each block's rows have their own spacing: a block computed with other rows' spacing
    would be off by about 1e-2."""
    field = latitude_longitude_field
    whole = hfvis.sky_view_factor(field, directions=8, max_distance=LATITUDE_LONGITUDE_DISTANCE)
    centre_spacing = hfvis.sky_view_factor(field.values, directions=8, max_distance=LATITUDE_LONGITUDE_DISTANCE,
                                           cell_size=(0.1 * 111320 * np.cos(np.radians(65)), 0.1 * 111320))
    assert np.nanmax(np.abs(centre_spacing - whole.values)) > 1e-3  # the rows' spacing matters here


# (environment lighting takes a field of one cell size: it refuses per-row spacing)
@pytest.mark.parametrize("operation", sorted(set(EXACT) - {"environment_light"}))
def test_latitude_longitude_chunked_equals_in_memory_bit_for_bit(latitude_longitude_field, operation):
    """On a latitude / longitude grid too: the horizon sweep's positions are whole units of ground
    length counted along the whole field's lines, the hull tree's whole units (HeightField::origin
    carries the whole field's rows)."""
    run = _latitude_longitude(operation)
    field = latitude_longitude_field
    whole = planes(run(field))
    assert all(np.isnan(w.values).any() and not np.isnan(w.values).all() for w in whole)  # holes, and values
    for chunks in latitude_longitude_chunkings():
        chunked = planes(run(field.chunk({"lat": chunks[0], "lon": chunks[1]})))
        assert len(chunked) == len(whole)
        for got, want in zip(chunked, whole):
            assert got.chunks is not None
            values, wanted = got.values, want.values
            holes = np.isnan(wanted)
            assert np.array_equal(np.isnan(values), holes), f"{got.name} {chunks}: nodata moved"
            assert np.array_equal(values[~holes].view(np.uint32), wanted[~holes].view(np.uint32)), \
                f"{got.name} {chunks}: largest difference {np.nanmax(np.abs(values - wanted))}"


def test_wide_heights_float32_cannot_hold_are_refused_chunk_by_chunk(field):
    """Heights of a wider dtype pass the in-memory run's float32 rounding check on a Dask array too
    (they were converted unchecked: heights near 1e10 came out flat), lazily; where float32 keeps
    them, with a nodata value of their own dtype, the result is the float32 array's bit for bit."""
    wide = field.astype(np.float64)
    far = (wide + 1e10).chunk({"y": 37, "x": 53})
    with pytest.raises(ValueError, match="rounds them"):
        hfvis.sky_view_factor(far, directions=8, max_distance=MAX_DISTANCE).compute()
    with pytest.raises(ValueError, match="rounds them"):  # the in-memory run refuses them alike
        hfvis.sky_view_factor(wide + 1e10, directions=8, max_distance=MAX_DISTANCE)
    near = wide.fillna(-9999.0).chunk({"y": 37, "x": 53})
    got = hfvis.sky_view_factor(near, directions=8, max_distance=MAX_DISTANCE, nodata=-9999.0).values
    want = hfvis.sky_view_factor(field, directions=8, max_distance=MAX_DISTANCE).values
    holes = np.isnan(want)
    assert holes.any() and np.array_equal(np.isnan(got), holes)
    assert np.array_equal(got[~holes].view(np.uint32), want[~holes].view(np.uint32))


@pytest.mark.parametrize("call", [
    lambda a: hfvis.sky_view_factor(a, directions=8, max_distance=10),
    lambda a: hfvis.intervisibility(a, directions=8, max_distance=10),
    lambda a: hfvis.cumulative_viewshed(a, [(5, 5)], pixels=True),
    lambda a: hfvis.viewshed(a, (5, 5), pixels=True),
    lambda a: hfvis.region_visibility(a, (1, 1, 3, 3)),
    lambda a: hfvis.sky_view_factor(a, max_error=0.05),
])
def test_unknown_chunk_sizes_are_refused_naming_the_cure(call):
    """Boolean indexing leaves a Dask array's chunk sizes NaN: Dask's or xarray's own errors, or
    "outside the 100 x nan field", before."""
    z = (100 + 20 * np.random.default_rng(0).random((120, 100))).astype(np.float32)
    d = da.from_array(z, chunks=30)
    a = xr.DataArray(d[d[:, 0] > -1e9], dims=("y", "x"))
    with pytest.raises(hfvis.InvalidArgumentError, match="compute_chunk_sizes"):
        call(a)


def test_latitude_longitude_azimuths_are_those_computed(latitude_longitude_field):
    """The azimuths of a chunked horizon run are the whole field's as computed (its cells' aspect
    moves them off the even spacing), as in memory: a probe of cells of 1 gave 0, 45, 90, ..., and
    subtracting the two runs kept half the azimuths."""
    field = latitude_longitude_field
    d = LATITUDE_LONGITUDE_DISTANCE
    whole = hfvis.horizon_angles(field, directions=8, max_distance=d)
    chunked = hfvis.horizon_angles(field.chunk({"lat": 20, "lon": 20}), directions=8, max_distance=d)
    assert not np.allclose(whole.azimuth.values % 45.0, 0.0)  # the aspect moved them
    assert np.array_equal(chunked.azimuth.values, whole.azimuth.values)
    assert (whole - chunked).sizes["azimuth"] == 8


def test_viewsheds_on_latitude_longitude_grids_are_refused_when_asked(latitude_longitude_field):
    """As the library refuses them, at once: not a lazy array that fails when computed."""
    field = latitude_longitude_field.chunk(20)
    lon, lat = float(field.lon[5]), float(field.lat[5])
    with pytest.raises(hfvis.InvalidArgumentError, match="latitude / longitude"):
        hfvis.viewshed(field, (lon, lat), max_distance=LATITUDE_LONGITUDE_DISTANCE)
    with pytest.raises(hfvis.InvalidArgumentError, match="latitude / longitude"):
        hfvis.cumulative_viewshed(field, [(lon, lat)])
