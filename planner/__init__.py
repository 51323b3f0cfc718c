"""wobjcal planner: the kinematic cell (PyBullet DIRECT), kinematics, meshes, sensor simulation,
feasibility of probe poses and search paths, exporters and the command line."""

from calib._version import __version__

__all__ = ["__version__"]
