"""Probe points, search commands and the probe callback: the contract between procedures and
whatever moves the sensor (a simulation in ``planner`` or a real robot).

A procedure (e.g. the paper's A-H procedure) never moves anything itself. For each measurement
it builds a :class:`SearchCommand` in the robot base frame from the nominal point and the
current estimate of ``T_base_wobj``, and calls a :data:`Probe`. The probe runs the search and
returns a :class:`ProbeResult`: the measured sensor-TCP position in the base frame, or a failure
with its reason. Because the next command depends on the estimate so far, the same procedure
code drives a simulation or a robot, step by step, as in section 3.2 of the paper.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_positive, check_unit_vector3, check_vector3
from calib.errors import DegenerateGeometryError, ShapeError
from calib.frames import transform_directions, transform_points

FloatArray = NDArray[np.float64]
SearchKind = Literal["approach", "edge"]


@dataclass(frozen=True)
class SearchSpec:
    """How a point is searched for, in the nominal wobj frame.

    Attributes:
        kind: ``"approach"``: move along the sensor axis (``-normal``) towards the surface until
            the sensor switches. ``"edge"``: keep the sensor at its sensing distance over a face
            and move along ``edge_direction`` until the sensor stops detecting (the face ends).
        start_offset_m: approach: distance of the start from the surface along ``+normal``, m.
            edge: distance before the nominal edge point along ``-edge_direction``, m.
        overtravel_m: how far past the nominal point the search may go before it fails, m.
        edge_direction: ``(3,)`` unit direction of motion of an edge search, wobj frame
            (must be perpendicular to ``normal``); ``None`` for approach searches.
    """

    kind: SearchKind = "approach"
    start_offset_m: float = 0.030
    overtravel_m: float = 0.020
    edge_direction: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        if self.kind not in ("approach", "edge"):
            raise ShapeError(f"search.kind must be 'approach' or 'edge', got {self.kind!r}")
        check_positive(self.start_offset_m, "search.start_offset_m")
        check_positive(self.overtravel_m, "search.overtravel_m")
        if self.kind == "edge":
            if self.edge_direction is None:
                raise ShapeError("search.edge_direction is required for an edge search")
            check_unit_vector3(self.edge_direction, "search.edge_direction")

    @property
    def length_m(self) -> float:
        """Total search travel, start to end, metres."""
        return self.start_offset_m + self.overtravel_m


@dataclass(frozen=True)
class ProbePoint:
    """A nominal probe point on the work object, wobj frame.

    Attributes:
        id: name of the point, e.g. ``"A"``.
        position_m: ``(3,)`` the surface point the measurement returns on the nominal part
            (for an edge search, the nominal edge point), wobj frame, metres.
        normal: ``(3,)`` unit outward normal of the face the sensor looks at, wobj frame.
        search: how the point is searched for.
        edge_normal: ``(3,)`` for an edge search, the unit outward normal of the face whose end
            the search finds (e.g. the top face when moving up the side face); ``None`` otherwise.
    """

    id: str
    position_m: tuple[float, float, float]
    normal: tuple[float, float, float]
    search: SearchSpec = field(default_factory=SearchSpec)
    edge_normal: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        if not self.id:
            raise ShapeError("probe point id must be a non-empty string")
        check_vector3(self.position_m, f"points[{self.id}].position_m")
        n = check_unit_vector3(self.normal, f"points[{self.id}].normal")
        if self.search.kind == "edge":
            d = np.asarray(self.search.edge_direction, float)
            if abs(float(d @ n)) > 1e-6:
                raise DegenerateGeometryError(
                    f"points[{self.id}].search.edge_direction must lie in the face "
                    f"(perpendicular to normal), got dot = {float(d @ n):.3g}"
                )
        if self.edge_normal is not None:
            check_unit_vector3(self.edge_normal, f"points[{self.id}].edge_normal")

    @property
    def constraint_normals(self) -> FloatArray:
        """``(k, 3)`` unit normals of the faces this point constrains (1, or 2 for edges)."""
        rows = [self.normal] if self.edge_normal is None else [self.normal, self.edge_normal]
        return np.asarray(rows, dtype=np.float64)


@dataclass(frozen=True)
class SearchCommand:
    """One search the robot is asked to run, in the robot base frame.

    Attributes:
        point_id: id of the probe point.
        kind: ``"approach"`` or ``"edge"`` (see :class:`SearchSpec`).
        start_m: ``(3,)`` sensor-TCP start position, base frame, metres.
        direction: ``(3,)`` unit direction of TCP motion, base frame.
        length_m: largest travel from the start, metres; no event within it is a failure.
        sensor_axis: ``(3,)`` unit sensor axis (sensor +z, looking into the surface), base frame.
        T_base_wobj_estimate: ``(4, 4)`` the estimate of the work-object frame the command was
            built from.
        nominal_m: ``(3,)`` where the event is expected on the estimated part, base frame.
        stop_normal: ``(3,)`` unit outward normal of the face that ends the search (an
            approach: the face it looks at; an edge search: the face whose end it finds), on
            the estimated part, base frame; ``None`` when not known.
    """

    point_id: str
    kind: SearchKind
    start_m: FloatArray
    direction: FloatArray
    length_m: float
    sensor_axis: FloatArray
    T_base_wobj_estimate: FloatArray
    nominal_m: FloatArray
    stop_normal: FloatArray | None = None

    @classmethod
    def from_point(cls, point: ProbePoint, T_base_wobj: ArrayLike) -> SearchCommand:
        """Build the command for ``point`` given the current estimate ``T_base_wobj``."""
        T = np.asarray(T_base_wobj, dtype=np.float64)
        s = point.search
        if T.shape != (4, 4):  # a batch of frames: the general transforms
            p = np.asarray(point.position_m, float)
            n = np.asarray(point.normal, float)
            start_w, dir_w, stop_w = _wobj_vectors(point)
            return cls(
                point_id=point.id,
                kind=s.kind,
                start_m=transform_points(T, start_w),
                direction=transform_directions(T, dir_w),
                length_m=s.length_m,
                sensor_axis=transform_directions(T, -n),
                T_base_wobj_estimate=T.copy(),
                nominal_m=transform_points(T, p),
                stop_normal=transform_directions(T, stop_w),
            )
        # one frame (every search of a procedure run): the four directions and two points
        # in one product each, a few microseconds instead of six einsum calls
        R, t = T[:3, :3], T[:3, 3]
        try:
            dirs_w, pts_w = _wobj_rows(point)
        except TypeError:  # a point built with lists or arrays (not hashable): not cached
            dirs_w, pts_w = _wobj_rows.__wrapped__(point)
        dirs = dirs_w @ R.T
        pts = pts_w @ R.T + t
        return cls(
            point_id=point.id,
            kind=s.kind,
            start_m=pts[0],
            direction=dirs[0],
            length_m=s.length_m,
            sensor_axis=dirs[1],
            T_base_wobj_estimate=T.copy(),
            nominal_m=pts[1],
            stop_normal=dirs[2],
        )


def _wobj_vectors(point: ProbePoint) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``(start, direction, stop normal)`` of ``point``'s search in the wobj frame (m)."""
    p = np.asarray(point.position_m, float)
    n = np.asarray(point.normal, float)
    s = point.search
    if s.kind == "approach":
        return p + s.start_offset_m * n, -n, n
    d = np.asarray(s.edge_direction, float)
    stop_w = d if point.edge_normal is None else np.asarray(point.edge_normal, float)
    return p - s.start_offset_m * d, d, stop_w


