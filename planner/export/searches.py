"""The searches an exported program runs for one point, from its safe start.

Every exporter moves to a point's safe start (:mod:`planner.export.safety`) and searches from
there, which is not the plan's search start when the safe clearance is the larger:

- an **approach** point: one search from the safe start ``face + max(clearance, start offset) *
  normal`` along ``-normal`` to the plan's search end (``SearchL`` to ``_end``);
- an **edge** point: an approach to the face the edge search runs along, from ``edge start +
  clearance * normal`` down to ``overtravel`` past the nominal face (``_face``), then the edge
  search from the (measured) face point along the plan's direction.

:func:`program_searches` gives these as :class:`calib.probing.SearchCommand` (base frame), which
``wobjcal check`` walks with the probe pose's orientation and branch, so the motion it checks is
the one the program runs; :func:`safe_and_face_wobj` gives the two targets for
:func:`planner.export.job.build_job`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.frames import transform_directions, transform_points
from calib.probing import ProbePoint, SearchCommand
from planner.export.safety import SafetySpec

FloatArray = NDArray[np.float64]


def safe_and_face_wobj(point: ProbePoint, safety: SafetySpec) -> tuple[FloatArray, FloatArray]:
    """``(safe start, face end)`` of ``point``'s program, sensor TCP positions, wobj frame, m.

    The face end is where the approach to the face stops at the latest: the plan's search end
    for an approach point, ``overtravel`` past the nominal face for an edge point.
    """
    cmd = SearchCommand.from_point(point, np.eye(4))
    n = np.asarray(point.normal, dtype=float)
    # the face point the first approach search looks for: the point, or the edge start
    face = np.asarray(point.position_m, float) if point.search.kind == "approach" else cmd.start_m
    clear = safety.start_clearance_m(face)
    if point.search.kind == "approach":
        safe = face + max(clear, point.search.start_offset_m) * n
        face_end = cmd.start_m + cmd.length_m * cmd.direction
    else:
        safe = face + clear * n
        face_end = face - safety.overtravel_m(face) * n
    return safe, face_end


def program_searches(
    point: ProbePoint, T_base_wobj: ArrayLike, safety: SafetySpec
) -> tuple[SearchCommand, ...]:
    """The searches the program runs for ``point`` (module docstring), base frame.

    Args:
        point: the point (a plan's: ``PlanPoint.to_probe_point()``).
        T_base_wobj: ``(4, 4)`` the (nominal) work object in the robot base frame.
        safety: the misplacement tolerance the safe starts are computed for.

    Returns:
        One command (approach point) or two (edge point: the face approach, then the edge
        search); each starts where the program starts it.
    """
    T = np.asarray(T_base_wobj, dtype=np.float64)
    cmd = SearchCommand.from_point(point, T)
    safe_w, face_end_w = safe_and_face_wobj(point, safety)
    safe = transform_points(T, safe_w)
    if point.search.kind == "approach":
        end = cmd.start_m + cmd.length_m * cmd.direction
        return (replace(cmd, start_m=safe, length_m=float(np.linalg.norm(end - safe))),)
    n = transform_directions(T, np.asarray(point.normal, dtype=float))
    face = cmd.start_m  # the edge search's start: on the face
    approach = SearchCommand(
        point_id=point.id,
        kind="approach",
        start_m=safe,
        direction=-n,
        length_m=float(np.linalg.norm(transform_points(T, face_end_w) - safe)),
        sensor_axis=cmd.sensor_axis,
        T_base_wobj_estimate=T.copy(),
        nominal_m=face.copy(),
        stop_normal=n,
    )
    return approach, cmd
