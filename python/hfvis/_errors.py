"""hfvis's exceptions: a hfvis.Error base, each also a subclass of the built-in exception a Python
caller expects (ValueError for a bad argument, TypeError for a wrong type, OSError for files).
hfvis._core raises the library's errors as these."""


class Error(Exception):
    """Base of every error hfvis raises."""


class InvalidArgumentError(Error, ValueError):
    """An argument or option out of its valid range: a negative cell size, K = 0, an observer
    outside the field, a Dask array without a maximum distance, ..."""


class InputTypeError(Error, TypeError):
    """An input of the wrong type or shape: not 2-D, a dtype that holds no heights."""


class IoError(Error, OSError):
    """A file that could not be read."""


class NoDeviceError(Error, RuntimeError):
    """No OpenCL platform, or no device matches the device choice."""


class DeviceError(Error, RuntimeError):
    """An OpenCL call or a kernel build failed."""


class MemoryBudgetError(Error, MemoryError):
    """The request does not fit the memory budget even one direction at a time."""
