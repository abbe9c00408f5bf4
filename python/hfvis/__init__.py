"""hfvis: visibility on height fields with OpenCL, for numpy arrays and xarray DataArrays.

Every operation takes a 2-D numpy array (cell sizes as cell_size, nodata as NaN or nodata=) or an
xarray DataArray (cell sizes, CRS and nodata from its coordinates or rioxarray; Dask-backed ones
run chunk by chunk with a halo of max_distance). One OpenCL context per process and device is
made on first use and kept; the GIL is released while the kernels run. docs/python.md has the API.
"""

from . import _core
from ._errors import (DeviceError, Error, InputTypeError, InvalidArgumentError, IoError, MemoryBudgetError,
                      NoDeviceError)
from ._operations import (HeightFieldFile, Horizons, Insolation, Intervisibility, SunShading, ambient_occlusion, cumulative_viewshed,
                          devices, environment_light, horizon_angles, horizon_distances, insolation, intervisibility,
                          read_height_field, sky_view_factor, sun_position, sun_shading, viewshed)

__version__ = _core.__version__

__all__ = [
    "Error", "InvalidArgumentError", "InputTypeError", "IoError", "NoDeviceError", "DeviceError", "MemoryBudgetError",
    "HeightFieldFile", "Horizons", "Intervisibility", "SunShading", "Insolation",
    "horizon_angles", "horizon_distances", "sky_view_factor", "ambient_occlusion", "intervisibility", "viewshed",
    "cumulative_viewshed", "sun_shading", "insolation", "environment_light", "sun_position", "devices", "read_height_field",
]
