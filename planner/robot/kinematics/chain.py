"""A serial kinematic chain from a URDF: joint limits, vectorized forward kinematics, Jacobian.

Fixed joints are folded into constant transforms when the chain is built, so ``fk`` does one
constant product and one joint motion per moving joint, for all ``N`` configurations at once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_shape
from planner.errors import UnknownFrameError, URDFError
from planner.robot.urdf import Joint, URDFModel, load_urdf

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class KinematicChain:
    """A serial chain of moving joints from ``base_link`` to ``tip_link`` (URDF frames).

    Attributes:
        name: the robot name from the URDF.
        base_link: link whose frame is ``base``; every pose is expressed in it.
        tip_link: link whose frame is the chain's tip (``tool0``, the flange, when present).
        joint_names: the moving joints, base to tip, ``(n,)``.
        joint_types: ``"revolute"``, ``"continuous"`` or ``"prismatic"`` per joint.
        axes: unit joint axes in each joint's own frame, ``(n, 3)``.
        T_prev_joint: constant transform from the previous moving joint's frame (after its
            motion; ``base`` for the first) to this joint's frame at zero, ``(n, 4, 4)``.
        T_last_tip: constant transform from the last moving joint's frame to the tip, ``(4, 4)``.
        lower: lower joint limits, ``(n,)``, rad (m for prismatic); ``-inf`` for continuous.
        upper: upper joint limits, ``(n,)``; ``+inf`` for continuous.
        link_attach: for every link rigidly attached to the chain: ``(k, T_jointk_link)`` with
            ``k`` the index of the moving joint the link follows (``-1``: the base).
        urdf_path: the file the chain came from (``None`` when built from a parsed model).
    """

    name: str
    base_link: str
    tip_link: str
    joint_names: tuple[str, ...]
    joint_types: tuple[str, ...]
    axes: FloatArray
    T_prev_joint: FloatArray
    T_last_tip: FloatArray
    lower: FloatArray
    upper: FloatArray
    link_attach: dict[str, tuple[int, FloatArray]] = field(repr=False)
    urdf_path: Path | None = None

    @property
    def n_joints(self) -> int:
        """Number of moving joints."""
        return len(self.joint_names)

    @classmethod
    def from_urdf(
        cls, path: str | Path, base_link: str | None = None, tip_link: str | None = None
    ) -> KinematicChain:
        """Build the chain of a URDF file (meshes need not exist for kinematics).

        Args:
            path: the URDF file.
            base_link: the base link; default the URDF's root link.
            tip_link: the tip link; default ``tool0`` when it is below ``base_link``, else the
                last link of the longest serial chain below ``base_link``.

        Raises:
            URDFError: the file is invalid, the chain holds a floating or planar joint, or it has
                no moving joint (e.g. a URDF of one link).
            UnknownFrameError: ``base_link`` or ``tip_link`` is not a link of the URDF.
        """
        return cls.from_model(load_urdf(path, check_meshes=False), base_link, tip_link)

    @classmethod
    def from_model(
        cls, model: URDFModel, base_link: str | None = None, tip_link: str | None = None
    ) -> KinematicChain:
        """Build the chain of a parsed :class:`URDFModel` (see :meth:`from_urdf`)."""
        names = model.link_names
        for arg, val in (("base_link", base_link), ("tip_link", tip_link)):
            if val is not None and val not in names:
                raise UnknownFrameError(
                    f"{arg} {val!r} is not a link of {model._where()}; links are {list(names)}"
                )
        base = base_link or model.root
        tip = tip_link or _default_tip(model, base)
        joints = model.joints_between(base, tip)
        where = model._where()
        moving: list[Joint] = []
        pending = np.eye(4)
        pre: list[FloatArray] = []
        attach: dict[str, tuple[int, FloatArray]] = {base: (-1, np.eye(4))}
        for j in joints:
            if j.type in ("floating", "planar"):
                raise URDFError(
                    f"{where}: joint {j.name!r} is {j.type}; a chain needs 1-DOF joints"
                )
            if j.is_moving:
                pre.append(pending @ j.T_parent_joint)
                moving.append(j)
                pending = np.eye(4)
                attach[j.child] = (len(moving) - 1, np.eye(4))
            else:
                pending = pending @ j.T_parent_joint
                attach[j.child] = (len(moving) - 1, pending.copy())
        if not moving:
            raise URDFError(
                f"{where}: no moving joint between base link {base!r} and tip link {tip!r}; "
                "a robot chain needs at least one revolute, continuous or prismatic joint"
            )
        _attach_fixed_subtrees(model, attach)
        lower = np.array([j.limit.lower if j.limit else -np.inf for j in moving])
        upper = np.array([j.limit.upper if j.limit else np.inf for j in moving])
        return cls(
            name=model.name,
            base_link=base,
            tip_link=tip,
            joint_names=tuple(j.name for j in moving),
            joint_types=tuple(j.type for j in moving),
            axes=np.array([j.axis for j in moving], dtype=float).reshape(-1, 3),
            T_prev_joint=np.array(pre).reshape(-1, 4, 4),
            T_last_tip=pending,
            lower=lower,
            upper=upper,
            link_attach=attach,
            urdf_path=model.path,
        )

    def check_q(self, q: ArrayLike, name: str = "q") -> FloatArray:
        """Return ``q`` as a finite ``(N, n)`` array (a single ``(n,)`` becomes ``(1, n)``)."""
        arr = np.asarray(q, dtype=np.float64) if not isinstance(q, np.ndarray) else q
        if arr.ndim == 1:
            arr = arr[None, :]
        return check_shape(arr, (None, self.n_joints), name)

    def within_limits(self, q: ArrayLike, tol: float = 1e-9) -> NDArray[np.bool_]:
        """Mask ``(...,)`` of configurations inside ``[lower - tol, upper + tol]``."""
        qa = np.asarray(q, dtype=np.float64)
        return np.all((qa >= self.lower - tol) & (qa <= self.upper + tol), axis=-1)

    def joint_frames(self, q: ArrayLike) -> FloatArray:
        """``T_base_jointk`` after each joint's motion, ``(N, n, 4, 4)``."""
        qa = self.check_q(q)
        N = qa.shape[0]
        T = np.broadcast_to(np.eye(4), (N, 4, 4))
        out = np.empty((N, self.n_joints, 4, 4))
        motions = self._motions(qa)
        for k in range(self.n_joints):
            T = T @ self.T_prev_joint[k] @ motions[:, k]
            out[:, k] = T
        return out

    def fk(self, q: ArrayLike) -> FloatArray:
        """Forward kinematics ``T_base_tip`` ``(N, 4, 4)`` of configurations ``q`` ``(N, n)``.

        A single configuration ``(n,)`` gives ``(1, 4, 4)``.

        Raises:
            ShapeError: ``q`` is not ``(N, n)``; NonFiniteError: ``q`` holds NaN or infinity.
        """
        qa = self.check_q(q)
        T = np.broadcast_to(np.eye(4), (qa.shape[0], 4, 4))
        motions = self._motions(qa)
        for k in range(self.n_joints):
            T = T @ self.T_prev_joint[k] @ motions[:, k]
        return T @ self.T_last_tip

    def fk_jacobian(self, q: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Tip poses ``(N, 4, 4)`` and geometric Jacobians ``(N, 6, n)`` in the base frame.

        Rows 0-2 of the Jacobian are the tip's linear velocity (m per rad or m per m), rows 3-5
        its angular velocity, for unit joint velocities.
        """
        frames = self.joint_frames(q)
        T_tip = frames[:, -1] @ self.T_last_tip if self.n_joints else self.fk(q)
        axes_b = np.einsum("nkij,kj->nki", frames[:, :, :3, :3], self.axes)
        lever = T_tip[:, None, :3, 3] - frames[:, :, :3, 3]
        prismatic = np.array([t == "prismatic" for t in self.joint_types])
        J = np.empty((frames.shape[0], 6, self.n_joints))
        J[:, :3, :] = np.where(prismatic[None, :, None], axes_b, np.cross(axes_b, lever)).transpose(
            0, 2, 1
        )
        J[:, 3:, :] = np.where(prismatic[None, :, None], 0.0, axes_b).transpose(0, 2, 1)
        return T_tip, J

    def link_poses(self, q: ArrayLike) -> dict[str, FloatArray]:
        """``T_base_link`` ``(N, 4, 4)`` of every link rigidly attached to the chain.

        Includes the chain's links and links hanging off them through fixed joints.
        """
        frames = self.joint_frames(q)
        N = frames.shape[0]
        out = {}
        for name, (k, T_const) in self.link_attach.items():
            out[name] = (
                np.broadcast_to(T_const, (N, 4, 4)).copy() if k < 0 else frames[:, k] @ T_const
            )
        return out

    def _motions(self, q: FloatArray) -> FloatArray:
        """Every joint's motion transform ``(N, n, 4, 4)`` for configurations ``q (N, n)``:
        Rodrigues' formula for revolute joints, a translation along the axis for prismatic
        ones (all joints at once; the same arithmetic as one joint at a time)."""
        N, n = q.shape
        M = np.zeros((N, n, 4, 4))
        M[..., 3, 3] = 1.0
        K, KK, prismatic = self._axis_matrices()
        s, c = np.sin(q)[..., None, None], np.cos(q)[..., None, None]
        M[..., :3, :3] = np.eye(3) + s * K + (1.0 - c) * KK
        if prismatic.any():
            M[:, prismatic, :3, :3] = np.eye(3)
            M[:, prismatic, :3, 3] = q[:, prismatic, None] * self.axes[prismatic]
        return M

    def _axis_matrices(self) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
        """``(K (n, 3, 3), K @ K, prismatic (n,))``: each axis's cross-product matrix."""
        cached = self.__dict__.get("_axis_cache")
        if cached is None:
            a = np.asarray(self.axes, dtype=np.float64).reshape(-1, 3)
            K = np.zeros((a.shape[0], 3, 3))
            K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -a[:, 2], a[:, 1], -a[:, 0]
            K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = a[:, 2], -a[:, 1], a[:, 0]
            prismatic = np.array([t == "prismatic" for t in self.joint_types], dtype=bool)
            cached = (K, np.stack([k @ k for k in K]), prismatic)  # as one joint at a time
            object.__setattr__(self, "_axis_cache", cached)
        return cached


def _default_tip(model: URDFModel, base: str) -> str:
    """``tool0`` when below ``base``; else the deepest leaf (most moving joints, then joints)."""
    below: dict[str, tuple[int, int]] = {base: (0, 0)}
    frontier = [base]
    while frontier:
        link = frontier.pop()
        for j in model.children(link):
            d_mov, d_all = below[link]
            below[j.child] = (d_mov + int(j.is_moving), d_all + 1)
            frontier.append(j.child)
    if "tool0" in below:
        return "tool0"
    order = {n: i for i, n in enumerate(model.link_names)}
    return max(below, key=lambda n: (*below[n], -order[n]))


def _attach_fixed_subtrees(model: URDFModel, attach: dict[str, tuple[int, FloatArray]]) -> None:
    """Add links hanging off chain links through fixed joints only (in place)."""
    frontier = list(attach)
    while frontier:
        link = frontier.pop()
        k, T = attach[link]
        for j in model.children(link):
            if j.type == "fixed" and j.child not in attach:
                attach[j.child] = (k, T @ j.T_parent_joint)
                frontier.append(j.child)
