"""The physical things a calibration plan is validated against, each defined once.

Owns (pure numpy, ``msgspec`` structs that the plan file holds under ``validation``):
    - :class:`~calib.models.proximity.ProximitySensor`: the inductive sensor (face, sensing
      distance, damping, hysteresis, jitter) and its response to face-to-metal distances;
    - :class:`~calib.models.robot_error.RobotErrorModel` and
      :class:`~calib.models.robot_error.AccuracyField`: repeatability and absolute accuracy;
    - :class:`~calib.models.touch.TouchProbe`: the ball-tipped touch-trigger probe (radius
      compensation, pre-travel and its lobing, trigger scatter);
    - :class:`~calib.models.misplacement.Misplacement`: how far the part may lie from nominal;
    - :mod:`calib.models.sensor`: the :class:`~calib.models.sensor.SensorModel` protocol every
      sensor kind satisfies, and :data:`SensorSettings`, the plan's tagged union of them (tag
      field ``kind``).

The plan (:mod:`calib.plan`), the simulation (:mod:`planner.sim`), the planar-face footprint
check (:mod:`planner.faces`) and the exporters (:mod:`planner.export`) all use these same
objects; none keeps a copy of their fields.
"""

from calib.models.misplacement import Misplacement
from calib.models.proximity import ProximitySensor, sunflower_disk
from calib.models.robot_error import AccuracyField, RobotErrorModel
from calib.models.sensor import SearchNoise, SensorModel
from calib.models.touch import TouchProbe

#: The plan's ``validation.sensor``: one struct per sensor kind, tagged by ``kind``.
SensorSettings = ProximitySensor | TouchProbe
#: The sensor kinds' tags, in the order the UI offers them.
SENSOR_KINDS: tuple[str, ...] = (ProximitySensor.KIND, TouchProbe.KIND)

__all__ = [
    "SENSOR_KINDS",
    "AccuracyField",
    "Misplacement",
    "ProximitySensor",
    "RobotErrorModel",
    "SearchNoise",
    "SensorModel",
    "SensorSettings",
    "TouchProbe",
    "sunflower_disk",
]
