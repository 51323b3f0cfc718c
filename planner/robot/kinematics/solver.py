"""One IK entry point for any chain: analytic OPW when the robot qualifies, numeric otherwise.

    solver = make_ik_solver(chain)          # solver.kind is "opw" or "numeric"
    sol = solver.solve(T_base_flange)       # (N, 4, 4) in, IKSolutions(q (N, K, n), valid (N, K))

``solver.why_not_opw`` says why the analytic solver was not used (``None`` when it was).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import as_float_array, check_finite
from calib.errors import DegenerateGeometryError, ShapeError
from planner.robot.kinematics.branches import BranchFlags, classify
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.numeric_ik import NumericIK
from planner.robot.kinematics.opw import wrap_angle
from planner.robot.kinematics.opw_from_urdf import NotOPWError, opw_from_chain
from planner.robot.kinematics.opw_robot import OPWRobot

#: A nearly-OPW arm (axes within this many m / sines of an angle of the ideal) whose OPW model
#: is within ``APPROX_FK_TOL`` of its FK still takes the analytic path, with numeric polishing.
APPROX_GEOM_TOL = 1e-4
APPROX_FK_TOL = 1e-3
#: Levenberg-Marquardt iterations that polish the branches of an approximate OPW model.
POLISH_ITER = 50

log = logging.getLogger(__name__)

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class IKSolutions:
    """Inverse-kinematics solutions of ``N`` flange poses.

    Attributes:
        q: joint values ``(N, K, n)``, rad (robot joint convention of the URDF); NaN where
            ``valid`` is False, so a forgotten mask cannot pass as a solution. For OPW arms each
            pose's solutions come first (by branch, then 2*pi variant) and ``K`` is the largest
            number of solutions of any pose in the batch (at least 8); for the numeric solver
            ``K`` is the number of seeds.
        valid: ``(N, K)`` bool: reaches the pose (1e-6 m, 1e-6 rad or better) within joint limits.
        branch: ``(N, K)`` int: for 6-axis OPW arms the configuration index 0-7 (ABB ``cfx``:
            4 * shoulder behind + 2 * wrist centre behind the lower arm + axis 5 negative, see
            :mod:`planner.robot.kinematics.branches`); -1 for numeric solutions and invalid entries.
    """

    q: FloatArray
    valid: NDArray[np.bool_]
    branch: NDArray[np.int_]

    @property
    def found(self) -> NDArray[np.bool_]:
        """``(N,)`` bool: at least one valid solution per pose."""
        return np.asarray(self.valid.any(axis=1), dtype=bool)

    def nearest(self, q_ref: ArrayLike) -> tuple[FloatArray, NDArray[np.bool_]]:
        """The valid solution closest to ``q_ref`` ``(n,)`` or ``(N, n)`` (max-abs joint distance).

        Returns:
            ``q (N, n)`` (NaN where none is valid) and ``found (N,)``.
        """
        ref = np.broadcast_to(np.asarray(q_ref, dtype=np.float64), self.q[:, 0].shape)
        d = np.where(self.valid, np.abs(self.q - ref[:, None]).max(axis=-1), np.inf)
        k = np.argmin(d, axis=1)
        q = self.q[np.arange(self.q.shape[0]), k]
        return q, self.found


def check_poses(value: ArrayLike, name: str, tol: float = 1e-6) -> FloatArray:
    """``value`` as ``(N, 4, 4)`` rigid transforms (a single ``(4, 4)`` becomes ``(1, 4, 4)``).

    The same checks as :func:`calib.frames.check_transform`, written element-wise over the
    sixteen matrix entries for speed (the IK handles over a million poses per second).

    Raises:
        ShapeError: not ``(N, 4, 4)`` or ``(4, 4)``, or the last row is not ``(0, 0, 0, 1)``.
        NonFiniteError: NaN or infinity.
        DegenerateGeometryError: a rotation part is not orthonormal with determinant +1.
    """
    return check_pose_entries(value, name, tol)[0]


def check_pose_entries(
    value: ArrayLike, name: str, tol: float = 1e-6
) -> tuple[FloatArray, FloatArray]:
    """:func:`check_poses`, also returning the entries: ``e[4 i + j]`` is ``T[:, i, j]``."""
    T = as_float_array(value, name)
    if T.ndim == 2:
        T = T[None]
    if T.ndim != 3 or T.shape[1:] != (4, 4):
        raise ShapeError(f"{name} must be (N, 4, 4) or (4, 4), got shape {np.shape(value)}")
    check_finite(T, name)
    e = np.ascontiguousarray(T.reshape(-1, 16).T)
    last = max(
        (float(np.abs(e[12 + j] - (j == 3)).max(initial=0.0)) for j in range(4)), default=0.0
    )
    if last > tol:
        raise ShapeError(f"{name} last row must be (0, 0, 0, 1)")
    c0, c1, c2 = e[0:12:4], e[1:12:4], e[2:12:4]  # the rotation's columns, (3, N) each
    worst = 0.0
    for a, b, target in (
        (c0, c0, 1.0),
        (c1, c1, 1.0),
        (c2, c2, 1.0),
        (c0, c1, 0.0),
        (c0, c2, 0.0),
        (c1, c2, 0.0),
    ):
        d = a[0] * b[0]
        d += a[1] * b[1]
        d += a[2] * b[2]
        d -= target
        worst = max(worst, float(np.abs(d).max(initial=0.0)))
    if worst > tol:
        raise DegenerateGeometryError(
            f"{name} rotation part is not orthonormal (max |R^T R - I| = {worst:.3g})"
        )
    det = (c0[1] * c1[2] - c0[2] * c1[1]) * c2[0]  # det R = (c0 x c1) . c2
    det += (c0[2] * c1[0] - c0[0] * c1[2]) * c2[1]
    det += (c0[0] * c1[1] - c0[1] * c1[0]) * c2[2]
    if np.any(det < 0):
        raise DegenerateGeometryError(f"{name} rotation part is a reflection (det < 0)")
    return T, e


class IKSolver:
    """Inverse kinematics of one chain (build with :func:`make_ik_solver`).

    Attributes:
        chain: the kinematic chain; poses are ``T_base_tip`` of it (the flange for ``tool0``).
        kind: ``"opw"`` (analytic, all branches) or ``"numeric"`` (seeded Levenberg-Marquardt).
        why_not_opw: why the analytic solver does not apply; ``None`` when ``kind == "opw"``.
        opw: the OPW model (``None`` for numeric).
        opw_exact: the OPW model reproduces the chain's FK within 1e-9; when False (a nearly-OPW
            URDF, e.g. rpy rounded to 4 digits) every branch is polished numerically on the
            chain, so solutions are exact for the URDF as written.
    """

    def __init__(
        self,
        chain: KinematicChain,
        numeric: NumericIK,
        opw: OPWRobot | None = None,
        why_not_opw: str | None = None,
        opw_exact: bool = True,
    ) -> None:
        self.chain = chain
        self.opw = opw
        self.kind = "opw" if opw is not None else "numeric"
        self.why_not_opw = why_not_opw
        self.opw_exact = opw_exact and opw is not None
        self._numeric = numeric

    def solve(self, T_base_flange: ArrayLike, seeds: ArrayLike | None = None) -> IKSolutions:
        """All solutions found for flange poses ``(N, 4, 4)`` (or one ``(4, 4)``).

        Args:
            T_base_flange: target tip poses in the base frame.
            seeds: start configurations for the numeric solver, ``(S, n)`` or ``(N, S, n)``;
                ignored by the analytic solver, which returns every branch anyway.

        Raises:
            ShapeError, NonFiniteError, DegenerateGeometryError: the poses are not valid
                rigid transforms (wrong shape, NaN, non-orthonormal rotation).
        """
        T, entries = check_pose_entries(T_base_flange, "T_base_flange")
        if self.opw is not None:
            # bits 4 and 2 of the OPW branch index are the geometric shoulder / elbow flags
            # (wrist centre behind axis 1 / behind the lower arm); bit 1 is axis 5's sign
            if self.opw_exact:
                return IKSolutions(*self.opw.solve(T, config_codes=True, entries=entries))
            q8, ok8 = self._polish(T, *self.opw.ik_branches(T))
            return IKSolutions(*self.opw.expand(q8, ok8, config_codes=True))
        res = self._numeric.solve(T, seeds)
        branch = np.full(res.valid.shape, -1, dtype=int)
        return IKSolutions(res.q, res.valid, branch)

    def _polish(
        self, T: FloatArray, q8: FloatArray, ok8: NDArray[np.bool_]
    ) -> tuple[FloatArray, NDArray[np.bool_]]:
        """Refine the branches of an approximate OPW model on the chain (Levenberg-Marquardt)."""
        q8 = np.array(q8)  # writable copy
        n_idx, b_idx = np.nonzero(ok8)
        if n_idx.size:
            q, err = self._numeric.refine(q8[n_idx, b_idx], T[n_idx], POLISH_ITER)
            good = (np.linalg.norm(err[:, :3], axis=1) <= self._numeric.tol_pos_m) & (
                np.linalg.norm(err[:, 3:], axis=1) <= self._numeric.tol_rot_rad
            )
            q8[n_idx, b_idx] = np.where(good[:, None], wrap_angle(q), np.nan)
            ok8 = ok8.copy()
            ok8[n_idx, b_idx] = good
        return q8, ok8

    def classify(self, q: ArrayLike) -> BranchFlags:
        """Shoulder, elbow and wrist flags of ``q (6,)`` (OPW arms only).

        Raises:
            NotOPWError: the chain is not an OPW arm (the message says why).
        """
        if self.opw is None:
            raise NotOPWError(f"branches are defined for OPW arms only: {self.why_not_opw}")
        return classify(self.opw, q)

    def abb_confdata(self, q: ArrayLike) -> tuple[int, int, int, int]:
        """ABB ``confdata`` ``(cf1, cf4, cf6, cfx)`` of ``q (6,)`` (OPW arms only)."""
        from planner.robot.kinematics.branches import abb_confdata

        if self.opw is None:
            raise NotOPWError(f"confdata needs an OPW arm: {self.why_not_opw}")
        return abb_confdata(q, self.opw)


def make_ik_solver(
    chain: KinematicChain, n_seeds: int = 12, rng: np.random.Generator | None = None
) -> IKSolver:
    """The best IK solver for ``chain``: OPW when it qualifies, else numeric.

    Args:
        chain: the kinematic chain (tip = flange).
        n_seeds: seeds per pose of the numeric solver.
        rng: random seeds for the numeric solver (default: a fixed low-discrepancy set).
    """
    numeric = NumericIK(chain, n_seeds=n_seeds, rng=rng)
    try:
        opw = opw_from_chain(chain)
    except NotOPWError as exc:
        try:
            approx = opw_from_chain(chain, tol=APPROX_GEOM_TOL, verify_tol=APPROX_FK_TOL)
        except NotOPWError:
            log.info("IK for %s: numeric, not OPW: %s", chain.name, exc)
            return IKSolver(chain, numeric, None, str(exc))
        log.info("IK for %s: nearly OPW (%s), analytic + polishing", chain.name, exc)
        return IKSolver(chain, numeric, approx, None, opw_exact=False)
    log.info("IK for %s: analytic OPW %s", chain.name, opw.params)
    return IKSolver(chain, numeric, opw, None)
