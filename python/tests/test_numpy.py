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


def test_intervisibility_with_max_error(tmp_path, projected_tif, dem):
    """max_error=E chooses K as viewcount's --max-error does; error_estimate gives its --error-out."""
    import rasterio

    error_tif = tmp_path / "error.tif"
    (count, area), _ = cli(tmp_path, projected_tif, "viewcount", "--max-error", "0.3", "--max-distance", "1500",
                           "--error-out", error_tif)
    ours = hfvis.intervisibility(dem, max_error=0.3, error_estimate=True, max_distance=1500, cell_size=30,
                                 nodata=NODATA)
    assert isinstance(ours, hfvis.IntervisibilityEstimate)
    equal(ours.visible_count, count)
    equal(ours.visible_area, area)
    (error,), _ = read_bands(error_tif)
    equal(ours.error, error)
    with rasterio.open(error_tif) as f:
        tags = f.tags()
    assert int(tags["hfvis_directions"]) == ours.directions and ours.directions not in (16, 64)
    assert float(tags["hfvis_estimated_error"]) == float(f"{ours.estimated_error:.10g}") <= 0.3
    # Without max_error, error_estimate keeps the K given; the naive method has no estimate.
    fixed = hfvis.intervisibility(dem, directions=8, error_estimate=True, max_distance=1500, cell_size=30,
                                  nodata=NODATA)
    assert fixed.directions == 8 and fixed.error.shape == dem.shape and fixed.estimated_error > 0.3
    with pytest.raises(hfvis.InvalidArgumentError):
        hfvis.intervisibility(dem, max_error=0.3, method="naive", cell_size=30, nodata=NODATA)


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
    # (a pathlib.Path is a path too: it was refused as "not a path")
    equal(hfvis.environment_light(dem, sky, directions=8, cell_size=30, nodata=NODATA), ours)
    azimuth, elevation = hfvis.sun_position("2026-06-21T12:00:00Z", 46.6, 8.0)
    done = run_cli("sun-position", "--at", "2026-06-21T12:00:00Z", "--lat", "46.6", "--lon", "8.0", quiet=False)
    printed = dict(item.split("=") for item in done.stdout.split())
    assert abs(float(printed["azimuth"]) - azimuth) < 1e-4 and abs(float(printed["elevation"]) - elevation) < 1e-4


def test_environment_light_with_max_error(dem):
    """max_error=E chooses K as shade --env --max-error does: the values are the run at that K's,
    the estimate at most E; a DataArray carries the K and the estimate."""
    rows = np.arange(16)[:, None]
    azimuth = np.arange(32)[None, :] * 2 * np.pi / 32
    sky = np.where(rows < 8, 2.0 - rows / 8 + 0.5 * np.cos(azimuth), 0.2).astype(np.float32)  # no sun
    ours = hfvis.environment_light(dem, sky, max_error=0.05, max_distance=1500, cell_size=30, nodata=NODATA)
    assert isinstance(ours, hfvis.ErrorEstimate)
    assert ours.estimated_error <= 0.05 and ours.error.shape == dem.shape and ours.directions % 8 == 0
    equal(ours.values, hfvis.environment_light(dem, sky, directions=ours.directions, max_distance=1500, cell_size=30,
                                               nodata=NODATA))
    with pytest.raises(hfvis.InvalidArgumentError):
        hfvis.environment_light(dem, sky, max_error=1.5, cell_size=30, nodata=NODATA)


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


def _svf_in_a_child():
    """Run in a forked child: the error's type and message (a call hung there before)."""
    try:
        hfvis.sky_view_factor(np.zeros((8, 8), np.float32), directions=4)
        return "ran", ""
    except hfvis.Error as e:
        return type(e).__name__, str(e)


