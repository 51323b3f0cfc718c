"""General 3-2-1 alignment: three points on a primary face, two on a secondary, one on a tertiary.

The faces are planes of the CAD nominal, ``n_i . x = d_i`` in the wobj frame, of any orientation
(not assumed orthogonal) and any offset (not assumed through the origin); only the angles
between them must be large enough to define a frame.

1. Primary: the three measured points give the measured plane and its normal ``m1`` (sign taken
   from the nominal point order, which a rigid motion preserves).
2. Secondary: the measured normal ``m2`` is perpendicular to the line through the two points and
   makes the nominal angle with ``m1`` (``m2 . m1 = n2 . n1``): a one-parameter family solved in
   closed form, the branch chosen to match the nominal layout.
3. The rotation maps the nominal pair ``(n1, n2)`` onto ``(m1, m2)``; ``m3 = R n3``.
4. Origin: each measured plane ``m_i . q = m_i . t + d_i`` through its points gives one row of the
   3x3 linear system ``[m1; m2; m3] t = [m_i . q_i - d_i]``.

An edge point can fill any role. Its role face is its ``normal``, except when that face is
parallel to an earlier role's face (e.g. an edge search up the primary face to the top edge used
as a secondary point): then the face whose end the search finds, ``edge_normal``, is used.

Tolerances fit real meshes (:mod:`calib.tolerances`): the normals of one role's points may
differ by :data:`~calib.tolerances.ROLE_NORMAL_TOL_RAD` (0.5 deg; the role face's normal is
their mean) and the points may lie :data:`~calib.tolerances.FACE_MAX_DEVIATION_M` (0.5 mm)
off one plane, as points clicked on two triangles of one face of a float32 mesh do.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_points
from calib.errors import DegenerateGeometryError, ShapeError
from calib.estimators.layout import axis_name, check_coincident
from calib.frames import check_transform, invert_transform, make_transform, transform_points
from calib.probing import ProbePoint
from calib.tolerances import FACE_MAX_DEVIATION_M, ROLE_NORMAL_TOL_RAD, same_direction

FloatArray = NDArray[np.float64]

#: Faces closer than this angle (radians) to parallel cannot define a frame.
MIN_FACE_ANGLE_RAD = float(np.deg2rad(2.0))
#: Primary points whose triangle is flatter than this (sine of its smallest angle) are collinear.
COLLINEAR_SIN = 1e-3
ROLES = ("primary", "secondary", "tertiary")
COUNTS = (3, 2, 1)


@dataclass(frozen=True)
class ThreeTwoOneLayout:
    """Which probe points fill the 3-2-1 roles, and the nominal faces they define (wobj frame).

    Attributes:
        primary: three points on the primary face.
        secondary: two points on the secondary face.
        tertiary: one point on the tertiary face.
        normals: ``(3, 3)`` unit nominal normal of the primary, secondary, tertiary face, wobj.
        offsets_m: ``(3,)`` plane offsets ``d_i = n_i . p`` of the three faces, metres.
    """

    primary: tuple[ProbePoint, ProbePoint, ProbePoint]
    secondary: tuple[ProbePoint, ProbePoint]
    tertiary: tuple[ProbePoint]
    normals: FloatArray
    offsets_m: FloatArray

    @classmethod
    def from_points(
        cls,
        primary: Sequence[ProbePoint],
        secondary: Sequence[ProbePoint],
        tertiary: Sequence[ProbePoint] | ProbePoint,
        min_face_angle_rad: float = MIN_FACE_ANGLE_RAD,
    ) -> ThreeTwoOneLayout:
        """Check the roles and derive the nominal faces.

        Raises:
            ShapeError: a role has the wrong number of points, or an entry is not a ProbePoint.
            DegenerateGeometryError: points of one role on different faces, coincident points,
                collinear primary points, secondary points along the primary normal, or
                (near-)parallel faces, named in the message.
        """
        if isinstance(tertiary, ProbePoint):
            tertiary = (tertiary,)
        groups = (tuple(primary), tuple(secondary), tuple(tertiary))
        for role, want, pts in zip(ROLES, COUNTS, groups):
            if len(pts) != want:
                raise ShapeError(f"3-2-1 {role} needs {want} point(s), got {len(pts)}")
            for p in pts:
                if not isinstance(p, ProbePoint):
                    raise ShapeError(f"3-2-1 {role} entries must be ProbePoints, got {p!r}")
        all_pts = groups[0] + groups[1] + groups[2]
        ids = [p.id for p in all_pts]
        if len(set(ids)) != 6:
            raise ShapeError(f"3-2-1 point ids must be unique, got {ids}")
        check_coincident(np.array([p.position_m for p in all_pts]), ids, "3-2-1 layout")
        normals = np.zeros((3, 3))
        offsets = np.zeros(3)
        for r, (role, pts) in enumerate(zip(ROLES, groups)):
            first = _role_normal(pts[0], normals[:r])
            role_normals = [first]
            for p in pts[1:]:
                m = _role_normal(p, normals[:r])
                cos = float(np.clip(m @ first, -1.0, 1.0))
                if not same_direction(cos):
                    raise DegenerateGeometryError(
                        f"3-2-1 {role} points {pts[0].id!r} and {p.id!r} lie on faces with "
                        f"normals {np.degrees(np.arccos(cos)):.3g} deg apart (one face allows "
                        f"{np.degrees(ROLE_NORMAL_TOL_RAD):.2g} deg); all points of a role must "
                        "be on one face"
                    )
                role_normals.append(m)
            n = _unit(np.mean(role_normals, axis=0))
            d = np.array([n @ np.asarray(p.position_m) for p in pts])
            if np.ptp(d) > FACE_MAX_DEVIATION_M:
                raise DegenerateGeometryError(
                    f"3-2-1 {role} points are not on one plane: offsets along the normal differ "
                    f"by {np.ptp(d) * 1e3:.3f} mm (one face allows "
                    f"{FACE_MAX_DEVIATION_M * 1e3:g} mm)"
                )
            normals[r], offsets[r] = n, d.mean()
        nominal = np.array([p.position_m for p in all_pts], dtype=np.float64)
        check_role_geometry(normals, nominal, "nominal", min_face_angle_rad)
        return cls(groups[0], groups[1], groups[2], normals, offsets)  # type: ignore[arg-type]

    @property
    def points(self) -> tuple[ProbePoint, ...]:
        """The six points in role order: primary, secondary, tertiary."""
        return self.primary + self.secondary + self.tertiary

    @property
    def nominal_m(self) -> FloatArray:
        """``(6, 3)`` nominal positions in role order, wobj frame, metres."""
        return np.array([p.position_m for p in self.points], dtype=np.float64)


@dataclass(frozen=True)
class ThreeTwoOneResult:
    """The frame found by a 3-2-1 alignment.

    Attributes:
        T_base_wobj: ``(4, 4)`` the measured work-object frame in the robot base frame.
        point_ids: ``(6,)`` ids in role order.
        residuals_m: ``(6,)`` signed distance of each measured point from its role face of the
            fitted frame, metres (zero up to rounding unless the measured angle between primary
            and secondary could not match the nominal one).
        in_plane_offsets_m: ``(6,)`` distance in the face between each measured point and its
            nominal point, metres: how far from the planned spot the sensor really measured.
    """

    T_base_wobj: FloatArray
    point_ids: tuple[str, ...]
    residuals_m: FloatArray
    in_plane_offsets_m: FloatArray


def three_two_one(
    layout: ThreeTwoOneLayout,
    measured_base: ArrayLike,
    T_base_wobj_guess: ArrayLike | None = None,
) -> ThreeTwoOneResult:
    """Find ``T_base_wobj`` from six measured points in 3-2-1 roles.

    Args:
        layout: the roles and nominal faces.
        measured_base: ``(6, 3)`` measured points in role order (primary x3, secondary x2,
            tertiary), robot base frame, metres.
        T_base_wobj_guess: ``(4, 4)`` optional rough estimate (e.g. the frame the points were
            commanded in). Without it, the side of the measured primary plane and the branch
            of the secondary face are taken from the nominal layout, which is right as long as
            the measured points do not flip the primary triangle or cross the secondary pair
            over; with it, the candidate closer to the guess is taken (right when the guess
            is off by less than half the angle between the two candidate secondary faces,
            which is large for a secondary pair laid along the primary/secondary edge).

    Raises:
        ShapeError: ``measured_base`` is not ``(6, 3)``.
        NonFiniteError: NaN or infinity in ``measured_base``.
        DegenerateGeometryError: measured points coincide, the primary points are collinear or
            the secondary points lie along the primary normal.
    """
    q = check_points(measured_base, "measured_base")
    if q.shape != (6, 3):
        raise ShapeError(f"measured_base must be (6, 3) in 3-2-1 role order, got {q.shape}")
    ids = [p.id for p in layout.points]
    check_coincident(q, ids, "measured_base")
    n1, n2, n3 = layout.normals
    p = layout.nominal_m
    _check_primary_triangle(q[:3], ids[:3], "measured_base")
    m1 = _unit(np.cross(q[1] - q[0], q[2] - q[0]))
    if T_base_wobj_guess is None:
        m1 *= np.sign(n1 @ np.cross(p[1] - p[0], p[2] - p[0]))
        pair = _secondary_normal(m1, q[4] - q[3], float(n1 @ n2), ids[3:5])
        m2 = pair[0] if _branch(n1, n2, p[4] - p[3]) > 0 else pair[1]
    else:
        R_guess = check_transform(T_base_wobj_guess, "T_base_wobj_guess")[:3, :3]
        m1 *= 1.0 if float(m1 @ R_guess @ n1) >= 0 else -1.0
        pair = _secondary_normal(m1, q[4] - q[3], float(n1 @ n2), ids[3:5])
        m2 = pair[0] if float(pair[0] @ R_guess @ n2) >= float(pair[1] @ R_guess @ n2) else pair[1]
    R = _frame(m1, m2) @ _frame(n1, n2).T
    m3 = R @ n3
    M = np.stack([m1, m2, m3])
    rhs = np.array([m1 @ q[:3].mean(0), m2 @ q[3:5].mean(0), m3 @ q[5]]) - layout.offsets_m
    t = np.linalg.solve(M, rhs)
    T = make_transform(R, t)
    x = transform_points(invert_transform(T), q)
    role_n = layout.normals[[0, 0, 0, 1, 1, 2]]
    diff = x - p
    resid = np.einsum("ij,ij->i", diff, role_n)
    in_plane = np.linalg.norm(diff - resid[:, None] * role_n, axis=1)
    return ThreeTwoOneResult(T, tuple(ids), resid, in_plane)


def check_role_geometry(
    normals: FloatArray, points: FloatArray, what: str, min_angle: float
) -> None:
    """Raise :class:`DegenerateGeometryError` when the faces or points cannot define a frame."""
    names = ROLES
    s_min = np.sin(min_angle)
    for i, j in ((0, 1), (0, 2), (1, 2)):
        s = float(np.linalg.norm(np.cross(normals[i], normals[j])))
        if s < s_min:
            raise DegenerateGeometryError(
                f"3-2-1 {what} {names[i]} and {names[j]} faces are parallel or nearly so "
                f"(angle {np.rad2deg(np.arcsin(min(s, 1.0))):.3g} deg, need at least "
                f"{np.rad2deg(min_angle):.3g} deg)"
            )
    c12 = _unit(np.cross(normals[0], normals[1]))
    if abs(float(c12 @ normals[2])) < s_min:
        raise DegenerateGeometryError(
            f"3-2-1 {what} tertiary face normal lies (nearly) in the plane of the primary and "
            f"secondary normals: translation along {axis_name(c12)} is not determined"
        )
    _check_primary_triangle(points[:3], ["P1", "P2", "P3"], what)
    u = points[4] - points[3]
    if np.linalg.norm(np.cross(_unit(u), normals[0])) < s_min:
        raise DegenerateGeometryError(
            f"3-2-1 {what} secondary points lie on a line along the primary normal: the "
            "rotation about the primary normal is not determined"
        )
    if abs(float(_unit(u) @ c12)) < s_min:
        raise DegenerateGeometryError(
            f"3-2-1 {what} secondary points lie on a line across the edge between the primary "
            "and secondary faces: two mirror-image secondary faces fit them; spread the two "
            "points along that edge instead"
        )


def _role_normal(p: ProbePoint, earlier: FloatArray) -> FloatArray:
    n = np.asarray(p.normal, dtype=np.float64)
    if p.edge_normal is not None and any(same_direction(abs(float(n @ e))) for e in earlier):
        n = np.asarray(p.edge_normal, dtype=np.float64)
    return n / np.linalg.norm(n)


def _unit(v: FloatArray) -> FloatArray:
    return v / np.linalg.norm(v)


def _check_primary_triangle(q: FloatArray, ids: Sequence[str], what: str) -> None:
    e = [q[1] - q[0], q[2] - q[0], q[2] - q[1]]
    area2 = np.linalg.norm(np.cross(e[0], e[1]))
    longest = max(float(np.linalg.norm(v)) for v in e)
    if area2 < COLLINEAR_SIN * longest**2:
        raise DegenerateGeometryError(
            f"3-2-1 {what} primary points {', '.join(repr(i) for i in ids)} are collinear: "
            "three points on one line do not define the primary plane"
        )


def _basis(m1: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray, float]:
    u = _unit(u)
    a = m1 - (m1 @ u) * u
    k = float(np.linalg.norm(a))
    if k < 1e-12:  # m1 along u: no in-plane direction; callers check k and refuse
        return a, np.cross(u, a), k
    a = a / k
    return a, np.cross(u, a), k


def _branch(n1: FloatArray, n2: FloatArray, u_nom: FloatArray) -> float:
    _, b, _ = _basis(n1, u_nom)
    return 1.0 if float(n2 @ b) >= 0 else -1.0


def _secondary_normal(
    m1: FloatArray, u: FloatArray, cos12: float, ids: Sequence[str]
) -> tuple[FloatArray, FloatArray]:
    """The two unit normals perpendicular to ``u`` at the nominal angle to ``m1``."""
    a, b, k = _basis(m1, u)
    if k < np.sin(MIN_FACE_ANGLE_RAD):
        raise DegenerateGeometryError(
            f"3-2-1 measured secondary points {ids[0]!r}, {ids[1]!r} lie on a line along the "
            "measured primary normal: the rotation about the primary normal is not determined"
        )
    c = float(np.clip(cos12 / k, -1.0, 1.0))
    s = np.sqrt(1.0 - c * c)
    return c * a + s * b, c * a - s * b


def _frame(n1: FloatArray, n2: FloatArray) -> FloatArray:
    e2 = _unit(n2 - (n2 @ n1) * n1)
    return np.stack([n1, e2, np.cross(n1, e2)], axis=1)
