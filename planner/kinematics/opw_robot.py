"""An OPW arm placed in a URDF's frames: base and tip transforms, joint limits, 2*pi variants.

``T_base_tip = T_base_opw @ opw_fk(params, q) @ T_ee_tip``: the OPW frame sits on axis 1 of the
URDF base, the OPW end frame on axis 6, and both constant transforms are derived from the URDF
(:mod:`planner.kinematics.opw_from_urdf`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from calib.frames import invert_transform
from planner.kinematics.opw import OPWParameters, opw_fk, opw_ik

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True, eq=False)
class OPWRobot:
    """An OPW arm with its place in the URDF and its joint limits.

    Attributes:
        params: the OPW parameters (lengths in metres, offsets in rad, sign corrections).
        T_base_opw: the OPW frame in the URDF base frame, ``(4, 4)``.
        T_ee_tip: the chain's tip frame (flange) in the OPW end frame, ``(4, 4)``.
        lower: lower joint limits ``(6,)``, rad (``-inf`` for continuous joints).
        upper: upper joint limits ``(6,)``, rad (``+inf`` for continuous joints).
    """

    params: OPWParameters
    T_base_opw: FloatArray
    T_ee_tip: FloatArray
    lower: FloatArray
    upper: FloatArray

    @property
    def turn_counts(self) -> tuple[int, ...]:
        """``(6,)`` how many values of each joint can give the same pose: ``ceil(range / 360)``.

        A joint whose range exceeds 360 degrees (e.g. ABB axis 6, +-400 deg) reaches the same
        pose at ``q`` and ``q +- 2*pi``; continuous joints (infinite limits) keep one value.
        """
        out = []
        for lo, hi in zip(self.lower, self.upper):
            finite = np.isfinite(lo) and np.isfinite(hi)
            out.append(max(1, int(np.ceil((hi - lo) / (2 * np.pi) - 1e-9))) if finite else 1)
        return tuple(out)

    def fk(self, q: FloatArray) -> FloatArray:
        """``T_base_tip (..., 4, 4)`` of robot joint values ``q (..., 6)``."""
        return self.T_base_opw @ opw_fk(self.params, q) @ self.T_ee_tip

    def ik_branches(self, T_base_tip: FloatArray) -> tuple[FloatArray, BoolArray]:
        """The 8 OPW branches ``q (N, 8, 6)`` wrapped to ``(-pi, pi]`` and ``reachable (N, 8)``.

        Joint limits are not applied; unreachable branches hold NaN.
        """
        T = np.asarray(T_base_tip, dtype=np.float64)
        if not np.array_equal(self.T_base_opw, np.eye(4)):
            T = invert_transform(self.T_base_opw) @ T
        if not np.array_equal(self.T_ee_tip, np.eye(4)):
            T = T @ invert_transform(self.T_ee_tip)
        return opw_ik(self.params, T)

    def solve(self, T_base_tip: FloatArray) -> tuple[FloatArray, BoolArray, NDArray[np.int_]]:
        """All solutions within joint limits, including the 2*pi variants (see :meth:`expand`).

        Args:
            T_base_tip: ``(N, 4, 4)`` tip poses in the base frame.
        """
        return self.expand(*self.ik_branches(T_base_tip))

    def expand(
        self, q8: FloatArray, ok8: BoolArray, min_k: int = 8
    ) -> tuple[FloatArray, BoolArray, NDArray[np.int_]]:
        """Add the 2*pi variants to branches ``q8 (N, 8, 6)``, apply the limits, pack the result.

        Joints whose limits lie within ``[-pi, pi]`` are checked as they are; the others are
        moved to their lowest value ``>= lower`` (modulo 2*pi) and ``turn_counts`` values
        ``+ 2*pi*i`` are tried.

        Returns:
            ``q (N, K, 6)``: each pose's valid solutions first, ordered by OPW branch then by
            variant, NaN after them; ``K = max(min_k, most solutions of any pose)``.
            ``valid (N, K)``: reachable and within the joint limits.
            ``branch (N, K)``: the OPW branch index 0-7 of each solution, -1 where not valid.
        """
        counts = self.turn_counts
        combos = np.array(list(itertools.product(*(range(m) for m in counts))), dtype=int)
        N, V = q8.shape[0], combos.shape[0]
        base = np.ascontiguousarray(np.transpose(q8, (2, 1, 0)))  # (6, 8, N), no copy from opw_ik
        inside = np.ascontiguousarray(ok8.T)  # (8, N): reachable and simple joints in limits
        multi: list[tuple[int, FloatArray, NDArray[np.bool_]]] = []  # (joint, q_lo, ok (m,8,N))
        two_pi = 2.0 * np.pi
        with np.errstate(invalid="ignore"):
            for j, (lo, hi) in enumerate(zip(self.lower, self.upper)):
                qj = base[j]
                if not (np.isfinite(lo) and np.isfinite(hi)):
                    continue
                if counts[j] == 1 and lo >= -np.pi and hi <= np.pi:
                    inside &= (qj >= lo - 1e-12) & (qj <= hi + 1e-12)
                    continue
                q_lo = qj - two_pi * np.floor((qj - lo + 1e-12) * (1.0 / two_pi))
                ok_m = np.stack([q_lo + two_pi * i <= hi + 1e-12 for i in range(counts[j])])
                multi.append((j, q_lo, ok_m))
        full = np.broadcast_to(inside[:, None, :], (8, V, N))
        for j, _, ok_m in multi:
            full = full & ok_m[combos[:, j]].transpose(1, 0, 2)  # (8, V, N)
        flat = np.ascontiguousarray(np.transpose(full, (2, 0, 1))).reshape(N, 8 * V)
        n_idx, kv = np.nonzero(flat)  # row-major: per pose, by branch then variant
        b_idx, v_idx = kv // V, kv % V
        per_pose = np.count_nonzero(flat, axis=1)
        K = max(min_k, int(per_pose.max()) if N else 0)
        rank = np.arange(n_idx.size) - np.repeat(np.cumsum(per_pose) - per_pose, per_pose)
        src = b_idx * N + n_idx  # index into a (8, N) plane
        dest = n_idx * K + rank  # index into an (N, K) plane
        q = np.full((N * K, 6), np.nan)
        for j in range(6):
            q[dest, j] = base[j].ravel()[src]
        for j, q_lo, _ in multi:
            q[dest, j] = q_lo.ravel()[src] + two_pi * combos[v_idx, j]
        valid = np.zeros(N * K, dtype=bool)
        valid[dest] = True
        branch = np.full(N * K, -1, dtype=int)
        branch[dest] = b_idx
        return q.reshape(N, K, 6), valid.reshape(N, K), branch.reshape(N, K)
