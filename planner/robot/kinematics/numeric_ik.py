"""Numerical inverse kinematics for any serial chain: vectorized Levenberg-Marquardt with seeds.

Every target pose is started from several seeds (the caller's, then a fixed, low-discrepancy set
spread over the joint limits, or random ones drawn from an explicit ``rng``). All
``N * seeds`` problems iterate together in numpy: damped least squares on the chain's analytic
geometric Jacobian, a step is kept only when it lowers the pose error (else the damping grows),
and joints are projected into their limits after each step (continuous joints are wrapped to
``[-pi, pi]``). Converged solutions within limits are valid; duplicates are dropped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from calib.arguments import check_shape
from calib.frames import check_transform
from planner.robot.kinematics.chain import KinematicChain

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class NumericIKResult:
    """Solutions of :meth:`NumericIK.solve`.

    Attributes:
        q: joint values ``(N, K, n)``, rad (m for prismatic); NaN where not valid.
        valid: ``(N, K)`` bool: pose error within tolerance, within joint limits, not a duplicate.
        pos_err_m: ``(N, K)`` final position error of each seed's solution, metres.
        rot_err_rad: ``(N, K)`` final rotation error of each seed's solution, radians.
    """

    q: FloatArray
    valid: BoolArray
    pos_err_m: FloatArray
    rot_err_rad: FloatArray


def pose_error(T_target: FloatArray, T: FloatArray) -> FloatArray:
    """Pose errors ``(M, 6)``: position (m), rotation vector of ``R_t R^T`` (rad); base frame."""
    e = np.empty((T.shape[0], 6))
    e[:, :3] = T_target[:, :3, 3] - T[:, :3, 3]
    R_err = T_target[:, :3, :3] @ np.swapaxes(T[:, :3, :3], 1, 2)
    e[:, 3:] = Rotation.from_matrix(R_err).as_rotvec()
    return e


class NumericIK:
    """Seeded, vectorized Levenberg-Marquardt IK on a :class:`KinematicChain`.

    Args:
        chain: the kinematic chain.
        n_seeds: seeds per pose besides the caller's (a fixed Halton set over the limits).
        max_iter: iterations per problem.
        tol_pos_m: position tolerance for a valid solution, metres.
        tol_rot_rad: rotation tolerance for a valid solution, radians.
        rng: when given, the seeds are drawn uniformly within the limits from it instead of the
            fixed Halton set (the solver is deterministic without it).
    """

    def __init__(
        self,
        chain: KinematicChain,
        n_seeds: int = 12,
        max_iter: int = 100,
        tol_pos_m: float = 1e-6,
        tol_rot_rad: float = 1e-6,
        rng: np.random.Generator | None = None,
    ) -> None:
        self.chain = chain
        self.max_iter = int(max_iter)
        self.tol_pos_m = float(tol_pos_m)
        self.tol_rot_rad = float(tol_rot_rad)
        n = chain.n_joints
        self._lo = np.where(np.isfinite(chain.lower), chain.lower, -np.pi)
        self._hi = np.where(np.isfinite(chain.upper), chain.upper, np.pi)
        self._wrap = ~np.isfinite(chain.lower) | ~np.isfinite(chain.upper)
        self._n_seeds = int(n_seeds)
        self._seeds: NDArray[np.float64] | None = None
        if rng is not None:  # drawn now: the caller's generator is used in its order
            self._seeds = self._spread(rng.uniform(size=(int(n_seeds), n)))

    @property
    def seeds(self) -> NDArray[np.float64]:
        """``(n_seeds, n)`` the solver's own start configurations, rad: the middle of the
        limits, then the Halton set (or the caller's random draws) spread over them. The
        Halton set is made on first use: ``scipy.stats`` takes ~0.2 s to import (seconds on a
        loaded machine), and a cell whose arm is OPW never solves numerically."""
        if self._seeds is None:
            from scipy.stats import qmc

            unit = qmc.Halton(d=self.chain.n_joints, scramble=False).random(self._n_seeds + 1)
            self._seeds = self._spread(unit[1:])
        return self._seeds

    def _spread(self, unit: NDArray[np.float64]) -> NDArray[np.float64]:
        """The middle of the limits and ``unit (k, n)`` points of the unit cube over them."""
        mid = 0.5 * (self._lo + self._hi)
        return np.vstack([mid, self._lo + unit * (self._hi - self._lo)])[: max(self._n_seeds, 1)]

    def solve(self, T_base_tip: ArrayLike, seeds: ArrayLike | None = None) -> NumericIKResult:
        """Solve for ``N`` tip poses ``(N, 4, 4)`` (base frame).

        Args:
            T_base_tip: target poses of the chain's tip, ``(N, 4, 4)`` or ``(4, 4)``.
            seeds: extra start configurations tried first, ``(S, n)`` for every pose or
                ``(N, S, n)`` per pose.

        Returns:
            ``K = S + n_seeds`` solutions per pose; see :class:`NumericIKResult`.

        Raises:
            ShapeError, NonFiniteError, DegenerateGeometryError: bad poses or seeds.
        """
        T = check_transform(T_base_tip, "T_base_tip")
        T = T[None] if T.ndim == 2 else T
        N, n = T.shape[0], self.chain.n_joints
        base = np.broadcast_to(self.seeds, (N, *self.seeds.shape))
        if seeds is not None:
            s = np.asarray(seeds, dtype=np.float64)
            s = check_shape(s, (None, n), "seeds") if s.ndim == 2 else s
            s = np.broadcast_to(s, (N, *s.shape)) if s.ndim == 2 else s
            s = check_shape(s, (N, None, n), "seeds")
            base = np.concatenate([s, base], axis=1)
        K = base.shape[1]
        q = self._project(base.reshape(N * K, n).copy())
        T_t = np.repeat(T, K, axis=0)
        q, err = self._iterate(q, T_t)
        pos_err = np.linalg.norm(err[:, :3], axis=1).reshape(N, K)
        rot_err = np.linalg.norm(err[:, 3:], axis=1).reshape(N, K)
        q = q.reshape(N, K, n)
        valid = (
            (pos_err <= self.tol_pos_m)
            & (rot_err <= self.tol_rot_rad)
            & self.chain.within_limits(q)
        )
        valid = _drop_duplicates(q, valid)
        q = np.where(valid[..., None], q, np.nan)
        return NumericIKResult(q, valid, pos_err, rot_err)

    def refine(
        self, q: ArrayLike, T_base_tip: ArrayLike, max_iter: int | None = None
    ) -> tuple[FloatArray, FloatArray]:
        """Polish configurations ``q (M, n)`` towards poses ``(M, 4, 4)`` without joint limits.

        Returns:
            the refined ``q (M, n)`` and the final pose errors ``(M, 6)`` (m, rad).
        """
        qa = np.array(q, dtype=np.float64).reshape(-1, self.chain.n_joints)
        T = np.asarray(T_base_tip, dtype=np.float64).reshape(-1, 4, 4)
        saved = self.max_iter, self._wrap, self._lo, self._hi
        try:
            if max_iter is not None:
                self.max_iter = int(max_iter)
            self._wrap = np.zeros_like(self._wrap)
            self._lo, self._hi = np.full_like(self._lo, -np.inf), np.full_like(self._hi, np.inf)
            return self._iterate(qa, T, lam0=1e-8)
        finally:
            self.max_iter, self._wrap, self._lo, self._hi = saved

    def _project(self, q: FloatArray) -> FloatArray:
        wrapped = (q + np.pi) % (2 * np.pi) - np.pi
        return np.where(self._wrap, wrapped, np.clip(q, self._lo, self._hi))

    def _iterate(
        self, q: FloatArray, T_t: FloatArray, lam0: float = 1e-2
    ) -> tuple[FloatArray, FloatArray]:
        """Levenberg-Marquardt on all problems at once; returns final ``q`` and errors."""
        M, n = q.shape
        lam = np.full(M, lam0)
        T, J = self.chain.fk_jacobian(q)
        err = pose_error(T_t, T)
        cost = np.einsum("mi,mi->m", err, err)
        active = np.ones(M, dtype=bool)
        stop = min(self.tol_pos_m, self.tol_rot_rad) * 1e-4
        eye = np.eye(n)
        for _ in range(self.max_iter):
            active &= cost > stop**2
            idx = np.flatnonzero(active)
            if idx.size == 0:
                break
            Ja, ea = J[idx], err[idx]
            JtJ = np.swapaxes(Ja, 1, 2) @ Ja
            g = np.einsum("mji,mj->mi", Ja, ea)
            dq = np.linalg.solve(JtJ + lam[idx, None, None] * eye, g[..., None])[..., 0]
            q_new = self._project(q[idx] + dq)
            T_new, J_new = self.chain.fk_jacobian(q_new)
            e_new = pose_error(T_t[idx], T_new)
            c_new = np.einsum("mi,mi->m", e_new, e_new)
            better = c_new < cost[idx]
            acc = idx[better]
            q[acc], J[acc], err[acc], cost[acc] = (
                q_new[better],
                J_new[better],
                e_new[better],
                c_new[better],
            )
            lam[acc] = np.maximum(lam[acc] / 3.0, 1e-12)
            rej = idx[~better]
            lam[rej] = lam[rej] * 4.0
            active[rej[lam[rej] > 1e8]] = False  # stuck in a local minimum
        return q, err


def _drop_duplicates(q: FloatArray, valid: BoolArray, tol_rad: float = 1e-4) -> BoolArray:
    """Keep the first of valid solutions closer than ``tol_rad`` in every joint (per pose)."""
    d = np.abs(q[:, :, None, :] - q[:, None, :, :]).max(axis=-1)  # (N, K, K)
    K = q.shape[1]
    earlier = np.tril(np.ones((K, K), dtype=bool), k=-1)  # [i, j] true when j < i
    dup = (d < tol_rad) & earlier[None] & valid[:, None, :]
    return valid & ~dup.any(axis=2)
