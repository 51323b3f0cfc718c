"""Point layouts as arrays of face constraints: shared by the general estimators.

A :class:`calib.probing.ProbePoint` constrains the face it lies on (one constraint normal) or,
for an edge search, the two faces that meet at the edge (two constraint normals). Every
estimator in ``calib`` needs the same flat arrays: one row per constraint with its unit normal,
the nominal point and the index of the point it came from. :func:`constraint_set` builds them
once, validating the layout, so a Monte Carlo loop that fits thousands of times pays for the
checks only once (compute once, use many times).

The linearised effect of a small motion ``delta = (dx, dy, dz, rx, ry, rz)`` of the wobj frame
(see :func:`calib.frames.small_motion`) on a point-to-plane residual ``n . (x - p)`` is the row
``-[n, x x n]``: the Pluecker coordinates of the constraint line through ``x`` along ``n``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import DegenerateGeometryError, ShapeError
from calib.probing import ProbePoint

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Two probe points closer than this (metres) are coincident.
COINCIDENT_TOL_M = 1e-6

#: Smallest part size used to scale rotations against translations, metres.
MIN_SCALE_M = 1e-3


@dataclass(frozen=True)
class ConstraintSet:
    """The face constraints of a point layout, as flat arrays (wobj frame).

    Attributes:
        point_ids: ``(N,)`` ids of the probe points, in the order given.
        positions_m: ``(N, 3)`` nominal point positions, wobj frame, metres.
        normals: ``(M, 3)`` unit outward face normal of each constraint, wobj frame
            (``M >= N``: an edge point adds a second row for its ``edge_normal``).
        nominal_m: ``(M, 3)`` the nominal point of each constraint, wobj frame, metres.
        point_index: ``(M,)`` index into ``point_ids`` of the point each constraint belongs to.
        centroid_m: ``(3,)`` mean of the nominal positions, wobj frame, metres.
        scale_m: size of the layout (RMS distance of the points from their centroid, at least
            :data:`MIN_SCALE_M`), metres; rotations are scaled by it to compare with translations.
    """

    point_ids: tuple[str, ...]
    positions_m: FloatArray
    normals: FloatArray
    nominal_m: FloatArray
    point_index: IntArray
    centroid_m: FloatArray
    scale_m: float

    @property
    def n_points(self) -> int:
        """Number of probe points ``N``."""
        return len(self.point_ids)

    @property
    def n_constraints(self) -> int:
        """Number of constraint rows ``M``."""
        return int(self.normals.shape[0])

    @property
    def constraint_ids(self) -> tuple[str, ...]:
        """``(M,)`` id of the point each constraint row belongs to."""
        return tuple(self.point_ids[i] for i in self.point_index)


def constraint_set(
    points: Sequence[ProbePoint] | ConstraintSet,
    name: str = "points",
    edge_rows: Literal["both", "edge"] = "both",
) -> ConstraintSet:
    """Validate a point layout and flatten it into a :class:`ConstraintSet`.

    Args:
        points: the probe points (each already validated by :class:`ProbePoint`); a
            :class:`ConstraintSet` is returned as it is.
        name: argument name used in error messages.
        edge_rows: ``"both"``: an edge point constrains its face and the face whose end it
            finds; ``"edge"``: an edge *search* constrains only the face whose end it finds
            (its ``edge_normal``), as when the point was measured by a search run along a
            commanded track: its coordinate across the face it slides over is the command's,
            not a measurement (see :func:`search_constraint_set`).

    Raises:
        ShapeError: no points, an entry that is not a ``ProbePoint``, or duplicate ids.
        DegenerateGeometryError: two points coincide (closer than :data:`COINCIDENT_TOL_M`).
    """
    if isinstance(points, ConstraintSet):
        return points
    pts = tuple(points)
    if not pts:
        raise ShapeError(f"{name} must hold at least one ProbePoint, got none")
    for i, p in enumerate(pts):
        if not isinstance(p, ProbePoint):
            raise ShapeError(f"{name}[{i}] must be a ProbePoint, got {type(p).__name__}")
    ids = tuple(p.id for p in pts)
    if len(set(ids)) != len(ids):
        dup = sorted({i for i in ids if ids.count(i) > 1})
        raise ShapeError(f"{name} ids must be unique, repeated: {', '.join(dup)}")
    positions = np.array([p.position_m for p in pts], dtype=np.float64)
    check_coincident(positions, ids, name)
    normals_list: list[FloatArray] = []
    index: list[int] = []
    for i, p in enumerate(pts):
        n = p.constraint_normals
        if edge_rows == "edge" and p.search.kind == "edge" and p.edge_normal is not None:
            n = n[1:]
        n = n / np.linalg.norm(n, axis=1, keepdims=True)
        normals_list.append(n)
        index.extend([i] * n.shape[0])
    normals = np.concatenate(normals_list, axis=0)
    point_index = np.asarray(index, dtype=np.int64)
    centroid = positions.mean(axis=0)
    rms = float(np.sqrt(np.mean(np.sum((positions - centroid) ** 2, axis=1))))
    return ConstraintSet(
        point_ids=ids,
        positions_m=positions,
        normals=normals,
        nominal_m=positions[point_index],
        point_index=point_index,
        centroid_m=centroid,
        scale_m=max(rms, MIN_SCALE_M),
    )


def search_constraint_set(
    points: Sequence[ProbePoint] | ConstraintSet, name: str = "points"
) -> ConstraintSet:
    """The constraints of points measured by searches: :func:`constraint_set` with an edge
    search contributing only its edge coordinate (``edge_rows="edge"``).

    An edge search slides the sensor along a commanded track over one face until that face
    ends; the recorded point lies on the track, so its coordinate along the face's normal is
    the command's (the estimate the search was commanded in), not a measurement of the part.
    """
    return constraint_set(points, name, edge_rows="edge")


def check_coincident(positions: FloatArray, ids: Sequence[str], name: str) -> None:
    """Raise :class:`DegenerateGeometryError` naming the first pair of coincident points."""
    n = positions.shape[0]
    if n < 2:
        return
    d = np.linalg.norm(positions[:, None, :] - positions[None, :, :], axis=-1)
    d[np.tril_indices(n)] = np.inf
    i, j = (int(k) for k in np.unravel_index(int(np.argmin(d)), d.shape))
    if d[i, j] < COINCIDENT_TOL_M:
        raise DegenerateGeometryError(
            f"{name}: points {ids[i]!r} and {ids[j]!r} coincide ({d[i, j] * 1e3:.4f} mm apart); "
            "use one point (an edge point for two faces) or move one of them"
        )


def constraint_jacobian(normals: FloatArray, x_m: FloatArray) -> FloatArray:
    """``(M, 6)`` derivative of the residuals ``n . (exp(delta)^-1 x - p)`` at ``delta = 0``.

    Args:
        normals: ``(M, 3)`` unit constraint normals, wobj frame.
        x_m: ``(M, 3)`` the points where the residuals are evaluated, wobj frame, metres.
    """
    J = np.empty((normals.shape[0], 6))
    J[:, :3] = -normals
    J[:, 3:] = -cross_rows(x_m, normals)
    return J


def cross_rows(a: FloatArray, b: FloatArray) -> FloatArray:
    """Row-wise cross product of ``(M, 3)`` arrays (``np.cross`` without its overhead)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def small_motion_matrix(delta: FloatArray) -> FloatArray:
    """``(4, 4)`` transform of one small motion ``(dx, dy, dz, rx, ry, rz)``: the same as
    :func:`calib.frames.small_motion` for a single ``(6,)`` vector, by Rodrigues' formula
    (no scipy call: this runs in every Gauss-Newton iteration).
    """
    w = delta[3:]
    theta = float(np.sqrt(w @ w))
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if theta < 1e-8:
        s, c = 1.0 - theta * theta / 6.0, 0.5 - theta * theta / 24.0
    else:
        s, c = np.sin(theta) / theta, (1.0 - np.cos(theta)) / (theta * theta)
    T = np.eye(4)
    T[:3, :3] += s * K + c * (K @ K)
    T[:3, 3] = delta[:3]
    return T


