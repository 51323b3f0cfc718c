"""Where a tool's sensor face lies behind its sensor TCP: the gap the TCP calibration must match.

The sensor TCP is where the sensor switches: its sensing distance in front of the face for a
proximity sensor, as the TCP calibration on the controller makes it. A plan whose sensor says
another distance than the tool's geometry (the built-in cable feeder's TCP lies 8 mm in front of
its sensor's face) describes a program whose measured points are off by the difference along
every normal, unless the controller's TCP is calibrated anew. :func:`sensor_face_gap_m` measures
the tool's gap: a ray from the sensor TCP back along its axis (``-z``) to the first surface of
the tool's body, in a PyBullet client of its own.
"""

from __future__ import annotations

import numpy as np

from planner.cell.scene.pybullet_client import connect_direct, pb
from planner.cell.scene.tool import Tool

#: How far behind the TCP the face is looked for, m.
MAX_GAP_M = 0.2


_GAPS: dict[tuple[bytes, bytes], float | None] = {}


def sensor_face_gap_m(tool: Tool) -> float | None:
    """The distance from ``tool``'s sensor TCP back to the tool's body along the TCP's axis,
    m (the TCP frame's ``-z``); ``None`` when the tool has no sensor TCP or nothing of it lies
    within :data:`MAX_GAP_M` behind the TCP. Cached by the tool's geometry and TCP."""
    if tool.sensor_tcp is None:
        return None
    T = tool.T_flange_tcp(tool.sensor_tcp)
    key = (tool.fingerprint(), np.ascontiguousarray(T).tobytes())
    if key not in _GAPS:
        _GAPS[key] = _cast(tool, T)
    return _GAPS[key]


def _cast(tool: Tool, T: np.ndarray) -> float | None:
    start = T[:3, 3]
    end = start - MAX_GAP_M * T[:3, 2]
    client = connect_direct()
    try:
        tool.create_body(client)
        hit = pb.rayTest(start.tolist(), end.tolist(), physicsClientId=client)[0]
    finally:
        pb.disconnect(physicsClientId=client)
    return None if hit[0] < 0 else float(hit[2]) * MAX_GAP_M


def gap_mismatch(tool: Tool, standoff_m: float, tol_m: float = 0.5e-3) -> str:
    """``""`` when ``tool``'s sensor TCP lies ``standoff_m`` (the plan's sensor's sensing
    distance, m) in front of its sensor's face within ``tol_m``, else one line saying by how
    much it does not and what that does to the measured points."""
    gap = sensor_face_gap_m(tool)
    if gap is None or abs(gap - standoff_m) <= tol_m:
        return ""
    return (
        f"the tool's sensor TCP lies {gap * 1e3:.1f} mm in front of its sensor face, but the "
        f"sensor switches {standoff_m * 1e3:.1f} mm in front of it: every measured point is "
        f"{abs(gap - standoff_m) * 1e3:.1f} mm off along its normal unless the controller's TCP "
        "is calibrated at the switching point (then give the tool that TCP)"
    )
