"""Observability of a point layout: does it pin down all 6 DOF of the work object, and how well?

Before anything is measured, the nominal points and normals give the constraint Jacobian
``J (M, 6)`` of the point-to-plane residuals with respect to a small motion of the wobj frame
(rows ``[n, (p - c) x n / L]``, rotations taken about the layout centroid ``c`` and scaled by
the layout size ``L`` so every column is dimensionless). Its singular values say how strongly
each combination of motions is constrained; a (near) zero one is a motion no measurement sees.

Each unconstrained motion is named in words, trying in turn: translation along a wobj axis,
rotation about a wobj axis through the origin, rotation about an axis parallel to a wobj axis,
and finally a general direction, rotation axis or screw.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from calib.errors import UnobservableError
from calib.estimators.layout import ConstraintSet, axis_name, constraint_set
from calib.probing import ProbePoint

FloatArray = NDArray[np.float64]

#: Singular values below this (relative to 1) count as zero: the motion is unconstrained.
RANK_TOL = 1e-6
#: A layout whose noise gain (1 / smallest scaled singular value) exceeds this is "weak".
WEAK_NOISE_GAIN = 10.0
_AXES = "xyz"


@dataclass(frozen=True)
class UnconstrainedMotion:
    """One motion of the wobj frame that no constraint sees.

    Attributes:
        name: short name, e.g. ``"translation along wobj z"``.
        explanation: why, e.g. ``"no point lies on a face whose normal has a z component"``.
        motion: ``(6,)`` unit small motion ``(dx, dy, dz, rx, ry, rz)`` in the wobj frame's own
            axes, rotations about the wobj origin (m, rad; normalised as a whole).
    """

    name: str
    explanation: str
    motion: FloatArray

    @property
    def message(self) -> str:
        """``"<name> is not constrained: <explanation>"``."""
        return f"{self.name} is not constrained: {self.explanation}"


@dataclass(frozen=True)
class ObservabilityReport:
    """How well a point layout constrains the 6 DOF of the wobj frame.

    Attributes:
        rank: number of constrained DOF (0-6).
        singular_values: ``(6,)`` singular values of the scaled constraint Jacobian, descending
            (dimensionless; translations in m, rotations in rad times ``scale_m``).
        scale_m: layout size used to scale rotations, metres.
        noise_gain: worst-case frame error per unit measurement noise,
            ``1 / smallest singular value`` (``inf`` when unobservable).
        rating: ``"ok"``, ``"weak"`` (noise gain above :data:`WEAK_NOISE_GAIN`) or
            ``"unobservable"``.
        unconstrained: the unconstrained motions, named (empty when observable).
        problems: layout-level diagnoses, e.g. ``"all 4 points lie on one line"``.
    """

    rank: int
    singular_values: FloatArray
    scale_m: float
    noise_gain: float
    rating: Literal["ok", "weak", "unobservable"]
    unconstrained: tuple[UnconstrainedMotion, ...]
    problems: tuple[str, ...]

    @property
    def observable(self) -> bool:
        """True when all 6 DOF are constrained."""
        return self.rank == 6

    @property
    def messages(self) -> tuple[str, ...]:
        """One sentence per problem and unconstrained motion, for a UI or a log."""
        return self.problems + tuple(m.message for m in self.unconstrained)


def scaled_jacobian(cs: ConstraintSet) -> FloatArray:
    """``(M, 6)`` dimensionless constraint Jacobian at the nominal layout (centroid, scaled)."""
    lever = np.cross(cs.nominal_m - cs.centroid_m, cs.normals) / cs.scale_m
    return np.concatenate([cs.normals, lever], axis=1)


def analyze_layout(points: Sequence[ProbePoint] | ConstraintSet) -> ObservabilityReport:
    """Inspect a nominal point layout before measuring.

    Args:
        points: the probe points (or a prepared :class:`ConstraintSet`).

    Returns:
        The report; it does not raise for an unobservable layout (see :func:`require_observable`).

    Raises:
        InputError: bad points (not ProbePoints, duplicate ids, coincident points).
    """
    cs = constraint_set(points)
    J = scaled_jacobian(cs)
    if J.shape[0] < 6:
        J = np.concatenate([J, np.zeros((6 - J.shape[0], 6))], axis=0)
    _, s, Vt = np.linalg.svd(J, full_matrices=True)
    s = s[:6]
    null = Vt[s < RANK_TOL].T  # (6, k) in scaled centroid coordinates
    rank = 6 - null.shape[1]
    noise_gain = float(np.inf) if rank < 6 else 1.0 / float(s[-1])
    if rank < 6:
        rating: Literal["ok", "weak", "unobservable"] = "unobservable"
    elif noise_gain > WEAK_NOISE_GAIN:
        rating = "weak"
    else:
        rating = "ok"
    motions = _name_null_space(null, cs) if rank < 6 else ()
    return ObservabilityReport(
        rank=rank,
        singular_values=s,
        scale_m=cs.scale_m,
        noise_gain=noise_gain,
        rating=rating,
        unconstrained=motions,
        problems=_layout_problems(cs) if rank < 6 else (),
    )


def require_observable(points: Sequence[ProbePoint] | ConstraintSet) -> ObservabilityReport:
    """Like :func:`analyze_layout` but raise when a DOF is unconstrained.

    Raises:
        UnobservableError: naming each unconstrained motion (also in ``.unconstrained``).
    """
    report = analyze_layout(points)
    if not report.observable:
        raise unobservable_error(report, "the point layout")
    return report


def unobservable_error(report: ObservabilityReport, what: str) -> UnobservableError:
    """Build the :class:`UnobservableError` for an unobservable ``report``."""
    detail = "; ".join(report.messages)
    return UnobservableError(
        f"{what} constrains only {report.rank} of 6 DOF: {detail}",
        unconstrained=tuple(m.name for m in report.unconstrained),
    )


def _layout_problems(cs: ConstraintSet) -> tuple[str, ...]:
    out: list[str] = []
    n = cs.n_points
    if n >= 2:
        centred = cs.positions_m - cs.centroid_m
        sv = np.linalg.svd(centred, compute_uv=False)
        if n >= 3 and sv[1] < 1e-9 * max(sv[0], 1e-12):
            out.append(f"all {n} points lie on one line")
    nn = np.linalg.svd(cs.normals, compute_uv=False)
    if cs.n_constraints >= 2 and nn[1] < 1e-6 * nn[0]:
        out.append("all faces are parallel (every constraint normal is the same direction)")
    return tuple(out)


def _to_scaled(t: FloatArray, w: FloatArray, cs: ConstraintSet) -> FloatArray:
    """Origin-based motion ``(t, w)`` -> scaled centroid coordinates, normalised."""
    v = np.concatenate([t + np.cross(w, cs.centroid_m), w * cs.scale_m])
    return v / np.linalg.norm(v)


def _to_origin(v: FloatArray, cs: ConstraintSet) -> FloatArray:
    """Scaled centroid coordinates -> origin-based ``(t, w)`` (m, rad), unit norm."""
    w = v[3:] / cs.scale_m
    t = v[:3] - np.cross(w, cs.centroid_m)
    out = np.concatenate([t, w])
    return out / np.linalg.norm(out)


def _name_null_space(null: FloatArray, cs: ConstraintSet) -> tuple[UnconstrainedMotion, ...]:
    k = null.shape[1]
    found: list[FloatArray] = []  # orthonormalised, scaled coordinates
    out: list[UnconstrainedMotion] = []
    proj = null @ null.T

    def accept(v: FloatArray, name: str, why: str) -> bool:
        r = v - sum((f @ v) * f for f in found) if found else v
        if np.linalg.norm(v - proj @ v) > 1e-6 or np.linalg.norm(r) < 0.5:
            return False
        found.append(r / np.linalg.norm(r))
        out.append(UnconstrainedMotion(name, why, _to_origin(v, cs)))
        return True

    eye = np.eye(3)
    for j in range(3):
        accept(
            _to_scaled(eye[j], np.zeros(3), cs),
            f"translation along wobj {_AXES[j]}",
            f"no point lies on a face whose normal has a {_AXES[j]} component",
        )
    for j in range(3):
        accept(
            _to_scaled(np.zeros(3), eye[j], cs),
            f"rotation about wobj {_AXES[j]}",
            f"every probe normal line meets or is parallel to the wobj {_AXES[j]} axis",
        )
    for j in range(3):
        if len(out) == k:
            break
        v = _rotation_parallel_to(null, eye[j], cs, found)
        if v is None:
            continue
        t, w = _split(v, cs)
        if abs(float(w @ t)) > 1e-9 * float(w @ w) * cs.scale_m:  # a screw: named below
            continue
        accept(
            v,
            f"rotation about an axis parallel to wobj {_AXES[j]} through {_mm(_axis_point(v, cs))}",
            "every probe normal line meets or is parallel to that axis",
        )
    if len(out) < k:
        rest = null - np.stack(found, 1) @ (np.stack(found, 1).T @ null) if found else null
        u, _, _ = np.linalg.svd(rest, full_matrices=False)
        for i in range(k - len(out)):
            v = u[:, i]
            accept(v, *_describe_general(v, cs))
    return tuple(out)


def _split(v: FloatArray, cs: ConstraintSet) -> tuple[FloatArray, FloatArray]:
    w = v[3:] / cs.scale_m
    return v[:3] - np.cross(w, cs.centroid_m), w


def _axis_point(v: FloatArray, cs: ConstraintSet) -> FloatArray:
    t, w = _split(v, cs)
    return np.cross(w, t) / float(w @ w)


def _mm(p: FloatArray) -> str:
    q = np.where(np.abs(p) < 5e-7, 0.0, p) * 1e3
    return "(" + ", ".join(f"{x:.1f}" for x in q) + ") mm"


def _rotation_parallel_to(
    null: FloatArray, axis: FloatArray, cs: ConstraintSet, found: list[FloatArray]
) -> FloatArray | None:
    """A null-space motion whose rotation part is along ``axis``, pure translations removed."""
    B = null[3:]  # rotation parts (times scale)
    other = np.eye(3) - np.outer(axis, axis)
    A = np.concatenate([other @ B, axis[None, :] @ B], axis=0)
    rhs = np.array([0.0, 0.0, 0.0, cs.scale_m])
    a, *_ = np.linalg.lstsq(A, rhs, rcond=None)
    if np.linalg.norm(A @ a - rhs) > 1e-6 * cs.scale_m:
        return None
    v = null @ a
    for f in found:
        if np.linalg.norm(f[3:]) < 1e-9:  # a found pure translation: remove it from the screw
            v = v - (f @ v) * f
    return v / np.linalg.norm(v)


def _describe_general(v: FloatArray, cs: ConstraintSet) -> tuple[str, str]:
    t, w = _split(v, cs)
    if float(np.linalg.norm(w)) * cs.scale_m < 1e-9 * max(float(np.linalg.norm(t)), 1e-12):
        where = axis_name(t)
        return (
            f"translation along {where}",
            f"every face normal is perpendicular to {where}",
        )
    c = np.cross(w, t) / float(w @ w)
    pitch = float(w @ t) / float(w @ w)
    where = axis_name(w)
    if abs(pitch) < 1e-9 * cs.scale_m:
        return (
            f"rotation about an axis along {where} through {_mm(c)}",
            "every probe normal line meets or is parallel to that axis",
        )
    return (
        f"screw motion about an axis along {where} through {_mm(c)} ({pitch * 1e3:.3g} mm per rad)",
        "the probe normal lines leave this combined rotation and translation free",
    )


def name_motion(motion: FloatArray, centroid_m: FloatArray, scale_m: float) -> str:
    """Name a (weak, not necessarily free) small motion of the wobj frame in words.

    The motion's larger part in scaled centroid coordinates decides: a rotation-dominated
    motion is ``"rotation about wobj y"`` (axis within about 10 degrees of a wobj axis, through
    the origin within 5 % of the layout size) or ``"rotation about an axis along <axis>
    through (x, y, z) mm"``; a translation-dominated one ``"translation along wobj z"``.

    Args:
        motion: ``(6,)`` small motion ``(dx, dy, dz, rx, ry, rz)`` about the wobj origin (m, rad).
        centroid_m: ``(3,)`` the layout centroid, wobj frame, metres.
        scale_m: the layout size, metres (rotations times this compare with translations).
    """
    t = np.asarray(motion[:3], dtype=np.float64)
    w = np.asarray(motion[3:], dtype=np.float64)
    c = np.asarray(centroid_m, dtype=np.float64)
    t_c = t + np.cross(w, c)  # the translation at the centroid
    if float(np.linalg.norm(w)) * scale_m <= float(np.linalg.norm(t_c)):
        return f"translation along {axis_name(_snap(t))}"
    axis = _snap(w)
    point = np.cross(w, t) / float(w @ w)  # the screw axis' point nearest the origin
    name = axis_name(axis)
    if float(np.linalg.norm(point)) < 0.05 * scale_m:
        return f"rotation about {name}"
    return f"rotation about an axis along {name} through {_mm(point)}"


def _snap(d: FloatArray, tol_rad: float = np.radians(10.0)) -> FloatArray:
    """``d`` normalised, snapped to the nearest wobj axis when within ``tol_rad`` of it."""
    u = d / np.linalg.norm(d)
    k = int(np.argmax(np.abs(u)))
    if abs(u[k]) >= np.cos(tol_rad):
        out = np.zeros(3)
        out[k] = np.sign(u[k])
        return out
    return u
