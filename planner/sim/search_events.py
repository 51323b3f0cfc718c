"""Bookkeeping of simulated searches: events, where a footprint landed, reachability hooks.

Used by the simulated sensors (:mod:`planner.sim.proximity`, :mod:`planner.sim.touch`) to report,
besides the measured point, what happened in each search (the report counts these per point,
with the reason), and to vet the path a search really ran against a
:class:`planner.cell.cell.Cell`. Landings are judged over the whole footprint against the
planar faces of the true mesh (:class:`FaceLookup`), so a sensor face partly over a hole or an
edge is counted with the fraction of its area that is off the face.

Every outcome is a :class:`planner.reasons.Reason`, its kind given where it is decided: a
search the sensor runs and finds nothing, or starts inside or already detecting, is a
``search`` (the simulators); a path the reachability hook refuses keeps the cell's kind and
pair (``reach``, ``joint_limit``, ``singularity``, ``collision``: :func:`cell_search_hook`);
a footprint that lands off its face or partly over a hole or an edge is a ``footprint``
(:class:`FaceLookup`, :data:`LANDED_OFF_FACE`, :data:`PARTLY_OFF_FACE`).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import NDArray

from calib.models.robot_error import AccuracyField, RobotErrorModel
from calib.models.sensor import tool_rotation
from calib.probing import SearchCommand
from planner.reasons import Reason

FloatArray = NDArray[np.float64]

#: A reachability hook: ``None`` when the commanded search is feasible, else why not.
ReachabilityHook = Callable[[SearchCommand], Reason | None]

#: Said before the reason of a search the reachability hook refuses.
UNREACHABLE = "unreachable or colliding: "


def _refusal(result: Any) -> Reason | None:
    """``None`` for a feasible :class:`planner.cell.probe.PathFeasibility`, else its
    cause (kind and pair as the cell gave them) after :data:`UNREACHABLE`."""
    if result.feasible:
        return None
    cause = result.cause
    if not isinstance(cause, Reason):
        raise TypeError(f"an infeasible search path must carry its cause (a Reason), got {cause!r}")
    return cause.worded(UNREACHABLE)


def cell_search_hook(cell: Any, step_m: float = 0.002) -> ReachabilityHook:
    """A hook that vets each commanded search with ``cell.check_search`` (a
    :class:`planner.cell.cell.Cell`); place the cell's work object where the part really is, so a
    search that collides because the part moved is caught.

    The reason returned is the cell's (its kind, and the pair of a collision) worded
    ``"unreachable or colliding: <the cell's reason>"``. Only the verdict is computed
    (``exact_clearance=False``: the broad phase clears most of each sample's collision query,
    :mod:`planner.cell.broad.path_clearance`; the same verdict and reason).
    """

    def hook(command: SearchCommand) -> Reason | None:
        return _refusal(cell.check_search(command, step_m=step_m, exact_clearance=False))

    return hook


@dataclass(frozen=True)
class ProgramPose:
    """How the measuring program runs one point, as ``wobjcal check`` chose it: the pose every
    exported program commands (its targets' orientation and configuration).

    Attributes:
        sensor_x_base: ``(3,)`` the sensor TCP's x axis at the checked probe pose, robot base
            frame, nominal part: the rotation about the sensor axis the targets carry.
        branch: the IK branch of that pose (OPW configuration 0-7; -1: any).
        q: ``(n,)`` its joint values, rad: the start of the nearest-solution choice.
    """

    sensor_x_base: FloatArray
    branch: int
    q: FloatArray


def program_search_hook(
    cell: Any,
    poses: Mapping[str, ProgramPose],
    keys: Mapping[str, str],
    T_base_wobj_nominal: FloatArray,
    tcp: str,
    step_m: float = 0.002,
    other_searches: str | None = None,
) -> ProgramSearchHook:
    """A hook that vets each commanded search the way ``wobjcal check`` walks it: with the
    sensor rotation and IK branch of the point's checked pose (``poses`` by plan id; a
    search's key maps to its plan id through ``keys``, :func:`planner.program.model.search_keys`),
    turned with the frame the search is commanded in (a target written in the work object
    moves with the program's estimate). Searches of no plan point (the x-offset run) run with
    the pose of the plan point ``other_searches`` names (the A-H programs run them with D's
    orientation), or any rotation and branch when it is ``None``. A plan point check found no
    pose for (a plan simulated though check refuses it) is reported as such, never vetted with
    a pose no program runs.

    The reason returned is the cell's worded ``"unreachable or colliding: <the cell's
    reason>"`` (its kind and pair kept); a point without a pose is a ``reach`` reason (check
    found no pose the robot can take there). As :func:`cell_search_hook`, only the verdict is
    computed.
    """
    return ProgramSearchHook(
        cell, poses, keys, np.asarray(T_base_wobj_nominal, dtype=float), tcp, step_m, other_searches
    )


class ProgramSearchHook:
    """The hook of :func:`program_search_hook`: called with one search, or with many through
    :meth:`many` (the same verdicts, the cell's paths checked together:
    ``cell.check_searches``).

    Attributes:
        cell: the open cell (a :class:`planner.cell.cell.Cell`, its work object where the part
            really lies).
        poses: the checked pose of each plan point, by plan id.
        keys: the plan id of each search id (:func:`planner.program.model.search_keys`).
        R_nom_T: ``(3, 3)`` the nominal part's rotation in the robot base frame, transposed
            (``R_wobj_base``): turns a commanded frame's rotation into the turn from nominal.
        tcp: the TCP that runs the searches.
        step_m: the paths' sampling step, m.
        other_searches: the plan point whose pose runs searches of no plan point (the
            x-offset run), or ``None``: any rotation and branch.
    """

    def __init__(
        self,
        cell: Any,
        poses: Mapping[str, ProgramPose],
        keys: Mapping[str, str],
        T_base_wobj_nominal: FloatArray,
        tcp: str,
        step_m: float,
        other_searches: str | None,
    ) -> None:
        self.cell = cell
        self.poses = poses
        self.keys = keys
        self.R_nom_T = T_base_wobj_nominal[:3, :3].T
        self.tcp = tcp
        self.step_m = step_m
        self.other_searches = other_searches

    def _pose(self, command: SearchCommand) -> ProgramPose | Reason | None:
        """The pose ``command`` runs with, the refusal of a point check found no pose for, or
        ``None`` (any rotation and branch)."""
        pid = self.keys.get(command.point_id)
        if pid is not None and pid not in self.poses:
            return Reason("reach", f"{UNREACHABLE}check found no pose for point {pid}")
        return self.poses.get(pid if pid is not None else (self.other_searches or ""))

    def _sensor_x(self, command: SearchCommand, pose: ProgramPose) -> FloatArray:
        """The pose's sensor x axis turned with the frame the search is commanded in."""
        R = np.asarray(command.T_base_wobj_estimate, dtype=float)[:3, :3] @ self.R_nom_T
        return R @ pose.sensor_x_base

    def __call__(self, command: SearchCommand) -> Reason | None:
        """``None`` when the robot can run ``command`` (base frame) with its point's pose,
        else why not (the cell's kind and pair, worded after :data:`UNREACHABLE`)."""
        pose = self._pose(command)
        if isinstance(pose, Reason):
            return pose
        if pose is None:
            res = self.cell.check_search(
                command, step_m=self.step_m, tcp=self.tcp, exact_clearance=False
            )
        else:
            res = self.cell.check_search(
                command,
                step_m=self.step_m,
                tcp=self.tcp,
                q_ref=pose.q,
                sensor_x=self._sensor_x(command, pose),
                branch=pose.branch,
                max_starts=1,
                exact_clearance=False,
            )
        return _refusal(res)

    def many(self, commands: Sequence[SearchCommand]) -> list[Reason | None]:
        """``[self(c) for c in commands]``, the searches with a pose checked together."""
        out: list[Reason | None] = [None] * len(commands)
        posed: list[tuple[int, ProgramPose]] = []
        for i, command in enumerate(commands):
            pose = self._pose(command)
            if isinstance(pose, Reason):
                out[i] = pose
            elif pose is None:
                out[i] = self(command)
            else:
                posed.append((i, pose))
        if posed:
            results = self.cell.check_searches(
                [commands[i] for i, _ in posed],
                [self._sensor_x(commands[i], pose) for i, pose in posed],
                [pose.q for _, pose in posed],
                [pose.branch for _, pose in posed],
                step_m=self.step_m,
                tcp=self.tcp,
            )
            for (i, _), res in zip(posed, results, strict=True):
                out[i] = _refusal(res)
        return out


def robot_offset(
    start_m: FloatArray,
    axis: FloatArray,
    rng: np.random.Generator,
    robot_error: RobotErrorModel,
    accuracy_field: AccuracyField | None,
    tcp_error_m: FloatArray | None,
) -> FloatArray:
    """``(3,)`` where the robot's TCP really runs minus where it is commanded, base frame, m.

    A fresh repeatability offset per search, the robot's accuracy field at the start, and the
    TCP calibration error (sensor tool frame, :func:`calib.models.sensor.tool_rotation`).
    """
    offset = robot_error.sample_repeatability_m(rng)
    if accuracy_field is not None:
        offset = offset + accuracy_field(start_m)
    if tcp_error_m is not None:
        offset = offset + tool_rotation(axis) @ tcp_error_m
    return offset


#: Searches of the x-offset run (``PX<layer>_<tooth>``) are counted together under this id.
XOFFSET_GROUP = "PX (x-offset run)"
_PX = re.compile(r"^PX\d+_\d+$")


def search_group(search_id: str) -> str:
    """The id a search is counted under: its own, or :data:`XOFFSET_GROUP` for the x-offset
    run's searches."""
    return XOFFSET_GROUP if _PX.match(search_id) else search_id


#: Landing of an approach whose footprint centre is not on the face it was meant for.
LANDED_OFF_FACE = Reason("footprint", "landed off its face")
#: Landing of an approach with part of its footprint over a hole or past an edge of its face.
PARTLY_OFF_FACE = Reason("footprint", "footprint partly over a hole or an edge")


@dataclass(frozen=True)
class ProbeEvent:
    """What happened in one simulated search (for the per-point outcome report).

    Attributes:
        point_id: the search's id as the procedure names it (``"D"``, a retake ``"D2"``).
        kind: ``"approach"`` or ``"edge"`` (the search's kind; a failure's kind is
            ``cause.kind``).
        cause: ``None`` on success, else why the search failed, with its kind (``search``
            from the sensor, the cell's kind and pair from the reachability hook).
        landing: ``None``, :data:`LANDED_OFF_FACE` or :data:`PARTLY_OFF_FACE` (``footprint``
            reasons): where an approach really landed.
        off_fraction: the part of the footprint (sensor face, or the ball's contact) not over
            the face the point was meant for, 0 to 1.
        travel_m: travel from the start to the event, m (``nan`` on failure).
    """

    point_id: str
    kind: str
    cause: Reason | None = None
    landing: Reason | None = None
    off_fraction: float = 0.0
    travel_m: float = float("nan")

    @property
    def reason(self) -> str:
        """The words of :attr:`cause` (``""`` on success)."""
        return "" if self.cause is None else str(self.cause)


@dataclass(frozen=True)
class SearchFailure:
    """The search a trial's calibration (or its x-offset run) stopped at, and why.

    Attributes:
        search: the failed search's id as the procedure names it (``"D"``, ``"C2"``,
            ``"PX1_11"``).
        cause: why, in the words the procedure reports it (the sensor's or the hook's, or the
            program's around them: ``"approach to the face: ..."``), with the kind and pair
            of the search's event (:func:`planner.sim.trial.search_failure`).
    """

    search: str
    cause: Reason

    def __str__(self) -> str:
        """``"<search>: <reason>"``, as the report lists it."""
        return f"{self.search}: {self.cause}"


@dataclass(frozen=True)
class FaceLookup:
    """Where a simulated footprint landed: the planar faces of the true part.

    Attributes:
        triangle_face: ``(F,)`` planar-face id of each triangle of the part mesh, ``-1`` for
            triangles on no planar face (:func:`planner.faces.detection.find_planar_faces`).
        intended: the planar face each search should land on, by the search's id (a plan id,
            or a role or retake key the procedure names its searches by); searches not listed
            are not classified.
    """

    triangle_face: NDArray[np.int64]
    intended: Mapping[str, int]

    def landing(self, point_id: str, triangles: NDArray[np.int64]) -> tuple[Reason | None, float]:
        """Classify a footprint from the triangles its samples hit (``-1``: nothing).

        The first sample is the footprint's centre (or nearest it); the samples are of equal
        area, so the fraction of samples off the intended face is that of the footprint.

        Returns:
            ``(landing, off_fraction)``: :data:`LANDED_OFF_FACE` or :data:`PARTLY_OFF_FACE`
            and the fraction off; ``(None, 0.0)`` when the whole footprint is on its face.
        """
        want = self.intended.get(point_id, -1)
        if want < 0 or len(triangles) == 0:
            return None, 0.0
        off = self._face_of[np.asarray(triangles, dtype=np.int64)] != want
        frac = np.count_nonzero(off) / len(off)  # np.mean's value, without its overhead
        if bool(off[0]):
            return LANDED_OFF_FACE, frac
        return (PARTLY_OFF_FACE, frac) if frac > 0.0 else (None, 0.0)

    @cached_property
    def _face_of(self) -> NDArray[np.int64]:
        """``(F + 1,)`` :attr:`triangle_face` with ``-1`` appended: indexed by a hit's
        triangle, ``-1`` (nothing hit) gives ``-1``."""
        return np.append(np.asarray(self.triangle_face, dtype=np.int64), -1)
