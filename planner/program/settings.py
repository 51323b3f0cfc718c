"""The procedure settings a program computes with: the plan's, with an unset edge-event offset
filled in once, for every face alike.

An edge search's sensor switches off some millimetres past the real edge (the edge-event offset,
about 6 mm for the default 18 mm sensor at a 3 mm inset); the procedure removes it from the edge
points. A plan that leaves ``edge_event_offset_m`` unset gets the sensor model's analytic value
for a straight edge (what a cell measures once on a reference edge): the exported programs (the
RAPID A-H module's ``nEdgeEvent``), ``wobjcal calibrate``, check and the validation all use the
value :func:`resolved_settings` gives, so no face computes the frame with another offset than
the program the robot runs. Measure it on the real sensor and put it in the plan.
"""

from __future__ import annotations

from typing import Any

import msgspec

#: Edge searches run this far inside the face along the sensor axis by default, m.
DEFAULT_EDGE_INSET_M = 0.003


def resolved_settings(
    settings: Any, sensor: Any, edge_inset_m: float = DEFAULT_EDGE_INSET_M
) -> Any:
    """``settings`` with an unset edge-event offset replaced by the sensor's analytic
    straight-edge offset at ``edge_inset_m`` (see
    :meth:`calib.models.ProximitySensor.edge_event_offset_m`; 0 for a sensor without edge
    searches).

    Args:
        settings: a procedure's settings struct (its ``edge_event_offset_m`` unset or not).
        sensor: the plan's sensor model (``plan.validation.sensor``).
        edge_inset_m: how far inside the face an edge search runs, m.
    """
    if getattr(settings, "edge_event_offset_m", 0.0) is not None:
        return settings
    offset = sensor.edge_event_offset_m(edge_inset_m) if sensor.runs_edge_searches else 0.0
    return msgspec.structs.replace(settings, edge_event_offset_m=offset)
