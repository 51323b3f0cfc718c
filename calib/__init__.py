"""wobjcal calibration core: pure numpy/scipy, no simulator, no UI.

Frames and conventions are documented once, in :mod:`calib.frames`. Importing ``calib`` never
imports PyBullet, viser or ``planner``.
"""

from calib._version import __version__
from calib.errors import (
    DegenerateGeometryError,
    InputError,
    NonFiniteError,
    ProbeFailedError,
    ShapeError,
    UnobservableError,
    WobjcalError,
)

__all__ = [
    "DegenerateGeometryError",
    "InputError",
    "NonFiniteError",
    "ProbeFailedError",
    "ShapeError",
    "UnobservableError",
    "WobjcalError",
    "__version__",
]
