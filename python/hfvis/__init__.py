"""hfvis: visibility on height fields with OpenCL, for numpy arrays and xarray DataArrays.

Every operation takes a 2-D numpy array (cell sizes as cell_size, nodata as NaN or nodata=) or an
xarray DataArray (cell sizes, CRS and nodata from its coordinates or rioxarray; Dask-backed ones
run chunk by chunk with a halo of max_distance). One OpenCL context per process and device is
made on first use and kept; the GIL is released while the kernels run. docs/python.md has the API.
"""

from . import _core
from ._errors import (DeviceError, Error, InputTypeError, InvalidArgumentError, IoError, MemoryBudgetError,
                      NoDeviceError)
from ._operations import (ErrorEstimate, HeightFieldFile, HorizonEstimate, Horizons, Insolation, Intervisibility,
                          IntervisibilityEstimate, Pvs,
                          RegionPairVisibility, RegionVisibility, SunShading, ambient_occlusion, bounce,
                          cumulative_viewshed, devices, environment_light, horizon_angles, horizon_distances,
                          horizon_lists, insolation, intervisibility, pvs, read_height_field, region_pair_visibility,
                          region_visibility, sky_view_factor, sun_position, sun_shading, viewshed)

__version__ = _core.__version__

__all__ = [
    "Error", "InvalidArgumentError", "InputTypeError", "IoError", "NoDeviceError", "DeviceError", "MemoryBudgetError",
    "HeightFieldFile", "Horizons", "HorizonEstimate", "Intervisibility", "IntervisibilityEstimate", "SunShading", "Insolation", "ErrorEstimate", "RegionVisibility",
    "RegionPairVisibility", "Pvs",
    "horizon_angles", "horizon_distances", "sky_view_factor", "ambient_occlusion", "intervisibility", "viewshed",
    "cumulative_viewshed", "sun_shading", "insolation", "environment_light", "region_visibility",
    "region_pair_visibility", "pvs", "horizon_lists", "bounce", "sun_position", "devices", "read_height_field",
]