def test_a_child_forked_after_opencl_was_set_up_is_refused_not_hung():
    import multiprocessing
    if "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork start method on this platform")
    hfvis.devices()  # the parent has set OpenCL up
    with multiprocessing.get_context("fork").Pool(1) as pool:
        kind, message = pool.apply_async(_svf_in_a_child).get(timeout=120)
    assert kind == "NoDeviceError", (kind, message)
    assert "'spawn'" in message and "forked" in message
    # The parent goes on.
    assert np.isfinite(hfvis.sky_view_factor(np.zeros((8, 8), np.float32), directions=4)).all()


def test_sky_view_factor_and_ambient_occlusion_with_max_error(tmp_path, projected_tif, dem):
    """max_error=E chooses K as the CLI's --max-error does; error_estimate gives its --error-out."""
    import rasterio

    error_tif = tmp_path / "error.tif"
    (svf,), _ = cli(tmp_path, projected_tif, "sky-view-factor", "--max-error", "0.01", "--max-distance", "900",
                    "--error-out", error_tif)
    ours = hfvis.sky_view_factor(dem, max_error=0.01, error_estimate=True, max_distance=900, cell_size=30,
                                 nodata=NODATA)
    assert isinstance(ours, hfvis.ErrorEstimate)
    equal(ours.values, svf)
    (error,), _ = read_bands(error_tif)
    equal(ours.error, error)
    with rasterio.open(error_tif) as f:
        tags = f.tags()
    assert int(tags["hfvis_directions"]) == ours.directions and ours.directions > 16
    assert float(tags["hfvis_estimated_error"]) == float(f"{ours.estimated_error:.10g}") <= 0.01
    (ao,), _ = cli(tmp_path, projected_tif, "ambient-occlusion", "--max-error", "0.02", "--max-distance", "900")
    r = hfvis.ambient_occlusion(dem, max_error=0.02, max_distance=900, cell_size=30, nodata=NODATA)
    equal(r.values, ao)
    assert r.estimated_error <= 0.02 and r.error.shape == dem.shape
    # Without max_error, error_estimate keeps the K given (the values are the CLI's with --error-out,
    # whose run sums the even and odd directions apart: they may differ from a run without by an ulp).
    (svf,), _ = cli(tmp_path, projected_tif, "sky-view-factor", "-k", "8", "--max-distance", "600",
                    "--error-out", error_tif)
    fixed = hfvis.sky_view_factor(dem, directions=8, error_estimate=True, max_distance=600, cell_size=30,
                                  nodata=NODATA)
    assert fixed.directions == 8
    equal(fixed.values, svf)
    equal(fixed.error, read_bands(error_tif)[0][0])


def test_horizon_angles_with_max_error(tmp_path, projected_tif, dem):
    """max_error=E (radians) chooses K as the CLI's horizon --max-error (degrees) does; error_estimate
    gives its --error-out (degrees there, radians here)."""
    import rasterio

    error_tif = tmp_path / "error.tif"
    planes, _ = cli(tmp_path, projected_tif, "horizon", "--max-error", "0.5", "--max-distance", "900",
                    "--error-out", error_tif)
    ours = hfvis.horizon_angles(dem, max_error=np.radians(0.5), error_estimate=True, max_distance=900,
                                cell_size=30, nodata=NODATA)
    assert isinstance(ours, hfvis.HorizonEstimate)
    assert ours.values.shape == (ours.directions,) + dem.shape and len(ours.azimuths) == ours.directions
    equal(ours.values, planes)
    (error,), _ = read_bands(error_tif)
    np.testing.assert_allclose(np.degrees(ours.error), error, rtol=1e-5, atol=1e-7)
    with rasterio.open(error_tif) as f:
        tags = f.tags()
    assert int(tags["hfvis_directions"]) == ours.directions > 16
    assert ours.estimated_error <= np.radians(0.5)
    assert abs(float(tags["hfvis_estimated_error"]) - np.degrees(ours.estimated_error)) < 1e-6
    # Without max_error, error_estimate keeps the K given; fewer than 5 directions are refused.
    fixed = hfvis.horizon_angles(dem, directions=12, error_estimate=True, cell_size=30, nodata=NODATA)
    assert fixed.directions == 12 and fixed.estimated_error > 0
    with pytest.raises(hfvis.InvalidArgumentError):
        hfvis.horizon_angles(dem, directions=4, error_estimate=True, cell_size=30, nodata=NODATA)
    with pytest.raises(hfvis.InvalidArgumentError):
        hfvis.horizon_angles(dem, max_error=2.0, cell_size=30, nodata=NODATA)


