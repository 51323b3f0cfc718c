"""What every sensor model provides to code that does not simulate it: :class:`SensorModel`.

The planar-face check needs the footprint that must lie on one face; the exporters and the
search checks need how far in front of the sensor the TCP sits when it triggers. Each sensor
kind (the proximity sensor now; a touch probe can follow) is one struct in :mod:`calib.models`
that satisfies this protocol, plus one entry in the simulation's sensor registry
(:data:`planner.sim.sensors.SENSORS`).
"""

from __future__ import annotations

from typing import ClassVar, Protocol


class SensorModel(Protocol):
    """A sensor as the planner sees it.

    Attributes:
        KIND: the sensor kind's name in the registry, e.g. ``"proximity"``.
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
