"""Probe-pose feasibility, batch-first: N surface points in, N answers (with reasons) out.

A probe pose puts the TCP (``sensor`` by default) on the surface point with its +z axis along
``-normal`` (into the surface); the rotation about that axis is free and searched every
``rotation_step_deg``. All ``N x R`` flange poses go to the IK solver in one call; candidates
(pose, branch) within limits and away from wrist singularity are then collision-checked in
order of least joint motion from ``q_ref`` (candidates near a joint limit last) until one
passes with margin. A feasible pose whose clearance slack or joint-limit margin is small is
``"marginal"``. Infeasible poses say why: out of reach, a joint at its limit, singular wrist, or
the limiting collision pair and its clearance.

Candidates are checked staged (:mod:`planner.cell.probe_clearance`): the tool once per rotation
before any robot link, and a candidate is dropped as soon as it can neither pass nor beat the
least-bad one so far, so a point that collides in every pose costs a fraction of the whole
queries; the answers are those of one whole clearance query per candidate (``staged=False``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import DegenerateGeometryError, ShapeError
from calib.frames import invert_transform
from calib.validation import check_positive, check_shape
from planner.cell.collision import DEFAULT_MARGIN_M, Clearance
from planner.cell.probe_clearance import ProbeClearance
from planner.robot.reach import no_ik_reason

if TYPE_CHECKING:
    from planner.cell.scene import CellScene
    from planner.robot.kinematics.chain import KinematicChain

FloatArray = NDArray[np.float64]
Status = Literal["feasible", "marginal", "infeasible"]

#: Wrist singularity of OPW arms: ``|sin q5|`` below ``sin`` of this angle, rad.
WRIST_SINGULAR_RAD = math.radians(5.0)
#: Other arms: smallest singular value of the Jacobian (translation rows / reach) below this.
MIN_SINGULAR_VALUE = 0.05
#: Clearances closer than this are a tie (Bullet's GJK answers vary by micrometres with the
#: scene's pose); among ties the earlier candidate (less joint motion) wins, m.
CLEARANCE_TIE_M = 1e-4
#: A joint closer than this to a limit makes a feasible pose marginal, rad.
MARGINAL_LIMIT_RAD = math.radians(5.0)


@dataclass(frozen=True)
class ProbeFeasibility:
    """Feasibility of one probe pose.

    Attributes:
        feasible: True when a collision-free, within-limits, non-singular pose was found.
        status: ``"feasible"``, ``"marginal"`` (feasible with small clearance or joint-limit
            margin) or ``"infeasible"``.
        reason: empty when ``status == "feasible"``; otherwise why, e.g. ``"out of reach
            (2.87 m from the shoulder, reach 1.92 m)"``, ``"joint 5 at limit"``,
            ``"singular wrist"``, ``"link_4 hits table (clearance -3.0 mm)"``.
        q: ``(n,)`` joint values of the chosen pose, rad; for an infeasible pose the least-bad
            candidate checked, ``None`` when there is no IK candidate at all.
        branch: IK branch of ``q`` (OPW configuration 0-7), -1 when unknown or none.
        rotation_rad: chosen rotation about the sensor axis, rad (NaN when none).
        clearance_m: clearance of the limiting pair at ``q``, m, capped at ``2 * margin_m + 5 mm``
            (nothing nearer); NaN when no pose was checked.
        joint_margin_rad: smallest distance of ``q`` to a joint limit, rad (NaN when none).
        T_base_flange: ``(4, 4)`` flange pose of ``q``, base frame, m (``None`` when none).
        clearance_pair: ``(robot or tool link, obstacle)`` that limits ``clearance_m``, or
            ``None`` when nothing came within the query's look-ahead (or no pose was checked).
    """

    feasible: bool
    status: Status
    reason: str
    q: FloatArray | None
    branch: int
    rotation_rad: float
    clearance_m: float
    joint_margin_rad: float
    T_base_flange: FloatArray | None
    clearance_pair: tuple[str, str] | None = None


def tcp_frames(points: FloatArray, normals: FloatArray, angles: FloatArray) -> FloatArray:
    """``T_wobj_tcp (N, R, 4, 4)``: origin on each point, +z = ``-normal``, rotated by angles.

    At angle 0 the TCP x axis is the unit vector perpendicular to z closest to the wobj axis
    least aligned with z (a fixed, deterministic choice); angle ``a`` turns x about z by ``a``.
    """
    z = -normals
    ref = np.eye(3)[np.argmin(np.abs(z), axis=1)]
    x0 = ref - np.einsum("ij,ij->i", ref, z)[:, None] * z
    x0 /= np.linalg.norm(x0, axis=1, keepdims=True)
    y0 = np.cross(z, x0)
    c, s = np.cos(angles)[None, :, None], np.sin(angles)[None, :, None]
    x = c * x0[:, None] + s * y0[:, None]
    y = np.cross(z[:, None], x)
    T = np.zeros((points.shape[0], angles.size, 4, 4))
    T[..., :3, 0], T[..., :3, 1] = x, y
    T[..., :3, 2] = z[:, None]
    T[..., :3, 3] = points[:, None]
    T[..., 3, 3] = 1.0
    return T


def limit_margin(chain: KinematicChain, q: FloatArray) -> FloatArray:
    """Smallest distance of each ``q (..., n)`` to a joint limit, rad (inf for no limits)."""
    with np.errstate(invalid="ignore"):
        return np.min(np.minimum(q - chain.lower, chain.upper - q), axis=-1)


def _near_limit_reason(chain: KinematicChain, q: FloatArray) -> str:
    """E.g. ``joint 3 near its upper limit (joint_3, 4.3 deg to go)`` for one ``q (n,)``."""
    to_lower, to_upper = q - chain.lower, chain.upper - q
    j = int(np.argmin(np.minimum(to_lower, to_upper)))
    side, left = ("lower", to_lower[j]) if to_lower[j] < to_upper[j] else ("upper", to_upper[j])
    return (
        f"joint {j + 1} near its {side} limit ({chain.joint_names[j]}, "
        f"{math.degrees(float(left)):.1f} deg to go)"
    )


def singular(cell: CellScene, q: FloatArray) -> tuple[NDArray[np.bool_], str]:
    """Mask ``(M,)`` of configurations ``q (M, n)`` too near a singularity, and the reason."""
    if cell.solver.kind == "opw" and q.shape[1] == 6:
        return np.abs(np.sin(q[:, 4])) < math.sin(WRIST_SINGULAR_RAD), "singular wrist"
    _, J = cell.chain.fk_jacobian(q)
    Js = J.copy()
    Js[:, :3] /= max(cell.reach_model.reach_m, 1e-9)
    sv = np.linalg.svd(Js, compute_uv=False)[:, -1]
    return sv < MIN_SINGULAR_VALUE, "near a singularity"


def check_probes(
    cell: CellScene,
    points_wobj: ArrayLike,
    normals_wobj: ArrayLike,
    tcp: str = "sensor",
    rotation_step_deg: float = 15.0,
    margin_m: float | None = None,
    q_ref: ArrayLike | None = None,
    max_checks: int = 48,
    staged: bool = True,
) -> list[ProbeFeasibility]:
    """Feasibility of ``N`` probe poses (see the module docstring).

    Args:
        cell: the cell (its current ``T_base_wobj`` places the points).
        points_wobj: ``(N, 3)`` surface points, wobj frame, m.
        normals_wobj: ``(N, 3)`` outward unit normals, wobj frame (normalised here).
        tcp: the TCP put on the point (its +z looks into the surface).
        rotation_step_deg: step of the free rotation about the sensor axis, degrees.
        margin_m: clearance to work object and fixtures, m (default the cell's 5 mm).
        q_ref: ``(n,)`` reference configuration for "least joint motion" (default home).
        max_checks: largest number of candidates collision-checked per point.
        staged: check candidates through :class:`planner.cell.probe_clearance.ProbeClearance`
            (tool once per rotation, a candidate dropped as soon as it can change nothing);
            ``False``: one whole clearance query per candidate, the plain reference. Both
            give the same answers.

    Returns:
        One :class:`ProbeFeasibility` per point, in the order given. The cell's joint state is
        restored afterwards.

    Raises:
        ShapeError, NonFiniteError: bad shapes or NaN/inf in points or normals.
        DegenerateGeometryError: a zero normal.
        UnknownFrameError: unknown TCP (the message lists the valid names).
    """

    pts = check_shape(points_wobj, (None, 3), "points_wobj")
    nrm = check_shape(normals_wobj, (None, 3), "normals_wobj")
    if nrm.shape != pts.shape:
        raise ShapeError(f"normals_wobj must be {pts.shape} like points_wobj, got {nrm.shape}")
    length = np.linalg.norm(nrm, axis=1)
    if np.any(length < 1e-9):
        raise DegenerateGeometryError(f"normals_wobj[{int(np.argmin(length))}] is zero")
    nrm = nrm / length[:, None]
    step = math.radians(check_positive(rotation_step_deg, "rotation_step_deg"))
    margin = DEFAULT_MARGIN_M if margin_m is None else check_positive(margin_m, "margin_m", True)
    T_flange_tcp = cell.T_flange_tcp(tcp)
    ref = cell.home_q if q_ref is None else check_shape(q_ref, (cell.chain.n_joints,), "q_ref")
    angles = np.arange(0.0, 2 * np.pi - 1e-9, step)
    N, R = pts.shape[0], angles.size
    if N == 0:
        return []
    T_base_tcp = cell.T_base_wobj @ tcp_frames(pts, nrm, angles)
    T_bf = (T_base_tcp @ invert_transform(T_flange_tcp)).reshape(N * R, 4, 4)
    sol = cell.solver.solve(T_bf)
    K = sol.q.shape[1]
    valid = sol.valid.reshape(N, R * K)
    q_all = sol.q.reshape(N, R * K, -1)
    sing = np.zeros_like(valid)
    sing_reason = "singular wrist"
    if valid.any():
        m, sing_reason = singular(cell, q_all[valid])
        sing[valid] = m
    usable = valid & ~sing
    margin_all = np.where(valid, limit_margin(cell.chain, q_all), -np.inf)
    motion = np.where(usable, np.linalg.norm(np.nan_to_num(q_all - ref), axis=-1), np.inf)
    out: list[ProbeFeasibility] = []
    stages = ProbeClearance(cell, margin)
    with cell.saved_state():
        for i in range(N):
            if not valid[i].any():
                reason = no_ik_reason(
                    cell.reach_model, cell.solver, cell.chain, T_bf[i * R : (i + 1) * R]
                )
                out.append(_none(reason))
                continue
            if not usable[i].any():
                out.append(_none(sing_reason))
                continue
            near_limit = margin_all[i] < MARGINAL_LIMIT_RAD
            keys = (motion[i], near_limit, ~usable[i])  # usable first, then by limit
            order = np.lexsort(keys)[: int(usable[i].sum())][:max_checks]
            best: tuple[Clearance, int] | None = None
            chosen: tuple[Clearance, int] | None = None
            stages.start_point(T_bf[i * R : (i + 1) * R])
            for c in order:
                if staged:
                    limit_ok = margin_all[i, c] >= MARGINAL_LIMIT_RAD
                    bound = _settled_at(best, margin, limit_ok)
                    got = stages.check(int(c) // K, q_all[i, c], bound)
                    if got is None:  # can neither pass nor beat the least-bad one
                        continue
                    cl = got
                else:
                    cell.set_joint_positions(q_all[i, c])
                    cl = cell.clearance(margin, sensor_wobj_allowed=True)
                if best is None or cl.slack_m > best[0].slack_m + CLEARANCE_TIE_M:
                    best = (cl, c)
                if cl.ok and cl.slack_m >= margin and margin_all[i, c] >= MARGINAL_LIMIT_RAD:
                    chosen = (cl, c)
                    break
            if chosen is None and best is not None and best[0].ok:
                chosen = best
            pick = chosen or best
            if pick is None:  # unreachable: order is non-empty when usable[i].any()
                out.append(_none("no candidate checked"))
                continue
            cl, c = pick
            r, k = divmod(int(c), K)
            fine = cl.slack_m >= margin and margin_all[i, c] >= MARGINAL_LIMIT_RAD
            status: Status = "infeasible" if chosen is None else "feasible" if fine else "marginal"
            if status == "feasible":
                reason = ""
            elif status == "marginal":
                reason = (
                    f"small clearance: {cl.describe()}"
                    if cl.slack_m < margin
                    else _near_limit_reason(cell.chain, q_all[i, c])
                )
            else:
                reason = cl.describe()
            out.append(
                ProbeFeasibility(
                    feasible=chosen is not None,
                    status=status,
                    reason=reason,
                    q=q_all[i, c].copy(),
                    branch=int(sol.branch[i * R + r, k]),
                    rotation_rad=float(angles[r]),
                    clearance_m=float(cl.clearance_m),
                    joint_margin_rad=float(margin_all[i, c]),
                    T_base_flange=T_bf[i * R + r].copy(),
                    clearance_pair=cl.pair,
                )
            )
    return out


def _settled_at(best: tuple[Clearance, int] | None, margin: float, limit_ok: bool) -> float:
    """Slack at or below which a candidate changes nothing: it does not beat the least-bad
    one so far by more than the tie, and it cannot pass (slack below ``margin``, or a joint
    near its limit). ``-inf`` while nothing has been checked."""
    if best is None:
        return -math.inf
    bound = best[0].slack_m + CLEARANCE_TIE_M
    return min(bound, math.nextafter(margin, -math.inf)) if limit_ok else bound


def _none(reason: str) -> ProbeFeasibility:
    nan = float("nan")
    return ProbeFeasibility(False, "infeasible", reason, None, -1, nan, nan, nan, None)
