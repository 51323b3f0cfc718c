"""The candidate poses of a batch of probe points: IK, limits, singularity, order. Vectorized.

A probe point's candidates are the IK solutions of its flange poses, one per rotation about the
sensor axis (see :func:`planner.cell.probe.feasibility.tcp_frames`): all ``N x R`` poses go to one
IK call. A candidate is *usable* when it is valid (within the limits) and not near a singularity;
the usable ones are checked in a fixed order: those at least
:data:`~planner.cell.probe.feasibility.MARGINAL_LIMIT_RAD` from every joint limit first, then by
joint motion from ``q_ref``; ties keep the IK's order. Points without a usable candidate get
their reason here (out of reach, a joint at its limit, singular wrist), one batched call for all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from calib.frames import invert_transform
from planner.reasons import Reason
from planner.robot.reach import no_ik_reasons

if TYPE_CHECKING:
    from planner.cell.scene import CellScene
    from planner.robot.kinematics.chain import KinematicChain

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Wrist singularity of OPW arms: ``|sin q5|`` below ``sin`` of this angle, rad.
WRIST_SINGULAR_RAD = math.radians(5.0)
#: Other arms: smallest singular value of the Jacobian (translation rows / reach) below this.
MIN_SINGULAR_VALUE = 0.05
#: A joint closer than this to a limit makes a feasible pose marginal, rad.
MARGINAL_LIMIT_RAD = math.radians(5.0)
#: The reasons of :func:`singular`: an OPW arm's wrist, another arm's Jacobian.
SINGULAR_WRIST = Reason("singularity", "singular wrist")
NEAR_SINGULARITY = Reason("singularity", "near a singularity")


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
    lo, hi = chain.lower, chain.upper
    with np.errstate(invalid="ignore"):
        if q.ndim < 2 or q.shape[-1] < 1:
            return np.min(np.minimum(q - lo, hi - q), axis=-1)
        # joint by joint: the same minimum as one reduction over the last axis, ~3x faster
        out = np.minimum(q[..., 0] - lo[0], hi[0] - q[..., 0])
        for j in range(1, q.shape[-1]):
            np.minimum(out, q[..., j] - lo[j], out=out)
            np.minimum(out, hi[j] - q[..., j], out=out)
        return out


def singular(cell: CellScene, q: FloatArray) -> tuple[BoolArray, Reason]:
    """Mask ``(M,)`` of configurations ``q (M, n)`` too near a singularity, and the reason."""
    if cell.solver.kind == "opw" and q.shape[1] == 6:
        return np.abs(np.sin(q[:, 4])) < math.sin(WRIST_SINGULAR_RAD), SINGULAR_WRIST
    _, J = cell.chain.fk_jacobian(q)
    Js = J.copy()
    Js[:, :3] /= max(cell.reach_model.reach_m, 1e-9)
    sv = np.linalg.svd(Js, compute_uv=False)[:, -1]
    return sv < MIN_SINGULAR_VALUE, NEAR_SINGULARITY


@dataclass(frozen=True)
class ProbeCandidates:
    """The candidates of ``N`` probe points (``C = R * K`` per point, rotation-major).

    Attributes:
        angles: ``(R,)`` rotations about the sensor axis, rad.
        T_base_flange: ``(N, R, 4, 4)`` flange pose of each point and rotation, base frame, m.
        q: ``(N, C, n)`` joint values, rad (NaN where there is no solution).
        branch: ``(N, C)`` IK branch (OPW configuration 0-7), -1 when none or unknown.
        usable: ``(N, C)`` within limits and away from singularities.
        limit_margin: ``(N, C)`` smallest distance to a joint limit, rad (-inf when invalid).
        near_limit: ``(N, C)`` a joint is within :data:`MARGINAL_LIMIT_RAD` of its limit.
        motion: ``(N, C)`` joint motion from ``q_ref`` (norm, rad), inf when not usable.
        reasons: per point, why it has no usable candidate, or ``None`` when it has one.
    """

    angles: FloatArray
    T_base_flange: FloatArray
    q: FloatArray
    branch: NDArray[np.int_]
    usable: BoolArray
    limit_margin: FloatArray
    near_limit: BoolArray
    motion: FloatArray
    reasons: tuple[Reason | None, ...]

    @property
    def per_rotation(self) -> int:
        """``K``: candidates per rotation."""
        return self.q.shape[1] // self.angles.size

    def order(self, i: int, max_checks: int) -> NDArray[np.int_]:
        """The usable candidates of point ``i`` in checking order, at most ``max_checks``."""
        keys = (self.motion[i], self.near_limit[i], ~self.usable[i])
        order = np.lexsort(keys)[: int(self.usable[i].sum())]
        return order[:max_checks]

    def first(self) -> NDArray[np.int_]:
        """``(N,)`` each point's first candidate in :meth:`order` (-1 when none is usable)."""
        far = self.usable & ~self.near_limit
        key = np.where(far, self.motion, np.inf)
        first = np.argmin(key, axis=1)
        none_far = ~far.any(axis=1)
        if none_far.any():
            near = np.where(self.usable[none_far], self.motion[none_far], np.inf)
            first[none_far] = np.argmin(near, axis=1)
        first[~self.usable.any(axis=1)] = -1
        return first


def probe_candidates(
    cell: CellScene,
    points_wobj: FloatArray,
    normals_wobj: FloatArray,
    T_flange_tcp: FloatArray,
    angles: FloatArray,
    q_ref: FloatArray,
) -> ProbeCandidates:
    """The candidates of probe points (unit normals, wobj frame); see the module docstring."""
    N, R = points_wobj.shape[0], angles.size
    T_base_tcp = cell.T_base_wobj @ tcp_frames(points_wobj, normals_wobj, angles)
    T_bf = T_base_tcp @ invert_transform(T_flange_tcp)
    sol = cell.solver.solve(T_bf.reshape(N * R, 4, 4))
    K = sol.q.shape[1]
    n = sol.q.shape[2]
    valid = sol.valid.reshape(N, R * K)
    q = sol.q.reshape(N, R * K, n)
    usable = valid.copy()
    sing_reason = SINGULAR_WRIST
    margin = np.full((N, R * K), -np.inf)
    motion = np.full((N, R * K), np.inf)
    if valid.any():
        qv = q[valid]
        sing, sing_reason = singular(cell, qv)
        usable[valid] = ~sing
        margin[valid] = limit_margin(cell.chain, qv)
        ok = ~sing
        mv = np.full(qv.shape[0], np.inf)
        mv[ok] = np.linalg.norm(qv[ok] - q_ref, axis=-1)
        motion[valid] = mv
    reasons: list[Reason | None] = [None] * N
    none_valid = np.flatnonzero(~valid.any(axis=1))
    for i, why in zip(
        none_valid.tolist(),
        no_ik_reasons(cell.reach_model, cell.solver, cell.chain, T_bf[none_valid]),
    ):
        reasons[i] = why
    for i in np.flatnonzero(valid.any(axis=1) & ~usable.any(axis=1)).tolist():
        reasons[i] = sing_reason
    return ProbeCandidates(
        angles=angles,
        T_base_flange=T_bf,
        q=q,
        branch=sol.branch.reshape(N, R * K),
        usable=usable,
        limit_margin=margin,
        near_limit=margin < MARGINAL_LIMIT_RAD,
        motion=motion,
        reasons=tuple(reasons),
    )
