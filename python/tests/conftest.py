"""Shared fixtures: the bundled Jacksboro DEM written as GeoTIFFs (projected and latitude /
longitude, with nodata holes) and the CLI (build/hfvis, built by scripts/build.sh) to compare with."""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import hfvis

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "hfvis"
NODATA = -9999.0
# data/jacksboro_fault_dem.txt: 3 arc-second cells, row 0 north, west edge and north edge.
JACKSBORO_WEST, JACKSBORO_NORTH, JACKSBORO_STEP = -84.41375, 36.732917, 0.0008333333333333334


def run_cli(*args, quiet=True):
    """Runs build/hfvis; a failure shows its message."""
    if not CLI.exists():
        pytest.fail(f"{CLI} is missing: build the C++ side first (bash scripts/build.sh)")
    done = subprocess.run([str(CLI), *map(str, args), *(["-q"] if quiet else [])], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def read_bands(path):
    """Every band of a GeoTIFF as float32 (nodata NaN, as the CLI writes it) and their names."""
    import rasterio

    with rasterio.open(path) as f:
        return f.read().astype(np.float32), list(f.descriptions)


@pytest.fixture(scope="session")
def jacksboro():
    """The bundled DEM (344 x 403) with a few nodata holes, read through the library."""
    heights = hfvis.read_height_field(ROOT / "data" / "jacksboro_fault_dem.exr").heights.copy()
    heights[100:104, 150:160] = np.nan
    heights[0, 0:5] = np.nan
    return heights


def write_geotiff(path, heights, crs, transform):
    import rasterio

    with rasterio.open(path, "w", driver="GTiff", width=heights.shape[1], height=heights.shape[0], count=1,
                       dtype="float32", crs=crs, transform=transform, nodata=NODATA) as f:
        f.write(np.where(np.isnan(heights), np.float32(NODATA), heights), 1)
    return path


@pytest.fixture(scope="session")
def projected_tif(tmp_path_factory, jacksboro):
    """The DEM as a UTM GeoTIFF of 30 m cells, nodata -9999."""
    from affine import Affine

    return write_geotiff(tmp_path_factory.mktemp("tif") / "projected.tif", jacksboro, "EPSG:32616",
                         Affine(30.0, 0.0, 700000.0, 0.0, -30.0, 4070000.0))


@pytest.fixture(scope="session")
def geographic_tif(tmp_path_factory, jacksboro):
    """The DEM in its own latitude / longitude grid (EPSG:4326)."""
    from affine import Affine

    step = JACKSBORO_STEP
    return write_geotiff(tmp_path_factory.mktemp("tif") / "geographic.tif", jacksboro, "EPSG:4326",
                         Affine(step, 0.0, JACKSBORO_WEST, 0.0, -step, JACKSBORO_NORTH))


@pytest.fixture(autouse=True, scope="session")
def pocl_cache():
    os.environ.setdefault("POCL_CACHE_DIR", str(ROOT / "bench" / "out" / "pocl-cache"))
