"""What every sensor model provides to code that does not simulate it: :class:`SensorModel`.

The planar-face check needs the footprint that must lie on one face; the exporters and the
search checks need how far in front of the sensor the TCP sits when it triggers; the predicted
accuracy (:mod:`calib.estimators.propagation`) needs how much a search's event moves with the
sensor's own noise and with a robot offset along the sensor axis (:class:`SearchNoise`). Each
sensor kind (the proximity sensor, the touch probe) is one struct in :mod:`calib.models` that
satisfies this protocol, plus one entry in the simulation's sensor registry
(:data:`planner.sim.sensors.SENSORS`). In a plan the kinds form the tagged union
:data:`calib.models.SensorSettings` (tag field ``kind``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Protocol

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class SearchNoise:
    """How one search's event moves along the search direction, to first order.

    The event travel ``t`` of a search changes by ``dt = sensor_sigma_m * z + axis_gain *
    (o . a) - o . m / (d . m)`` for a standard normal ``z`` (the sensor's own noise), a robot
    offset ``o`` of the TCP, the sensor axis ``a``, the search direction ``d`` and the normal
    ``m`` of the face that stops the search.

    Attributes:
        sensor_sigma_m: 1-sigma of the event travel from the sensor alone, metres.
        axis_gain: metres of event travel per metre the TCP runs closer along the sensor axis
            (0 for an approach: the axis is the search direction, already in the last term;
            about 1.2 for the default proximity sensor's edge search).
    """

    sensor_sigma_m: float
    axis_gain: float = 0.0


def face_frame(axis: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Two unit vectors ``(u, v)`` spanning the sensor face, perpendicular to ``axis`` ``(3,)``.

    The convention of every sensor model: ``u = axis x e_x`` (``axis x e_y`` when the axis is
    close to ``e_x``) normalised, ``v = axis x u``. ``(u, v, axis)`` is the sensor's tool frame
    the simulation uses for a TCP calibration error.
    """
    ax, ay, az = (float(c) for c in np.asarray(axis, dtype=np.float64).tolist())
    # u = axis x helper, helper = e_x unless the axis is close to it (then e_y); its length
    # by numpy's dot (a plain sum can differ in the last bit, and a ray on a triangle's edge
    # with it), the rest in floats
    u = np.array([0.0, az, -ay]) if abs(ax) < 0.9 else np.array([-az, 0.0, ax])
    u /= math.sqrt(float(u @ u))
    u0, u1, u2 = u.tolist()
    v = np.array([ay * u2 - az * u1, az * u0 - ax * u2, ax * u1 - ay * u0])
    return u, v


def tool_rotation(axis: FloatArray) -> FloatArray:
    """``(3, 3)`` the sensor's tool frame ``[u, v, axis]`` (columns) for a sensor axis ``(3,)``."""
    a = np.asarray(axis, dtype=np.float64)
    u, v = face_frame(a)
    return np.column_stack([u, v, a])


class SensorModel(Protocol):
    """A sensor as the planner sees it.

    Attributes:
        KIND: the sensor kind's name in the registry and the plan's tag, e.g. ``"proximity"``.
    """

    KIND: ClassVar[str]

    @property
    def footprint_radius_m(self) -> float:
        """Radius of the area that must lie on one planar face at the probe point, m."""
        ...

    @property
    def standoff_m(self) -> float:
        """Distance from the sensor face to the TCP when the sensor triggers, m."""
        ...

    @property
    def runs_edge_searches(self) -> bool:
        """True when the sensor can find the end of a face while sliding over it."""
        ...

    def edge_event_offset_m(self, inset_m: float) -> float:
        """How far past a straight edge an edge search reports it, m (0 without edge searches)."""
        ...

    def search_noise(self, kind: str, edge_inset_m: float) -> SearchNoise:
        """The first-order noise of one search of ``kind`` (``"approach"`` or ``"edge"``)."""
        ...
