"""An OPW arm placed in a URDF's frames: base and tip transforms, joint limits, 2*pi variants.

``T_base_tip = T_base_opw @ opw_fk(params, q) @ T_ee_tip``: the OPW frame sits on axis 1 of the
URDF base, the OPW end frame on axis 6, and both constant transforms are derived from the URDF
(:mod:`planner.robot.kinematics.opw_from_urdf`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from calib.frames import invert_transform
from planner.robot.kinematics.opw import OPWParameters, opw_fk, opw_ik
from planner.robot.kinematics.opw_limited import opw_ik_within
from planner.robot.kinematics.packing import JointLimits, assemble, select_rows

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Poses per batch in :meth:`OPWRobot.solve`: its temporaries then fit the CPU cache.
CHUNK = 4096


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
        return opw_ik(self.params, self._to_opw(np.asarray(T_base_tip, dtype=np.float64)))

    def solve(
        self,
        T_base_tip: FloatArray,
        config_codes: bool = False,
        min_k: int = 8,
        entries: FloatArray | None = None,
    ) -> tuple[FloatArray, BoolArray, NDArray[np.int_]]:
        """All solutions within joint limits, including the 2*pi variants (see :meth:`expand`).

        Bit for bit the result of ``expand(*ik_branches(T))``, computed faster: the wrist is
        solved only for arm solutions within the limits of axes 1-3
        (:func:`planner.robot.kinematics.opw_limited.opw_ik_within`), in batches of ``CHUNK`` poses
        so that the temporaries stay in the CPU cache.

        Args:
            T_base_tip: ``(N, 4, 4)`` tip poses in the base frame.
            config_codes: ``branch`` holds configuration codes ``(b & 6) + (axis 5 < 0)``
                (see :class:`planner.robot.kinematics.solver.IKSolutions`) instead of branch
                indices.
            min_k: the smallest ``K`` returned.
            entries: ``T_base_tip`` entry-major, ``(16, N)`` (row ``4 i + j`` is
                ``T[:, i, j]``), when the caller has it already.
        """
        T = np.asarray(T_base_tip, dtype=np.float64)
        parts = []
        for s in range(0, T.shape[0], CHUNK):
            if entries is not None and self._at_base:
                e = entries[:, s : s + CHUNK]
            else:
                Tc = self._to_opw(T[s : s + CHUNK])
                e = np.ascontiguousarray(Tc.reshape(-1, 16).T)
            parts.append(opw_ik_within(self.params, e, self._limits, config_codes))
        return assemble(parts, min_k)

    def expand(
        self, q8: FloatArray, ok8: BoolArray, min_k: int = 8, config_codes: bool = False
    ) -> tuple[FloatArray, BoolArray, NDArray[np.int_]]:
        """Add the 2*pi variants to branches ``q8 (N, 8, 6)``, apply the limits, pack the result.

        Joints whose limits lie within ``[-pi, pi]`` are checked as they are; the others are
        moved to their lowest value ``>= lower`` (modulo 2*pi) and ``turn_counts`` values
        ``+ 2*pi*i`` are tried (:mod:`planner.robot.kinematics.packing`).

        Returns:
            ``q (N, K, 6)``: each pose's valid solutions first, ordered by OPW branch then by
            variant, NaN after them; ``K = max(min_k, most solutions of any pose)``.
            ``valid (N, K)``: reachable and within the joint limits.
            ``branch (N, K)``: the OPW branch index 0-7 of each solution (or with
            ``config_codes`` its configuration code), -1 where not valid.
        """
        N = q8.shape[0]
        rows = np.array(q8, dtype=np.float64).reshape(8 * N, 6)  # select_rows overwrites both
        inside = np.array(ok8, dtype=bool).reshape(8 * N)
        pose = np.repeat(np.arange(N), 8)
        branch = np.tile(np.arange(8), N)
        sel = select_rows(self._limits, rows, inside, pose, branch, N, config_codes)
        return assemble([sel], min_k)

    def _to_opw(self, T_base_tip: FloatArray) -> FloatArray:
        """``T_opw_ee (N, 4, 4)`` of tip poses in the base frame."""
        T = T_base_tip
        if not np.array_equal(self.T_base_opw, np.eye(4)):
            T = invert_transform(self.T_base_opw) @ T
        if not np.array_equal(self.T_ee_tip, np.eye(4)):
            T = T @ invert_transform(self.T_ee_tip)
        return T

    @cached_property
    def _at_base(self) -> bool:
        """The OPW frame is the base frame and the end frame is the tip (no transforms)."""
        return bool(
            np.array_equal(self.T_base_opw, np.eye(4)) and np.array_equal(self.T_ee_tip, np.eye(4))
        )

    @cached_property
    def _limits(self) -> JointLimits:
        return JointLimits.of(self.lower, self.upper, self.turn_counts)
