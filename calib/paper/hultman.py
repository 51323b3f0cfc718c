"""The general positional-calibration equations of Hultman & Leijon (2013), section 3.1.

Each function implements one equation (or a small group) of the paper, in the paper's
notation, with points in the robot base frame (the paper's RBCS) and in metres:

- eq. 1-2: :func:`v1_vector`, :func:`v2_vector`;
- eq. 3-4: :func:`x_vector`, :func:`z_vector`;
- eq. 5-6: :func:`rotation_from_axes` (``R_base_wobj`` from the unit vectors);
- eq. 7-9: :func:`tait_bryan_angles` (delegates to :func:`calib.frames.tait_bryan_zyx_from_matrix`);
- eq. 1-6 together: :func:`orientation_from_vectors`, :func:`orientation_from_three_points`;
- eq. 10: :func:`adjust_origin`;
- eq. 11-12 (section 3.2): :func:`alpha1_from_points`, :func:`p3_estimate`.

The sought work-object frame (the paper's WOCS) has its yz-plane on the measured face and
``+x`` along its outward normal; ``P1 -> P2`` runs along ``+y``. Degenerate input (coincident
or collinear points, NaN or infinity, wrong shapes) raises the errors of :mod:`calib.errors`
with a message that names the points. These functions are called thousands of times by the
Monte Carlo validation, so they do only cheap checks.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import as_float_array, check_finite, check_positive, check_vector3
from calib.errors import DegenerateGeometryError, ShapeError
from calib.frames import check_transform, make_transform, tait_bryan_zyx_from_matrix

FloatArray = NDArray[np.float64]

#: Two points closer than this (metres) are coincident.
COINCIDENT_TOL_M = 1e-9
#: Vectors whose angle has a sine below this are parallel (the points are collinear).
COLLINEAR_SIN_TOL = 1e-9

_E_BASE = np.eye(3)  # eq. 5: the unit vectors of the RBCS, as rows


def v1_vector(p1: ArrayLike, p2: ArrayLike) -> FloatArray:
    """Eq. 1: ``V1 = P2 - P1``, base frame, metres (``(3,)``)."""
    return check_vector3(p2, "P2") - check_vector3(p1, "P1")


def v2_vector(p2: ArrayLike, p3: ArrayLike) -> FloatArray:
    """Eq. 2: ``V2 = P3 - P2``, base frame, metres (``(3,)``)."""
    return check_vector3(p3, "P3") - check_vector3(p2, "P2")


def x_vector(v1: ArrayLike, v2: ArrayLike) -> FloatArray:
    """Eq. 3: ``X = V1 x V2``, the normal of the WOCS yz-plane (towards +x), ``(3,)``."""
    return np.cross(check_vector3(v1, "V1"), check_vector3(v2, "V2"))


def z_vector(x: ArrayLike, y: ArrayLike) -> FloatArray:
    """Eq. 4: ``Z = X x Y`` with ``Y = V1``, the WOCS +z direction, ``(3,)``."""
    return np.cross(check_vector3(x, "X"), check_vector3(y, "Y"))


def rotation_from_axes(ux: ArrayLike, uy: ArrayLike, uz: ArrayLike) -> FloatArray:
    """Eq. 5-6: the rotation ``R_base_wobj`` (3x3) from the WOCS unit vectors in the base frame.

    Element ``(i, j)`` is the dot product of the WOCS unit vector ``j`` with the RBCS unit
    vector ``i`` (eq. 5), so the columns of the result are ``uX``, ``uY`` and ``uZ``.

    Args:
        ux: ``(3,)`` unit vector of the WOCS x axis, base frame.
        uy: ``(3,)`` unit vector of the WOCS y axis, base frame.
        uz: ``(3,)`` unit vector of the WOCS z axis, base frame.
    """
    axes = np.stack([check_vector3(ux, "uX"), check_vector3(uy, "uY"), check_vector3(uz, "uZ")])
    return _E_BASE @ axes.T  # R[i, j] = U_j . U_R0_i


def tait_bryan_angles(R_base_wobj: ArrayLike) -> FloatArray:
    """Eq. 7-9: Tait-Bryan z-y'-x'' angles ``(alpha, beta, gamma)`` (rad) of ``R_base_wobj``.

    Uses :func:`calib.frames.tait_bryan_zyx_from_matrix` (identical to scipy's ``"ZYX"``).
    """
    return tait_bryan_zyx_from_matrix(R_base_wobj)


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """``a x b`` for two ``(3,)`` vectors (np.cross costs ~10x more for a single pair)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def _norm(v: FloatArray) -> float:
    return math.sqrt(float(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]))