def mask_channels(bits, samples):
    """The CLI's --masks channels (16 samples each, as whole numbers) from (words, H, W) bits."""
    channels = (samples + 15) // 16
    planes = [(bits[k // 2] >> (16 * (k % 2))) & 0xFFFF for k in range(channels)]
    return np.stack(planes).astype(np.float32)


def test_region_visibility(tmp_path, projected_tif, dem):
    masks_tif = tmp_path / "masks.tif"
    (fraction,), _ = cli(tmp_path, projected_tif, "arealight", "--light", "200,170,206,175", "--light-height",
                         "10", "--samples", "40", "--max-distance", "3000", "--masks", masks_tif)
    r = hfvis.region_visibility(dem, (200, 170, 206, 175), samples=40, height=10, max_distance=3000, cell_size=30,
                                nodata=NODATA)
    assert r.fraction.dtype == np.float32 and r.bits.dtype == np.uint32 and r.bits.shape == (2,) + dem.shape
    assert np.isnan(r.fraction[100, 150]) and 0 < np.nanmean(r.fraction) < 1
    equal(r.fraction, fraction)
    masks, names = read_bands(masks_tif)
    assert names == ["m000", "m001", "m002"]
    holes = np.isnan(r.fraction)
    ours = mask_channels(r.bits, 40)
    ours[:, holes] = np.nan
    equal(ours, masks)
    # The bits and the fraction agree: the popcount over S.
    counts = np.unpackbits(np.moveaxis(r.bits, 0, -1).copy().view(np.uint8), axis=-1).sum(axis=-1)
    np.testing.assert_array_equal((counts[~holes] / 40).astype(np.float32), r.fraction[~holes])
    # Points (a CSV of the CLI's --sources), exact and decorrelated jitter.
    sources = tmp_path / "sources.csv"
    sources.write_text("col,row,height\n10,20,5\n300.5,200.25,12\n150,160\n")
    (fraction,), _ = cli(tmp_path, projected_tif, "arealight", "--sources", sources, "--light-height", "3",
                         "--method", "exact", "--target-height", "1.5")
    points = np.array([[10, 20, 5], [300.5, 200.25, 12], [150, 160, 3]])
    r = hfvis.region_visibility(dem, points, method="exact", target_height=1.5, cell_size=30, nodata=NODATA)
    equal(r.fraction, fraction)
    (fraction,), _ = cli(tmp_path, projected_tif, "arealight", "--light", "20,30,60,40", "--decorrelate",
                         "--seed", "7", "--samples", "8", "--absolute", "--light-height", "900",
                         "--max-distance", "2000")
    r = hfvis.region_visibility(dem, (20, 30, 60, 40), decorrelate=True, seed=7, samples=8, absolute=True,
                                height=900, max_distance=2000, cell_size=30, nodata=NODATA)
    equal(r.fraction, fraction)
    assert r.rgb is None


def test_region_visibility_light_image(tmp_path, projected_tif, dem):
    import rasterio

    # A grey 3 x 2 image (a one-band GeoTIFF): R = G = B, each as arealight --light-image's.
    grey = np.array([[1, 2, 4], [0.5, 3, 0]], np.float32)
    light = tmp_path / "light.tif"
    with rasterio.open(light, "w", driver="GTiff", width=3, height=2, count=1, dtype="float32") as f:
        f.write(grey, 1)
    bands, names = cli(tmp_path, projected_tif, "arealight", "--light", "200,170,206,175", "--light-height", "10",
                       "--samples", "40", "--max-distance", "3000", "--light-image", light)
    r = hfvis.region_visibility(dem, (200, 170, 206, 175), samples=40, height=10, max_distance=3000, cell_size=30,
                                nodata=NODATA, light_image=grey)
    assert r.rgb.shape == (3,) + dem.shape and r.rgb.dtype == np.float32
    for c, name in enumerate("RGB"):
        equal(r.rgb[c], bands[names.index(name)])
    assert 0 < np.nanmean(r.rgb[0]) < np.nanmean(grey)
    # A white light: R = G = B = the fraction; an image of the wrong shape is refused.
    white = hfvis.region_visibility(dem, (200, 170, 206, 175), samples=40, height=10, max_distance=3000,
                                    cell_size=30, nodata=NODATA, light_image=np.ones((3, 4, 5)))
    for c in range(3):
        equal(white.rgb[c], white.fraction)
    with pytest.raises(hfvis.InputTypeError):
        hfvis.region_visibility(dem, (200, 170, 206, 175), cell_size=30, nodata=NODATA, light_image=np.ones((2, 4, 5)))
    for empty in (np.ones((0, 0)), np.ones((3, 0, 0))):  # (was run without its image, rgb None)
        with pytest.raises(hfvis.InputTypeError, match="non-empty"):
            hfvis.region_visibility(dem, (200, 170, 206, 175), cell_size=30, nodata=NODATA, light_image=empty)


def test_region_pair_visibility(tmp_path, projected_tif, dem):
    import json

    out, rays = tmp_path / "pair.json", tmp_path / "rays.csv"
    run_cli("region", projected_tif, "--from", "200,170,210,180", "--to", "215,170,225,180", "-o", out, "--rays", rays,
            "--samples", "24", "--from-height", "10", "--to-height", "3")
    printed = json.loads(out.read_text())
    r = hfvis.region_pair_visibility(dem, (200, 170, 210, 180), (215, 170, 225, 180), samples=24, source_height=10,
                                     receiver_height=3, cell_size=30, nodata=NODATA)
    assert (r.pairs, r.clear_pairs) == (printed["pairs"], printed["clear_pairs"]) and 0 < r.clear_pairs < r.pairs
    assert r.visible_fraction == printed["visible_fraction"]
    assert r.bits.shape == (24, 1) and r.sources.shape == (24, 3) and r.sources_xy is None

    def text(value):  # the CLI's numbers: 10 significant digits
        return f"{value:.10g}"

    for samples, fractions, key in ((r.sources, r.source_fraction, "from_samples"),
                                    (r.receivers, r.receiver_fraction, "to_samples")):
        assert [[text(p["col"]), text(p["row"]), text(p["height"]), text(p["visible_fraction"])]
                for p in printed[key]] == [[text(v) for v in (*p, f)] for p, f in zip(samples, fractions)]
    clear = {",".join(line.split(",")[:6]) for line in rays.read_text().splitlines()[1:]}  # pixels, not map x, y
    ours = {",".join(text(v) for v in (*r.sources[s], *r.receivers[t]))
            for t in range(24) for s in range(24) if (r.bits[t, s // 32] >> (s % 32)) & 1}
    assert ours == clear


def test_pvs(tmp_path, projected_tif, dem):
    import json

    out, bitset = tmp_path / "pvs.json", tmp_path / "pvs.bin"
    run_cli("pvs", projected_tif, "-o", out, "--bitset", bitset, "--samples", "30000", "--view-cell", "48",
            "--tile", "32", "--view-height", "2,20", "--seed", "5")
    printed = json.loads(out.read_text())
    calls = []
    r = hfvis.pvs(dem, samples=30000, view_cell=48, tile=32, band_low=2, band_high=20, seed=5, cell_size=30,
                  nodata=NODATA, progress=lambda samples, error: calls.append(samples))
    assert r.samples == printed["samples"] and r.rays == printed["rays"] and r.entries == printed["entries"]
    assert r.discontinuities == printed["discontinuities"]
    assert r.layout["view_x"] == printed["view_cells"]["across"] and r.layout["tiles_y"] == printed["tiles"]["down"]
    assert [None if s is None else s.tolist() for s in r.sets] == printed["pvs"]
    assert r.entries > 0 and calls and calls[-1] == r.samples
    words = np.frombuffer(bitset.read_bytes(), "<u4")
    np.testing.assert_array_equal(words[-r.bits.size:], r.bits.ravel())
    # Resumed from those sets with another seed: every entry stays, more are found; another grid's
    # bits are refused.
    more = hfvis.pvs(dem, samples=10000, view_cell=48, tile=32, band_low=2, band_high=20, seed=6, cell_size=30,
                     nodata=NODATA, start=r.bits)
    assert np.all(r.bits & ~more.bits == 0) and more.entries > r.entries
    # The view-space filter only adds, its entries counted in filtered; 9 neighbours are refused.
    merged = hfvis.pvs(dem, samples=30000, view_cell=48, tile=32, band_low=2, band_high=20, seed=5, cell_size=30,
                       nodata=NODATA, view_filter=8)
    assert np.all(r.bits & ~merged.bits == 0) and merged.entries == r.entries + merged.filtered > r.entries
    with pytest.raises(hfvis.InvalidArgumentError, match="view_filter"):
        hfvis.pvs(dem, samples=100, cell_size=30, nodata=NODATA, view_filter=9)
    # The Earth's curvature, as the CLI's --curvature gives it (its JSON's drop coefficient).
    run_cli("pvs", projected_tif, "-o", out, "--samples", "30000", "--view-cell", "48", "--tile", "32",
            "--view-height", "2,20", "--seed", "5", "--curvature")
    curved_cli = json.loads(out.read_text())
    assert 6e-8 < curved_cli["curvature"] < 7e-8 and printed["curvature"] == 0
    curved = hfvis.pvs(dem, samples=30000, view_cell=48, tile=32, band_low=2, band_high=20, seed=5, cell_size=30,
                       nodata=NODATA, curvature=curved_cli["curvature"])
    assert [None if s is None else s.tolist() for s in curved.sets] == curved_cli["pvs"]
    with pytest.raises(hfvis.InvalidArgumentError, match="curvature"):
        hfvis.pvs(dem, samples=100, cell_size=30, nodata=NODATA, curvature=2.0)
    # A maximum distance (ground units), as the CLI's --max-distance: fewer entries.
    run_cli("pvs", projected_tif, "-o", out, "--samples", "30000", "--view-cell", "48", "--tile", "32",
            "--view-height", "2,20", "--seed", "5", "--max-distance", "1500")
    near_cli = json.loads(out.read_text())
    near = hfvis.pvs(dem, samples=30000, view_cell=48, tile=32, band_low=2, band_high=20, seed=5, cell_size=30,
                     nodata=NODATA, max_distance=1500)
    assert near_cli["max_distance"] == 1500 and near.entries == near_cli["entries"] < r.entries
    assert [None if s is None else s.tolist() for s in near.sets] == near_cli["pvs"]
    # The settled estimate: its samples counted apart, as the CLI's JSON; 0 turns it off.
    assert r.estimate_samples == printed["estimate_samples"]
    assert [row["settling"] for row in r.history] == [row["settling"] for row in printed["progress"]]
    kw = dict(view_cell=48, tile=32, band_low=2, band_high=20, seed=5, cell_size=30, nodata=NODATA)
    for n in (60000, 120000, 240000, 480000):  # the first budget that leaves something to settle
        settled = hfvis.pvs(dem, samples=n, **kw)
        if settled.estimate_samples:
            break
    assert 0 < settled.estimate_samples <= n and settled.samples == n + settled.estimate_samples
    assert settled.history[-1]["settling"] and not settled.history[0]["settling"]
    plain = hfvis.pvs(dem, samples=n, estimate_entries=0, **kw)
    assert plain.estimate_samples == 0 and plain.samples == n
    assert np.all(plain.bits & ~settled.bits == 0)
    for bad in (-1, 2.5, 10**7):
        with pytest.raises(hfvis.InvalidArgumentError, match="estimate_entries"):
            hfvis.pvs(dem, samples=100, cell_size=30, nodata=NODATA, estimate_entries=bad)
    with pytest.raises(hfvis.InvalidArgumentError, match="where this field and grid have 42 view cells"):
        hfvis.pvs(dem, samples=100, view_cell=64, tile=32, cell_size=30, nodata=NODATA, start=r.bits)
    # A mask per pixel, as the CLI's --view-mask: only the view cells it touches are computed.
    mask = np.zeros(dem.shape, np.float32)
    mask[10, 10] = mask[300, 390] = 1
    r = hfvis.pvs(dem, samples=5000, view_cell=48, tile=32, mask=mask, witnesses=True, cell_size=30, nodata=NODATA)
    assert r.computed.sum() == 2 and r.sets[0] is not None and r.sets[1] is None
    # One witness per sampled entry, in the view cell and tile it stands for (eyes in pixels).
    w = r.witnesses
    assert len(w["view_cell"]) == r.entries - r.filtered > 0 and w["eye"].shape == (len(w["tile"]), 3)
    for v, t, eye in zip(w["view_cell"], w["tile"], w["eye"]):
        assert t in r.sets[v] and (int(eye[0]) // 48, int(eye[1]) // 48) == (v % r.layout["view_x"],
                                                                            v // r.layout["view_x"])


def test_horizon_lists(tmp_path, projected_tif, dem):
    import json

    out = tmp_path / "lists.json"
    run_cli("horizon-lists", projected_tif, "--at", "200,170", "--at", "150,100", "--at", "0,0", "-k", "8",
            "--samples-per-unit", "2", "-o", out)
    printed = json.loads(out.read_text())["receivers"]
    ours = hfvis.horizon_lists(dem, [(200, 170), (150, 100), (0, 0)], directions=8, samples_per_unit=2,
                               cell_size=30, nodata=NODATA)
    assert ours[1]["nodata"] and ours[2]["nodata"] and not ours[0]["nodata"]
    for receiver in ours + printed:  # heights: float32, the JSON's shortest text of it (NaN: null)
        receiver["height"] = None if receiver["height"] is None or np.isnan(receiver["height"]) else \
            np.float32(receiver["height"])
    assert ours == printed
    assert sum(len(d["horizons"]) for d in ours[0]["directions"]) > 8


def test_bounce(tmp_path, projected_tif, dem):
    import rasterio

    heights = np.where(dem == NODATA, np.nan, dem)
    radiance = np.stack([np.nan_to_num((heights - np.nanmin(heights)) / 100.0), np.full(dem.shape, 0.5)])
    radiance = radiance.astype(np.float32)
    with rasterio.open(projected_tif) as f:
        profile = dict(f.profile, count=2, nodata=None)
    with rasterio.open(tmp_path / "radiance.tif", "w", **profile) as f:
        f.write(radiance)
    irradiance, _ = cli(tmp_path, projected_tif, "bounce", "--radiance", tmp_path / "radiance.tif", "-k", "8")
    ours = hfvis.bounce(dem, radiance, directions=8, cell_size=30, nodata=NODATA)
    assert ours.shape == (2,) + dem.shape and np.isnan(ours[0, 100, 150])
    equal(ours, irradiance)
    equal(hfvis.bounce(dem, radiance[1], directions=8, cell_size=30, nodata=NODATA), irradiance[1])


def test_ambient_occlusion_and_sky_view_factor_stay_within_0_and_1():
    """Shares of the sky: the azimuthal quadrature passed 1 by its error on steep noise (1.006 at
    K = 16), and the integral lies inside."""
    steep = (np.random.default_rng(21).standard_normal((64, 64)) * 100).astype(np.float32)
    for k in (8, 16):
        ao = hfvis.ambient_occlusion(steep, directions=k)
        svf = hfvis.sky_view_factor(steep, directions=k)
        assert 0.0 <= ao.min() and ao.max() <= 1.0
        assert 0.0 <= svf.min() and svf.max() <= 1.0
        if k == 16:
            assert ao.max() == 1.0  # (clamped there: without the clamp 7 pixels pass it)
