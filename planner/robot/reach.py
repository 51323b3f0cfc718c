"""Reach of a robot, and why a pose has no IK solution: out of reach, or a joint at a limit.

The reasons name numbers a person can check: the flange's (or, for OPW arms, the wrist
centre's) distance from the shoulder against the arm's reach, or the joint that breaks its
limit in most of the analytic branches. Each is a :class:`planner.reasons.Reason` of kind
``reach`` (out of reach, too close, no solution; "out of reach" measures the part, whose units
may be wrong: ``about_part``) or ``joint_limit``.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from calib.frames import invert_transform
from planner.memo import Memo
from planner.reasons import Reason

if TYPE_CHECKING:
    from planner.robot.kinematics.chain import KinematicChain
    from planner.robot.kinematics.solver import IKSolver

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ReachModel:
    """Where the shoulder is and how far the flange gets from it.

    Attributes:
        axis_origin_m: ``(3,)`` a point on joint 1's axis, base frame, m.
        axis: ``(3,)`` joint 1's unit axis, base frame.
        shoulder_m: ``(3,)`` the shoulder (joint 2's origin) at zero, base frame, m.
        reach_m: largest flange distance from the shoulder over 20,000 random in-limit
            configurations (the shoulder turning with joint 1), m.
    """

    axis_origin_m: FloatArray
    axis: FloatArray
    shoulder_m: FloatArray
    reach_m: float

    def shoulder_towards(self, p: FloatArray) -> FloatArray:
        """``(M, 3)``: the shoulder turned about joint 1's axis towards points ``p (M, 3)``."""
        o, a = self.axis_origin_m, self.axis
        s = self.shoulder_m - o
        s_ax = (s @ a) * a
        r_s = float(np.linalg.norm(s - s_ax))
        v = p - o
        r_p = v - np.outer(v @ a, a)
        norm = np.linalg.norm(r_p, axis=1, keepdims=True)
        unit = np.divide(r_p, norm, out=np.zeros_like(r_p), where=norm > 1e-12)
        return o + s_ax + r_s * unit


def reach_model(chain: KinematicChain, rng: np.random.Generator) -> ReachModel:
    """The :class:`ReachModel` of ``chain`` (uses ``rng`` for the sampled configurations)."""
    lo = np.where(np.isfinite(chain.lower), chain.lower, -np.pi)
    hi = np.where(np.isfinite(chain.upper), chain.upper, np.pi)
    zero = chain.joint_frames(np.clip(np.zeros(chain.n_joints), lo, hi))[0]
    k = min(1, chain.n_joints - 1)
    axis = zero[0, :3, :3] @ chain.axes[0]
    q = rng.uniform(lo, hi, size=(20_000, chain.n_joints))
    frames = chain.joint_frames(q)
    tip = frames[:, -1] @ chain.T_last_tip
    reach = float(np.max(np.linalg.norm(tip[:, :3, 3] - frames[:, k, :3, 3], axis=1)))
    return ReachModel(zero[0, :3, 3].copy(), axis, zero[k, :3, 3].copy(), reach)


def cell_reach_model(chain: KinematicChain) -> ReachModel:
    """The :func:`reach_model` of ``chain`` with seed 0, as every cell computes it; kept per
    chain content (joint types, axes, joint frames, tip, limits), so a cell opened again for
    the same robot does not sample its 20,000 configurations again. Its arrays are read-only."""
    h = hashlib.sha1(repr(chain.joint_types).encode())
    for a in (chain.axes, chain.T_prev_joint, chain.T_last_tip, chain.lower, chain.upper):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    key = h.hexdigest()
    model = _REACH.get(key)
    if model is None:
        model = reach_model(chain, np.random.default_rng(0))
        for a in (model.axis_origin_m, model.axis, model.shoulder_m):
            a.flags.writeable = False
        model = _REACH.put(key, model)
    return model


#: :func:`cell_reach_model`'s models: ``{content hash of the chain: model}``.
_REACH: Memo[str, ReachModel] = Memo(16)


def _out_of_reach(where: str) -> Reason:
    return Reason("reach", f"out of reach ({where})", about_part=True)


def _no_solution(where: str) -> Reason:
    return Reason("reach", f"no IK solution within joint limits ({where})")


def _at_limit(chain: KinematicChain, j: int) -> Reason:
    return Reason("joint_limit", f"joint {j + 1} at limit ({chain.joint_names[j]})")


def no_ik_reason(
    model: ReachModel, solver: IKSolver, chain: KinematicChain, T_flange: FloatArray
) -> Reason:
    """Why ``(R, 4, 4)`` flange poses (base frame, m) of one point have no valid IK solution.

    Args:
        model: the robot's reach (:func:`reach_model`).
        solver: its IK solver (the OPW branches say which joint breaks its limit).
        chain: its kinematic chain (joint names and limits).
        T_flange: ``(R, 4, 4)`` the candidate flange poses, base frame, m.
    """
    p = T_flange[:, :3, 3]
    dist = float(np.min(np.linalg.norm(p - model.shoulder_towards(p), axis=1)))
    where = f"{dist:.2f} m from the shoulder, reach {model.reach_m:.2f} m"
    if dist > model.reach_m:
        return _out_of_reach(where)
    opw = solver.opw
    if opw is not None:
        q8, ok8 = opw.ik_branches(T_flange)
        if not ok8.any():
            return opw_wrist_reason(opw, T_flange)
        q = q8[ok8]
        lo, hi = chain.lower, chain.upper
        two_pi = 2 * np.pi
        with np.errstate(invalid="ignore"):
            best = np.full(q.shape, np.inf)  # violation of each joint over its 2*pi variants
            for k in (-2, -1, 0, 1, 2):
                qk = q + k * two_pi
                best = np.minimum(best, np.maximum(lo - qk, 0) + np.maximum(qk - hi, 0))
        worst = np.argmax(best, axis=1)  # each candidate's worst joint
        j = int(np.bincount(worst, minlength=q.shape[1]).argmax())
        return _at_limit(chain, j)
    return _no_solution(where)


def opw_wrist_reason(opw: Any, T_flange: FloatArray) -> Reason:
    """Why an OPW arm reaches none of the flange poses ``(R, 4, 4)``: the wrist centre's
    distance from the shoulder against the arm's range ``|c2 - k| .. c2 + k``."""
    return opw_wrist_reasons(opw, T_flange[None])[0]


def opw_wrist_reasons(opw: Any, T_flange: FloatArray) -> list[Reason]:
    """:func:`opw_wrist_reason` of ``P`` points at once, ``T_flange (P, R, 4, 4)``."""
    P = opw.params
    T = invert_transform(opw.T_base_opw) @ T_flange @ invert_transform(opw.T_ee_tip)
    c = T[..., :3, 3] - P.c4 * T[..., :3, 2]
    radial = np.sqrt(np.maximum(c[..., 0] ** 2 + c[..., 1] ** 2 - P.b**2, 0.0))
    k = math.hypot(P.c3, P.a2)
    d = np.minimum(
        np.hypot(radial - P.a1, c[..., 2] - P.c1), np.hypot(radial + P.a1, c[..., 2] - P.c1)
    )
    lo, hi = abs(P.c2 - k), P.c2 + k
    i = np.argmin(np.abs(d - np.clip(d, lo, hi)), axis=1)
    out = []
    for di in d[np.arange(d.shape[0]), i].tolist():
        if di < lo:
            why = f"too close (wrist centre {di:.2f} m from the shoulder, min {lo:.2f} m)"
            out.append(Reason("reach", why))
        else:
            out.append(
                _out_of_reach(f"wrist centre {di:.2f} m from the shoulder, reach {hi:.2f} m")
            )
    return out


def no_ik_reasons(
    model: ReachModel, solver: IKSolver, chain: KinematicChain, T_flange: FloatArray
) -> list[Reason]:
    """:func:`no_ik_reason` of ``P`` points at once: ``T_flange (P, R, 4, 4)``, base frame, m.

    The same reasons as one call per point (``tests/planner/robot/test_reach.py`` compares them),
    with one batched IK call for all points instead of one per point.
    """
    T = np.asarray(T_flange, dtype=np.float64)
    P, R = T.shape[:2]
    if P == 0:
        return []
    p = T[..., :3, 3].reshape(P * R, 3)
    dist = np.min(np.linalg.norm(p - model.shoulder_towards(p), axis=1).reshape(P, R), axis=1)
    out: list[Reason | None] = [None] * P
    rest = []
    for i, di in enumerate(dist.tolist()):
        if di > model.reach_m or solver.opw is None:
            where = f"{di:.2f} m from the shoulder, reach {model.reach_m:.2f} m"
            out[i] = _out_of_reach(where) if di > model.reach_m else _no_solution(where)
        else:
            rest.append(i)
    opw = solver.opw
    if rest and opw is not None:
        idx = np.array(rest)
        q8, ok8 = opw.ik_branches(T[idx].reshape(-1, 4, 4))
        n_j = q8.shape[-1]
        q8 = q8.reshape(len(idx), R * 8, n_j)
        ok8 = ok8.reshape(len(idx), R * 8)
        owner, row = np.nonzero(ok8)
        q = q8[owner, row]  # (K, n): the branches that exist
        lo, hi = chain.lower, chain.upper
        with np.errstate(invalid="ignore"):
            # violation of each joint over its 2*pi variants k = -2..2: the distance of
            # q + 2 pi k to [lo, hi] falls, then rises with k, so its least is at the first
            # variant at or above lo or at the one before it
            two_pi = 2 * np.pi
            k_up = np.clip(np.ceil((lo - q) / two_pi), -2, 2)
            q_up, q_dn = q + k_up * two_pi, q + np.clip(k_up - 1, -2, 2) * two_pi
            best = np.minimum(
                np.maximum(lo - q_up, 0) + np.maximum(q_up - hi, 0),
                np.maximum(lo - q_dn, 0) + np.maximum(q_dn - hi, 0),
            )
        worst = np.argmax(best, axis=1)  # each branch's worst joint
        counts = np.bincount(owner * n_j + worst, minlength=len(idx) * n_j).reshape(-1, n_j)
        any_ok = np.asarray(ok8.any(axis=1), dtype=bool)
        none_ok = np.flatnonzero(~any_ok)
        wrist = opw_wrist_reasons(opw, T[idx[none_ok]]) if none_ok.size else []
        for n, why in zip(none_ok.tolist(), wrist):
            out[rest[n]] = why
        for n in np.flatnonzero(any_ok).tolist():
            j = int(np.argmax(counts[n]))
            out[rest[n]] = _at_limit(chain, j)
    return [s for s in out if s is not None]