def _rotation_from_vectors(a: FloatArray, b: FloatArray, names: tuple[str, str]) -> FloatArray:
    """Eq. 3-6 on checked ``(3,)`` arrays; raises when a vector is zero or they are parallel."""
    na, nb = _norm(a), _norm(b)
    for vec_name, n in zip(names, (na, nb), strict=True):
        if n < COINCIDENT_TOL_M:
            raise DegenerateGeometryError(f"vector {vec_name} has zero length ({n:.3g} m)")
    x = _cross(a, b)  # eq. 3
    nx = _norm(x)
    if nx < COLLINEAR_SIN_TOL * na * nb:
        raise DegenerateGeometryError(
            f"vectors {names[0]} and {names[1]} are parallel: "
            f"sin(angle) = {nx / (na * nb):.3g}, so they span no plane"
        )
    ux = x / nx
    uy = a / na
    uz = _cross(ux, uy)  # eq. 4, unit: ux and uy are orthonormal
    return np.stack([ux, uy, uz], axis=1)  # eq. 5-6, as rotation_from_axes


def orientation_from_vectors(
    v1: ArrayLike, v2: ArrayLike, names: tuple[str, str] = ("V1", "V2")
) -> FloatArray:
    """Eq. 3-6: ``R_base_wobj`` from ``V1`` (along WOCS +y) and a second in-plane vector ``V2``.

    ``X = V1 x V2`` (eq. 3), ``Y = V1``, ``Z = X x Y`` (eq. 4), normalised and stacked (eq. 5-6).

    Args:
        v1: ``(3,)`` vector along the WOCS +y axis, base frame.
        v2: ``(3,)`` second vector in the WOCS yz-plane, with ``V1 x V2`` towards WOCS +x.
        names: how the two vectors are called in error messages.

    Returns:
        ``(3, 3)`` rotation ``R_base_wobj``.

    Raises:
        DegenerateGeometryError: a vector is (near) zero, or the two are parallel.
    """
    return _rotation_from_vectors(check_vector3(v1, names[0]), check_vector3(v2, names[1]), names)


def _rotation_from_points(
    a: FloatArray, b: FloatArray, c: FloatArray, invert_v2: bool, names: tuple[str, str, str]
) -> FloatArray:
    """Eq. 1-6 on checked ``(3,)`` points; raises on coincident or collinear points."""
    v1, v2 = b - a, c - b  # eq. 1-2
    for vec, i, j in ((v1, 0, 1), (v2, 1, 2), (c - a, 0, 2)):
        dist = _norm(vec)
        if dist < COINCIDENT_TOL_M:
            raise DegenerateGeometryError(
                f"points {names[i]} and {names[j]} coincide (distance {dist:.3g} m)"
            )
    sin_angle = _norm(_cross(v1, v2)) / (_norm(v1) * _norm(v2))
    if sin_angle < COLLINEAR_SIN_TOL:
        raise DegenerateGeometryError(
            f"points {', '.join(names)} are collinear: sin(angle between V1 and V2) = "
            f"{sin_angle:.3g}, so they define no plane"
        )
    return _rotation_from_vectors(v1, -v2 if invert_v2 else v2, ("V1", "V2"))


def orientation_from_three_points(
    p1: ArrayLike,
    p2: ArrayLike,
    p3: ArrayLike,
    *,
    invert_v2: bool = False,
    names: tuple[str, str, str] = ("P1", "P2", "P3"),
) -> FloatArray:
    """Eq. 1-6: ``R_base_wobj`` from three points on the face that becomes the WOCS yz-plane.

    ``V1 = P2 - P1`` (eq. 1) is the WOCS +y axis, ``V2 = P3 - P2`` (eq. 2); the WOCS +x axis is
    the plane normal ``V1 x V2`` (eq. 3) and ``+z = X x Y`` (eq. 4).

    Args:
        p1: ``(3,)`` first point, base frame, metres.
        p2: ``(3,)`` second point; ``P1 -> P2`` is along WOCS +y.
        p3: ``(3,)`` third point, not on the line ``P1 P2``.
        invert_v2: use ``-V2`` (the paper's final stator rotation: H, F, D "by inverting the
            direction of V2", because D lies below the edge points).
        names: how the points are called in error messages, e.g. ``("H", "F", "D")``.

    Returns:
        ``(3, 3)`` rotation ``R_base_wobj``.

    Raises:
        ShapeError, NonFiniteError: a point is not a finite ``(3,)`` vector.
        DegenerateGeometryError: two points coincide or the three are collinear.
    """
    a = check_vector3(p1, names[0])
    b = check_vector3(p2, names[1])
    c = check_vector3(p3, names[2])
    return _rotation_from_points(a, b, c, invert_v2, names)


