"""Search-path feasibility: can the robot run a whole approach or edge search?

A search (:class:`calib.probing.SearchCommand`, base frame) moves the sensor TCP from
``start_m`` along ``direction`` for ``length_m``, the sensor axis fixed. The path is sampled at
``<= step_m``; the rotation about the sensor axis and the IK branch are chosen at the start
(candidates in order of least joint motion), and every later sample takes the solution of the
same branch nearest to the previous one. A sample fails when it has no solution on that
branch within limits, a joint jumps more than ``max_joint_jump_rad``, it is near a singularity,
or it collides. The sensor may come as close as contact to the work object (not the margin).
Past the nominal point of an approach search, robot and tool are not checked against the work
object at all, only against fixtures and themselves: the real search stops at the surface, and
a part lying farther away has moved its surface away by just as much, so the geometry at the
stop is the one checked at the nominal point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_positive, check_shape, check_vector3
from calib.errors import DegenerateGeometryError
from calib.frames import invert_transform
from planner.cell.broad import first_failure, path_clearances
from planner.cell.probe.feasibility import (
    MARGINAL_LIMIT_RAD,
    limit_margin,
    singular,
    tcp_frames,
)
from planner.cell.scene import DEFAULT_MARGIN_M
from planner.reasons import Reason
from planner.robot.reach import no_ik_reason

if TYPE_CHECKING:
    from calib.probing import SearchCommand
    from planner.cell.scene import CellScene

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class PathFeasibility:
    """Feasibility of one search path.

    Attributes:
        feasible: True when the whole path passes.
        cause: ``None`` when feasible; else why, with the distance, e.g. ``"at 23.0 mm:
            link_5 hits clamp (clearance 2.1 mm)"`` (a ``collision`` with its pair), ``"at 0.0
            mm: out of reach (...)"`` (``reach``; leaving the pose's IK branch too), a joint at
            its limit (``joint_limit``), a singularity or a joint's jump (``singularity``).
        fail_at_m: distance along the path of the first failing sample, m (NaN if feasible).
        s_m: ``(M,)`` distances of the samples from the start, m.
        q_path: ``(M', n)`` joint values of the samples that passed (all ``M`` when feasible),
            rad.
        rotation_rad: the rotation about the sensor axis used (see
            :func:`planner.cell.probe.feasibility.tcp_frames`), rad; NaN when no start was found.
        branch: IK branch of the path (OPW configuration 0-7), -1 when unknown.
        min_clearance_m: smallest clearance along the checked samples, m (NaN if none).
    """

    feasible: bool
    cause: Reason | None
    fail_at_m: float
    s_m: FloatArray
    q_path: FloatArray
    rotation_rad: float
    branch: int
    min_clearance_m: float

    @property
    def reason(self) -> str:
        """The words of :attr:`cause` (``""`` when feasible)."""
        return "" if self.cause is None else str(self.cause)


def check_search(
    cell: CellScene,
    command: SearchCommand,
    step_m: float = 0.001,
    max_joint_jump_rad: float = math.radians(5.0),
    tcp: str = "sensor",
    margin_m: float | None = None,
    rotation_step_deg: float = 15.0,
    q_ref: ArrayLike | None = None,
    max_starts: int = 6,
    sensor_x: ArrayLike | None = None,
    branch: int | None = None,
    exact_clearance: bool = True,
) -> PathFeasibility:
    """Check the search ``command`` in ``cell`` (see the module docstring).

    Args:
        cell: the cell.
        command: the search, base frame.
        step_m: largest distance between samples, m.
        max_joint_jump_rad: largest joint change between samples, rad.
        tcp: the TCP that runs the search.
        margin_m: clearance to work object and fixtures, m (default the cell's 5 mm).
        rotation_step_deg: step of the rotations about the sensor axis tried at the start.
        q_ref: ``(n,)`` reference configuration for the start choice (default home).
        max_starts: start candidates (rotation, branch) tried before giving up.
        sensor_x: ``(3,)`` the sensor TCP's x axis, base frame: only that rotation about the
            sensor axis is tried (the probe pose's, which the exported program runs; its
            component along the axis is ignored), start solutions nearest ``q_ref`` first
            (max-abs joint distance, as the export picks a target's joint values).
            ``None``: every ``rotation_step_deg``, least motion away from the limits first.
        branch: only start solutions of this IK branch (the probe pose's: the program's
            configuration); ``None`` or ``-1``: any branch.
        exact_clearance: compute the clearance of every sample (``min_clearance_m``);
            ``False``: only the verdict, the same ``feasible`` and ``reason`` (the broad
            phase clears most of each sample's query: :mod:`planner.cell.broad.path_clearance`),
            ``min_clearance_m`` NaN.

    Returns:
        The first start candidate whose whole path passes, else the one that got farthest.
        The cell's joint state is restored afterwards.

    Raises:
        ShapeError, NonFiniteError: bad vectors in the command; DegenerateGeometryError:
        zero direction or sensor axis; UnknownFrameError: unknown TCP.
    """

    step = check_positive(step_m, "step_m")
    start, direction, axis, s, skip_from = sampled_path(command, step)
    jump = check_positive(max_joint_jump_rad, "max_joint_jump_rad")
    margin = DEFAULT_MARGIN_M if margin_m is None else check_positive(margin_m, "margin_m", True)
    ref = cell.home_q if q_ref is None else check_shape(q_ref, (cell.chain.n_joints,), "q_ref")
    T_tcp_flange = invert_transform(cell.T_flange_tcp(tcp))
    if sensor_x is None:
        rot_step = math.radians(check_positive(rotation_step_deg, "rotation_step_deg"))
        angles = np.arange(0.0, 2 * np.pi - 1e-9, rot_step)
    else:
        angles = np.array([sensor_angle(check_vector3(sensor_x, "sensor_x"), start, axis)])
    # T_base_tcp of every (rotation, sample): normals are -axis, points along the path
    points = start + s[:, None] * direction
    T_start = tcp_frames(start[None], -axis[None], angles)[0]  # (R, 4, 4)
    # a numeric solver starts from q_ref (e.g. the probe pose's solution) besides its seeds
    starts = cell.solver.solve(T_start @ T_tcp_flange, seeds=None if q_ref is None else ref[None])
    K = starts.valid.shape[1]
    q0 = starts.q
    ok0 = starts.valid.copy()
    if branch is not None and branch >= 0:
        ok0 &= starts.branch == branch
    if ok0.any():
        sing, _ = singular(cell, q0[ok0])
        ok0[ok0] = ~sing
    empty = np.zeros((0, cell.chain.n_joints))
    if not ok0.any():
        if not starts.valid.any():
            reason = no_ik_reason(cell.reach_model, cell.solver, cell.chain, T_start @ T_tcp_flange)
        elif branch is not None and branch >= 0 and not (starts.branch == branch).any():
            reason = Reason("reach", f"no solution on IK branch {branch} (the probe pose's)")
        else:
            reason = Reason("singularity", "singular at the start")
        at_start = reason.worded("at 0.0 mm: ")
        return PathFeasibility(False, at_start, 0.0, s, empty, math.nan, -1, math.nan)
    if sensor_x is None:  # free choice: least motion, away from the limits first
        motion = np.where(ok0, np.linalg.norm(np.nan_to_num(q0 - ref), axis=-1), np.inf)
        near = limit_margin(cell.chain, np.nan_to_num(q0)) < MARGINAL_LIMIT_RAD
    else:  # the program's start: the solution nearest the pose (export's rule, max-abs)
        motion = np.where(ok0, np.abs(np.nan_to_num(q0 - ref)).max(axis=-1), np.inf)
        near = np.zeros_like(ok0)
    order = np.lexsort((motion.ravel(), near.ravel(), ~ok0.ravel()))[: int(ok0.sum())]
    order = order[:max_starts]
    best: PathFeasibility | None = None
    with cell.saved_state():
        for flat in order:
            r, k = divmod(int(flat), K)
            T_path = T_start[r].copy()[None].repeat(s.size, axis=0)
            T_path[:, :3, 3] = points
            res = _walk(
                cell,
                T_path @ T_tcp_flange,
                q0[r, k],
                int(starts.branch[r, k]),
                s,
                jump,
                margin,
                skip_from,
                float(angles[r]),
                exact_clearance,
            )
            if res.feasible:
                return res
            if best is None or res.fail_at_m > best.fail_at_m:
                best = res
    if best is None:  # order is non-empty because ok0.any()
        raise RuntimeError("no start candidate was tried")
    return best


def _walk(
    cell: CellScene,
    T_flange: FloatArray,
    q_start: FloatArray,
    branch: int,
    s: FloatArray,
    jump: float,
    margin: float,
    skip_from: float,
    rotation: float,
    exact_clearance: bool = True,
) -> PathFeasibility:
    """Follow one start solution along the sampled path (see the module docstring)."""
    sol = cell.solver.solve(T_flange, seeds=q_start[None])
    q_path, fail_j, reason = follow_branch(
        cell, sol.q, sol.valid, sol.branch, T_flange, q_start, branch, jump
    )
    skip = s[:fail_j] > skip_from
    if not exact_clearance:  # the verdict only: the first sample that fails, broad phase first
        j, cl = first_failure(cell, q_path[:fail_j], T_flange[:fail_j], skip, margin)
        if cl is not None:
            fail_j, reason = j, cl.reason()
        return path_verdict(s, q_path, fail_j, reason, rotation, branch, math.nan)
    # every sample's clearance up to the first that fails (the broad phase clears most parts)
    min_cl = math.inf
    for j, cl in enumerate(path_clearances(cell, q_path[:fail_j], T_flange[:fail_j], skip, margin)):
        min_cl = min(min_cl, cl.clearance_m)
        if not cl.ok:
            fail_j, reason = j, cl.reason()
            break
    return path_verdict(s, q_path, fail_j, reason, rotation, branch, min_cl)


def sampled_path(
    command: SearchCommand, step_m: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, float]:
    """A search's checked path: ``(start (3,), unit direction (3,), unit sensor axis (3,),
    s (M,), skip_from)``, base frame, m: the samples' distances from the start at ``<=
    step_m``, and the distance past which an approach is not checked against the work object
    (its nominal point; ``inf`` for an edge search).

    Raises:
        ShapeError, NonFiniteError: bad vectors; DegenerateGeometryError: a zero direction or
        sensor axis; a length that is not positive.
    """
    start = check_vector3(command.start_m, "command.start_m")
    direction = unit_vector(command.direction, "command.direction")
    axis = unit_vector(command.sensor_axis, "command.sensor_axis")
    length = check_positive(command.length_m, "command.length_m")
    nominal = check_vector3(command.nominal_m, "command.nominal_m")
    s = np.linspace(0.0, length, math.ceil(length / step_m - 1e-9) + 1)
    s_nominal = float((nominal - start) @ direction)
    skip_from = s_nominal + 1e-9 if command.kind == "approach" else math.inf
    return start, direction, axis, s, skip_from


def follow_branch(
    cell: CellScene,
    q: FloatArray,
    valid: NDArray[np.bool_],
    branches: NDArray[np.int64],
    T_flange: FloatArray,
    q_start: FloatArray,
    branch: int,
    jump: float,
) -> tuple[FloatArray, int, Reason | None]:
    """The joint path of one start solution along a sampled path, before any clearance test.

    Args:
        cell: the cell (its chain, solver and reach model, for the reasons).
        q, valid, branches: the IK solutions of the ``M`` samples (:class:`IKSolutions`'
            ``(M, K, n)``, ``(M, K)``, ``(M, K)``).
        T_flange: ``(M, 4, 4)`` the samples' flange poses, base frame, m.
        q_start: ``(n,)`` the start solution, rad.
        branch: its IK branch (``-1``: any).
        jump: largest joint change between samples, rad.

    Returns:
        ``(q_path (M, n), fail_j, reason)``: every sample takes the solution of ``branch``
        nearest the previous one (max-abs); ``fail_j`` is the first sample without one, with a
        joint jump or near a singularity (``M`` when none), ``reason`` why (``None`` when none).
    """
    M = T_flange.shape[0]
    q_path = np.empty((M, q_start.size))
    prev = q_start
    fail_j, reason = M, None
    for j in range(M):
        ok = valid[j] & ((branches[j] == branch) if branch >= 0 else True)
        if not ok.any():
            fail_j = j
            reason = (
                no_ik_reason(cell.reach_model, cell.solver, cell.chain, T_flange[j : j + 1])
                if not valid[j].any()
                else Reason("reach", f"leaves IK branch {branch}")
            )
            break
        d = np.where(ok, np.abs(q[j] - prev).max(axis=-1), np.inf)
        k = int(np.argmin(d))
        if j > 0 and d[k] > jump:
            fail_j = j
            jj = int(np.argmax(np.abs(q[j, k] - prev)))
            # a joint flips between two samples: the path passes near a singularity
            reason = Reason("singularity", f"joint {jj + 1} jumps {math.degrees(d[k]):.1f} deg")
            break
        q_path[j] = prev = q[j, k]
    if fail_j > 0:
        sing, why = singular(cell, q_path[:fail_j])
        if sing.any():
            fail_j, reason = int(np.argmax(sing)), why
    return q_path, fail_j, reason


def path_verdict(
    s: FloatArray,
    q_path: FloatArray,
    fail_j: int,
    reason: Reason | None,
    rotation: float,
    branch: int,
    min_cl: float,
) -> PathFeasibility:
    """The :class:`PathFeasibility` of a path whose first failing sample is ``fail_j``
    (``len(s)``: none) for ``reason``; ``min_cl`` the smallest clearance seen, m."""
    min_cl = min_cl if math.isfinite(min_cl) else math.nan
    M = s.size
    if fail_j == M or reason is None:
        return PathFeasibility(True, None, math.nan, s, q_path, rotation, branch, min_cl)
    at = float(s[fail_j])
    return PathFeasibility(
        False,
        reason.worded(f"at {at * 1e3:.1f} mm: "),
        at,
        s,
        q_path[:fail_j].copy(),
        rotation,
        branch,
        min_cl,
    )


def sensor_angle(x: FloatArray, start: FloatArray, axis: FloatArray) -> float:
    """The rotation about the sensor ``axis`` (:func:`tcp_frames`' angle) whose TCP x axis
    is ``x`` projected off the axis, rad."""
    T0 = tcp_frames(start[None], -axis[None], np.zeros(1))[0, 0]
    u, v = float(x @ T0[:3, 0]), float(x @ T0[:3, 1])
    if math.hypot(u, v) < 1e-9 * max(1.0, float(np.linalg.norm(x))):
        raise DegenerateGeometryError("sensor_x must not be along the sensor axis")
    return math.atan2(v, u)


def unit_vector(v: ArrayLike, name: str) -> FloatArray:
    """``v`` (a 3-vector, checked as ``name``) made unit length.

    Raises:
        DegenerateGeometryError: ``v`` is the zero vector.
    """
    a = check_vector3(v, name)
    n = float(np.linalg.norm(a))
    if n < 1e-12:
        raise DegenerateGeometryError(f"{name} must not be the zero vector")
    return a / n
