"""The physical things a calibration plan is validated against, each defined once.

Owns (pure numpy, ``msgspec`` structs that the plan file holds under ``validation``):
    - :class:`~calib.models.proximity.ProximitySensor`: the inductive sensor (face, sensing
      distance, damping, hysteresis, jitter) and its response to face-to-metal distances;
    - :class:`~calib.models.robot_error.RobotErrorModel` and
      :class:`~calib.models.robot_error.AccuracyField`: repeatability and absolute accuracy;
    - :class:`~calib.models.misplacement.Misplacement`: how far the part may lie from nominal.

The plan (:mod:`calib.plan`), the simulation (:mod:`planner.sim`), the planar-face footprint
check (:mod:`planner.faces`) and the exporters (:mod:`planner.export`) all use these same
objects; none keeps a copy of their fields.
"""

from calib.models.misplacement import Misplacement
from calib.models.proximity import ProximitySensor, sunflower_disk
from calib.models.robot_error import AccuracyField, RobotErrorModel

__all__ = [
    "AccuracyField",
    "Misplacement",
    "ProximitySensor",
    "RobotErrorModel",
    "sunflower_disk",
]