def _shift_origin(
    T: FloatArray, axis: int, point: FloatArray, face_coord: float = 0.0
) -> FloatArray:
    """Eq. 10 for one axis on a checked frame and point: the new ``T_base_wobj``."""
    R, o = T[:3, :3], T[:3, 3]
    shift = float(R[:, axis] @ (point - o)) - face_coord  # the point's coordinate in the WOCS
    out = T.copy()
    out[:3, 3] = o + shift * R[:, axis]
    return out


def adjust_origin(
    T_prelim: ArrayLike,
    p4_base: ArrayLike | None = None,
    p5_base: ArrayLike | None = None,
    p6_base: ArrayLike | None = None,
    *,
    use: tuple[bool, bool, bool] | None = None,
    face_coords_wobj: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> FloatArray:
    """Eq. 10: shift the WOCS origin with points on the faces ``x = 0``, ``y = 0``, ``z = 0``.

    Each point is expressed in the preliminary WOCS ``T_prelim`` (already rotated as wanted);
    the x-coordinate of P4, the y-coordinate of P5 and the z-coordinate of P6 form the
    shift, which is rotated into the base frame and added to the preliminary origin:
    ``o_adj = R_base_wobj @ (P4_W^x, P5_W^y, P6_W^z) + o_prel``. The rotation is unchanged.
    An axis whose point is not used keeps its origin coordinate (the paper adjusts x alone,
    then y alone, and so on).

    Args:
        T_prelim: ``(4, 4)`` preliminary ``T_base_wobj`` (new rotation, old origin).
        p4_base: ``(3,)`` point on the face ``x = 0`` (the face's normal is the WOCS x axis),
            base frame, metres; ``None`` leaves the x origin.
        p5_base: ``(3,)`` point on the face ``y = 0``, base frame; ``None`` leaves y.
        p6_base: ``(3,)`` point on the face ``z = 0``, base frame; ``None`` leaves z.
        use: which of x, y, z to adjust; by default the axes whose point is given.
        face_coords_wobj: the nominal coordinates ``(x of P4's face, y of P5's face, z of
            P6's face)`` in the WOCS, metres. The paper's faces pass through the origin
            (zeros, eq. 10 exactly); a face at ``x = -0.005`` is handled by passing ``-0.005``.

    Returns:
        ``(4, 4)`` adjusted ``T_base_wobj``.

    Raises:
        InputError: an axis is to be adjusted but its point is missing, or bad shapes/values.
    """
    T = check_transform(T_prelim, "T_prelim")
    if T.shape != (4, 4):
        raise ShapeError(f"T_prelim must be (4, 4), got {T.shape}")
    points = (p4_base, p5_base, p6_base)
    flags = tuple(p is not None for p in points) if use is None else tuple(bool(u) for u in use)
    if len(flags) != 3:
        raise ShapeError(f"use must hold 3 flags (x, y, z), got {len(flags)}")
    faces = check_vector3(face_coords_wobj, "face_coords_wobj")
    R, o = T[:3, :3], T[:3, 3]
    shift_w = np.zeros(3)
    for axis, (name, point, flag) in enumerate(zip(("P4", "P5", "P6"), points, flags, strict=True)):
        if not flag:
            continue
        if point is None:
            raise ShapeError(f"{name} is required to adjust the {'xyz'[axis]} origin")
        p_w = R.T @ (check_vector3(point, name) - o)  # the point in the preliminary WOCS
        shift_w[axis] = p_w[axis] - faces[axis]
    return make_transform(R, R @ shift_w + o)


def _finite_scalar(value: object, name: str) -> float:
    """``value`` as a finite float, or an :class:`InputError` naming ``name``."""
    arr = as_float_array(value, name)  # type: ignore[arg-type]
    if arr.ndim != 0:
        raise ShapeError(f"{name} must be a scalar, got shape {arr.shape}")
    return float(check_finite(arr, name))


def alpha1_from_points(a_base: ArrayLike, b_base: ArrayLike) -> float:
    """Eq. 11: ``alpha1 = atan((B_x - A_x) / (B_y - A_y))``, radians in ``[-pi/2, pi/2]``.

    ``alpha1`` is the angle of the horizontal projection of ``A -> B`` from the base y axis
    towards base +x (clockwise seen from above), folded into ``[-pi/2, pi/2]``, so ``A -> B``
    along base +y and along base -y both give ``alpha1 = 0``. For a WOCS turned by the
    Tait-Bryan angle ``alpha`` about base z (``A -> B`` along WOCS +y), ``alpha1 = -alpha``
    modulo ``pi``: the sign is opposite to eq. 7-9's alpha. We evaluate ``arctan2(dx, dy)``
    and fold it, which equals ``atan(dx / dy)`` for every ``dy != 0`` and gives the limit
    ``+-pi/2`` when ``dy = 0`` (where the printed formula divides by zero). Eq. 12 is
    unchanged by ``alpha1 -> alpha1 +- pi``, so the fold never matters there.

    Args:
        a_base: ``(3,)`` measured point A, base frame, metres.
        b_base: ``(3,)`` measured point B, base frame, metres.

    Raises:
        DegenerateGeometryError: A and B coincide in the base xy-plane (alpha1 undefined).
    """
    a = check_vector3(a_base, "A")
    b = check_vector3(b_base, "B")
    dx, dy = float(b[0] - a[0]), float(b[1] - a[1])
    if math.hypot(dx, dy) < COINCIDENT_TOL_M:
        raise DegenerateGeometryError(
            "points A and B coincide in the base xy-plane, so alpha1 (eq. 11) is undefined"
        )
    alpha1 = math.atan2(dx, dy)
    if alpha1 > math.pi / 2:
        alpha1 -= math.pi
    elif alpha1 < -math.pi / 2:
        alpha1 += math.pi
    return alpha1


def p3_estimate(
    a_base: ArrayLike, b_base: ArrayLike, beta1_rad: float, height_m: float = 0.050
) -> FloatArray:
    """Eq. 11-12: the constructed point P3, ``height_m`` above B on the assumed side face.

    ``P3 = B + h * (tan(beta1) cos(alpha1)^2, tan(beta1) sin(alpha1) cos(alpha1), 1)`` with
    ``alpha1`` from eq. 11 and ``h = height_m`` (the paper's 50 mm). The face is taken to be
    inclined by ``beta1`` from vertical with its top leaning towards base +x: rising ``h``
    along it moves ``h tan(beta1)`` horizontally, towards ``(cos alpha1, sin alpha1)``
    (approximately) in the base xy-plane. For a WOCS with y along base +y (the robot at
    -x) ``beta1`` is the Tait-Bryan beta of ``R_base_wobj``; with y along base -y (the
    robot at +x, WOCS x towards it) it is ``-beta``. Because eq. 11's alpha1 is minus the
    WOCS turn about z, the printed y-term has the opposite sign to the exact slope; that
    error lies along ``A -> B`` (= V1) to first order and so does not change
    ``X = V1 x V2``: it tilts the preliminary WOCS about its y axis by only about
    ``2 tan(beta1) sin(a)^2`` rad, ``a`` the turn of ``A -> B`` from the base y axis
    (0.1 deg at 3 deg, 1 deg at 10 deg, 4 deg at 20 deg), which later steps remove. We keep
    eq. 12 as printed.

    Args:
        a_base: ``(3,)`` measured point A (P1), base frame, metres.
        b_base: ``(3,)`` measured point B (P2), base frame, metres.
        beta1_rad: assumed inclination of the side face from vertical, radians (paper:
            15 deg), positive when the face's top leans towards base +x; a face leaning
            towards base -x needs a negative ``beta1``.
        height_m: height of P3 above B, metres (paper: 50 mm).

    Returns:
        ``(3,)`` the point P3, base frame, metres.

    Raises:
        DegenerateGeometryError: A and B coincide in the base xy-plane.
        InputError: ``beta1_rad`` not finite or ``|beta1| >= 90 deg``; ``height_m`` not > 0.
    """
    beta1 = _finite_scalar(beta1_rad, "beta1_rad")
    if abs(beta1) >= math.pi / 2:
        raise ShapeError(f"beta1_rad must lie in (-pi/2, pi/2), got {beta1:.6g}")
    height = check_positive(height_m, "height_m")
    alpha1 = alpha1_from_points(a_base, b_base)
    b = np.asarray(b_base, dtype=np.float64)
    ca, sa, tb = math.cos(alpha1), math.sin(alpha1), math.tan(beta1)
    return b + height * np.array([tb * ca * ca, tb * sa * ca, 1.0])