@lru_cache(maxsize=4096)
def _wobj_rows(point: ProbePoint) -> tuple[FloatArray, FloatArray]:
    """``(directions (3, 3), points (2, 3))`` :meth:`SearchCommand.from_point` moves into the
    base frame: the search direction, the sensor axis and the stop normal; the start and the
    nominal point (wobj frame, m; computed once per point, read-only)."""
    start_w, dir_w, stop_w = _wobj_vectors(point)
    n = np.asarray(point.normal, float)
    dirs = np.array([dir_w, -n, stop_w])
    pts = np.array([start_w, np.asarray(point.position_m, float)])
    dirs.setflags(write=False)
    pts.setflags(write=False)
    return dirs, pts


@dataclass(frozen=True)
class ProbeResult:
    """What a probe returns.

    Attributes:
        point_m: ``(3,)`` measured sensor-TCP position at the switching event, base frame, metres;
            ``None`` when the probe failed.
        reason: empty on success; otherwise why it failed (e.g. ``"no detection within 50 mm"``,
            ``"sensor already detecting at start"``, ``"unreachable: joint 5 at limit"``).
        travel_m: distance travelled from the start to the event, metres (``nan`` on failure).
    """

    point_m: FloatArray | None
    reason: str = ""
    travel_m: float = float("nan")

    @property
    def ok(self) -> bool:
        """True when the probe returned a point."""
        return self.point_m is not None


#: A probe runs one search and returns its result.
Probe = Callable[[SearchCommand], ProbeResult]
