"""Dask-backed DataArrays: chunk by chunk with a halo of the maximum distance, against the
in-memory run on fixed and random chunkings (chunks smaller than the halo among them) with nodata
holes across chunk edges: bit for bit where the library gives it (intervisibility, cumulative
viewsheds), within rounding for the horizon sweep's outputs; a LocalCluster of two worker
processes."""

import dask.array as da
import numpy as np
import pytest
import xarray as xr

import hfvis

CELL = 30.0
MAX_DISTANCE = 300.0  # 10 cells: a halo of 12 pixels


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


# Exact: the hull tree decides visibility exactly, so every chunking gives the same bits.
EXACT = {
    "intervisibility": lambda a: hfvis.intervisibility(a, directions=8, max_distance=MAX_DISTANCE),
}
# Not bit for bit (a known defect, docs/python.md): the horizon sweep places a line's samples at
# (offset + j) * period from the line's start at the field's edge, so a chunk's lines round
# differently (and a sample exactly at the maximum distance may be cut or kept). The bounds are
# those measured on these chunkings, with some room; other fields and distances can exceed them.
WITHIN = {
    "sky_view_factor": (lambda a: hfvis.sky_view_factor(a, directions=8, max_distance=MAX_DISTANCE), 2e-6),
    "ambient_occlusion": (lambda a: hfvis.ambient_occlusion(a, directions=8, max_distance=MAX_DISTANCE), 2e-6),
    "horizon_angles": (lambda a: hfvis.horizon_angles(a, directions=8, max_distance=MAX_DISTANCE), 2e-5),
    "sun_shading": (lambda a: hfvis.sun_shading(a, 200, 15, max_distance=MAX_DISTANCE).direct, 2e-4),
}


def planes(result):
    return [result[name] for name in sorted(result)] if isinstance(result, xr.Dataset) else [result]


@pytest.mark.parametrize("operation", sorted(EXACT))
def test_chunked_equals_in_memory_bit_for_bit(field, operation):
    run = EXACT[operation]
    whole = planes(run(field))
    for chunks in chunkings():
        chunked = planes(run(field.chunk({"y": chunks[0], "x": chunks[1]})))
        for got, want in zip(chunked, whole):
            assert got.chunks is not None, "a Dask input gives a Dask result"
            np.testing.assert_array_equal(got.values, want.values, err_msg=f"{got.name} {chunks}")


@pytest.mark.parametrize("operation", sorted(WITHIN))
def test_chunked_equals_in_memory_within_rounding(field, operation):
    run, bound = WITHIN[operation]
    whole = run(field)
    for chunks in chunkings():
        chunked = run(field.chunk({"y": chunks[0], "x": chunks[1]}))
        assert chunked.chunks is not None and chunked.dims == whole.dims
        np.testing.assert_array_equal(np.isnan(chunked.values), np.isnan(whole.values))  # nodata where it was
        np.testing.assert_allclose(chunked.values, whole.values, rtol=0, atol=bound, err_msg=str(chunks))
        if "azimuth" in whole.coords:
            np.testing.assert_array_equal(chunked.azimuth, whole.azimuth)
        for name, coord in whole.coords.items():
            np.testing.assert_array_equal(chunked[name], coord)


def test_chunks_smaller_than_the_halo_are_rechunked(field):
    svf = hfvis.sky_view_factor(field.chunk({"y": 5, "x": 5}), directions=4, max_distance=MAX_DISTANCE)
    assert min(min(c) for c in svf.chunks) >= 12  # the halo: ceil(300 / 30) + 2 pixels


def test_no_maximum_distance_is_refused(field):
    with pytest.raises(hfvis.InvalidArgumentError, match="max_distance"):
        hfvis.sky_view_factor(field.chunk(50), directions=4)


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


def test_latitude_longitude_grid_takes_each_blocks_rows():
    """60 to 70 degrees north in 0.1 degree cells: a row's east-west spacing shrinks by a third
    over the field, so a block computed with other rows' spacing would be off by about 1e-2."""
    rng = np.random.default_rng(5)
    heights = (np.cumsum(np.cumsum(rng.normal(size=(100, 120)), 0), 1) * 20).astype(np.float32)
    lat, lon = 70 - 0.1 * (np.arange(100) + 0.5), 10 + 0.1 * (np.arange(120) + 0.5)
    field = xr.DataArray(heights, dims=("lat", "lon"), coords={"lat": lat, "lon": lon})
    whole = hfvis.sky_view_factor(field, directions=8, max_distance=30000)
    centre_spacing = hfvis.sky_view_factor(heights, directions=8, max_distance=30000,
                                           cell_size=(0.1 * 111320 * np.cos(np.radians(65)), 0.1 * 111320))
    assert np.nanmax(np.abs(centre_spacing - whole.values)) > 1e-3  # the rows' spacing matters here
    for chunks in [(37, 53), (16, 120), (100, 9)]:
        chunked = hfvis.sky_view_factor(field.chunk({"lat": chunks[0], "lon": chunks[1]}), directions=8,
                                        max_distance=30000)
        np.testing.assert_allclose(chunked.values, whole.values, rtol=0, atol=1e-6, err_msg=str(chunks))
    counts = hfvis.intervisibility(field, directions=8, max_distance=30000).visible_count
    chunked = hfvis.intervisibility(field.chunk({"lat": 37, "lon": 53}), directions=8, max_distance=30000)
    np.testing.assert_array_equal(chunked.visible_count.values, counts.values)