def point_motion_jacobian(p_wobj: ArrayLike) -> FloatArray:
    """``(..., 3, 6)`` map from a small frame motion ``delta`` to the shift of a wobj point.

    A point fixed in the wobj frame at ``p`` moves by ``dt + dr x p = [I, -[p]x] delta`` in the
    frame's own axes when the frame moves by ``delta = (dt, dr)`` (see
    :func:`calib.frames.small_motion`).
    """
    p = np.asarray(p_wobj, dtype=np.float64)
    J = np.zeros((*p.shape[:-1], 3, 6))
    J[..., 0, 0] = J[..., 1, 1] = J[..., 2, 2] = 1.0
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    # -[p]x
    J[..., 0, 4], J[..., 0, 5] = z, -y
    J[..., 1, 3], J[..., 1, 5] = -z, x
    J[..., 2, 3], J[..., 2, 4] = y, -x
    return J


def axis_name(direction: ArrayLike, tol: float = 1e-6) -> str:
    """Name a unit direction in wobj words: ``"wobj z"`` or ``"wobj (0.707, 0, 0.707)"``.

    The sign is dropped for the coordinate axes (a motion along -z is one along z).
    """
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    k = int(np.argmax(np.abs(d)))
    if abs(abs(d[k]) - 1.0) < tol:
        return f"wobj {'xyz'[k]}"
    if d[k] < 0:
        d = -d
    d = np.where(np.abs(d) < 5e-4, 0.0, d)
    return "wobj (" + ", ".join(f"{v:.3g}" for v in d) + ")"


