"""The searches an exported program runs for one point, from its safe start.

Every exporter moves to a point's safe start (:mod:`planner.program.safety`) and searches from
there, which is not the plan's search start when the safe clearance is the larger:

- an **approach** point: one search from the safe start ``face + max(clearance, start offset) *
  normal`` along ``-normal`` to the plan's search end (``SearchL`` to ``_end``);
- an **edge** point: an approach to the face the edge search runs along, from ``edge start +
  clearance * normal`` down to ``overtravel`` past the nominal face (``_face``), then the edge
  search from the (measured) face point along the plan's direction, then a straight retreat
  from where it stopped back to the safe start.

:func:`program_searches` gives these as :class:`calib.probing.SearchCommand` (base frame), which
``wobjcal check`` walks with the probe pose's orientation and branch, so the motion it checks is
the one the program runs; :func:`safe_and_face_wobj` gives the two targets for
:func:`planner.export.job.build_job`.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError
from calib.frames import transform_directions, transform_points
from calib.probing import ProbePoint, SearchCommand
from planner.program.safety import SafetySpec

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
    clear = safety.start_clearance_m(face, point.id)
    if point.search.kind == "approach":
        safe = face + max(clear, point.search.start_offset_m) * n
        face_end = cmd.start_m + cmd.length_m * cmd.direction
    else:
        safe = face + clear * n
        face_end = face - safety.overtravel_m(face, point.id) * n
    return safe, face_end


class ProgramSearch(NamedTuple):
    """One search of a program: what a message calls it, and the command (base frame)."""

    name: str
    command: SearchCommand


def program_searches(
    point: ProbePoint,
    T_base_wobj: ArrayLike,
    safety: SafetySpec,
    measured_start_wobj: ArrayLike | None = None,
) -> tuple[ProgramSearch, ...]:
    """The searches the program runs for ``point`` (module docstring), base frame.

    Args:
        point: the point (a plan's: ``PlanPoint.to_probe_point()``).
        T_base_wobj: ``(4, 4)`` the (nominal) work object in the robot base frame.
        safety: the misplacement tolerance the safe starts are computed for.
        measured_start_wobj: for an edge point, where the adaptive RAPID program starts the
            edge search instead of approaching the face (``edge_start_from_measured``: the
            measured E or G plus the offset along the normal), wobj frame, m; the program
            then moves there in a straight line from the safe start.

    Returns:
        One search (approach point: its retreat runs back along it) or three (edge point: the
        face approach, or the move to the measured start; the edge search; the straight
        retreat from where it stops to the safe start); each starts where the program starts
        it.

    Raises:
        InputError: the measured start lies past the end of the plan's edge search.
    """
    T = np.asarray(T_base_wobj, dtype=np.float64)
    cmd = SearchCommand.from_point(point, T)
    safe_w, face_end_w = safe_and_face_wobj(point, safety)
    safe = transform_points(T, safe_w)
    end = cmd.start_m + cmd.length_m * cmd.direction
    if point.search.kind == "approach":
        length = float(np.linalg.norm(end - safe))
        return (
            ProgramSearch(
                "search from the safe start", replace(cmd, start_m=safe, length_m=length)
            ),
        )
    n = transform_directions(T, np.asarray(point.normal, dtype=float))
    if measured_start_wobj is None:
        face_end = transform_points(T, face_end_w)
        first = _line(cmd, safe, cmd.start_m, n, length_m=float(np.linalg.norm(face_end - safe)))
        edge = cmd
        names = ("approach to the face from the safe start", "edge search")
    else:
        to = transform_points(T, np.asarray(measured_start_wobj, dtype=float))
        run = float((end - to) @ cmd.direction)
        if run <= 0.0:
            raise InputError(
                f"point {point.id}: the edge search from the measured start (edge_start_from_"
                f"measured) would start {-run * 1e3:.1f} mm past the end of the plan's search"
            )
        first = _line(cmd, safe, to, n)
        edge = replace(cmd, start_m=to, length_m=run)
        names = (
            "move from the safe start to the measured start",
            "edge search from the measured start",
        )
    # where the edge search stops (nominally), then the straight retreat to the safe start
    stop = edge.start_m + float((edge.nominal_m - edge.start_m) @ edge.direction) * edge.direction
    return (
        ProgramSearch(names[0], first),
        ProgramSearch(names[1], edge),
        ProgramSearch("retreat to the safe start", _line(cmd, stop, safe, n)),
    )


def _line(
    cmd: SearchCommand,
    a: FloatArray,
    b: FloatArray,
    n: FloatArray,
    length_m: float | None = None,
) -> SearchCommand:
    """A straight move of ``cmd``'s sensor from ``a`` towards ``b`` (base frame), walked as an
    approach whose nominal point is ``b`` (checked against the part up to there, the sensor
    allowed to touch it); ``length_m`` runs it past ``b`` (a search's overtravel)."""
    gap = float(np.linalg.norm(b - a))
    return SearchCommand(
        point_id=cmd.point_id,
        kind="approach",
        start_m=a,
        direction=(b - a) / gap if gap > 0.0 else -n,
        length_m=max(gap if length_m is None else length_m, 1e-6),
        sensor_axis=cmd.sensor_axis,
        T_base_wobj_estimate=cmd.T_base_wobj_estimate.copy(),
        nominal_m=np.asarray(b, dtype=float).copy(),
        stop_normal=n,
    )