@dataclass(frozen=True)
class FaceLayout:
    """A random work object of three planar faces with probe points, for tests and benchmarks.

    Attributes:
        normals: ``(3, 3)`` unit outward normals of the faces, wobj frame.
        offsets_m: ``(3,)`` plane offsets ``d_i``: face ``i`` is ``n_i . x = d_i``, metres.
        corner_m: ``(3,)`` the point common to the three faces, wobj frame, metres.
        points: probe points, grouped by face in order; edge points (if any) come last.
        face_of: ``(len(points),)`` index of the face each point's ``normal`` belongs to.
    """

    normals: FloatArray
    offsets_m: FloatArray
    corner_m: FloatArray
    points: tuple[ProbePoint, ...]
    face_of: tuple[int, ...]


def random_face_layout(
    rng: np.random.Generator,
    counts: Sequence[int] = (3, 2, 1),
    *,
    n_edge_points: int = 0,
    size_m: float = 0.4,
    min_angle_rad: float = float(np.deg2rad(30.0)),
    start_offset_m: float = 0.030,
    overtravel_m: float = 0.020,
) -> FaceLayout:
    """Draw three non-parallel, generally non-orthogonal faces (not through the origin) with
    ``counts[i]`` approach points on face ``i`` and ``n_edge_points`` edge points on the line
    where faces 0 and 1 meet (``normal`` of face 0, ``edge_normal`` of face 1).

    Points lie within ``size_m`` of the corner; the primary triangle and the pair on face 1
    are kept well spread, so the layout suits a 3-2-1 alignment in face order.
    """
    from calib.probing import SearchSpec  # local: only this helper needs it

    search = SearchSpec(start_offset_m=start_offset_m, overtravel_m=overtravel_m)
    while True:
        n = rng.normal(size=(3, 3))
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        s01 = np.linalg.norm(np.cross(n[0], n[1]))
        if s01 < np.sin(min_angle_rad):
            continue
        c01 = np.cross(n[0], n[1]) / s01
        if abs(c01 @ n[2]) < np.sin(min_angle_rad):
            continue
        d = rng.uniform(-0.5, 0.5, size=3)
        corner = np.linalg.solve(n, d)
        pts: list[ProbePoint] = []
        face_of: list[int] = []
        ok = True
        for f, k in enumerate(counts):
            a = np.cross(n[f], rng.normal(size=3))
            a /= np.linalg.norm(a)
            b = np.cross(n[f], a)
            uv = rng.uniform(-size_m, size_m, size=(k, 2))
            pos = corner + uv[:, :1] * a + uv[:, 1:] * b
            ok &= _well_spread(pos, n[f], size_m)
            if f == 1 and k >= 2:  # the secondary pair must run along the face-0/face-1 edge
                u = (pos[1] - pos[0]) / np.linalg.norm(pos[1] - pos[0])
                ok &= bool(abs(u @ c01) > 0.5)
            for j in range(k):
                pts.append(ProbePoint(f"f{f}p{j}", tuple(pos[j]), tuple(n[f]), search))
                face_of.append(f)
        if not ok:
            continue
        across = n[1] - (n[1] @ n[0]) * n[0]
        across /= np.linalg.norm(across)
        edge_search = SearchSpec("edge", start_offset_m, overtravel_m, edge_direction=tuple(across))
        for j in range(n_edge_points):
            pos = corner + c01 * rng.uniform(-size_m, size_m)
            pts.append(
                ProbePoint(f"e{j}", tuple(pos), tuple(n[0]), edge_search, edge_normal=tuple(n[1]))
            )
            face_of.append(0)
        all_pos = np.array([p.position_m for p in pts])
        gaps = np.linalg.norm(all_pos[:, None] - all_pos[None], axis=-1) + np.eye(len(pts))
        if gaps.min() < 0.05 * size_m:
            continue
        return FaceLayout(n, d, np.asarray(corner, dtype=np.float64), tuple(pts), tuple(face_of))


def _well_spread(pos: FloatArray, normal: FloatArray, size_m: float) -> bool:
    if pos.shape[0] == 2:
        u = pos[1] - pos[0]
        return bool(np.linalg.norm(u) > 0.2 * size_m)
    if pos.shape[0] >= 3:
        e1, e2 = pos[1] - pos[0], pos[2] - pos[0]
        area2 = np.linalg.norm(np.cross(e1, e2))
        return bool(area2 > 0.3 * size_m**2)
    return True
