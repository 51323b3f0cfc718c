"""The first contact of a sweeping ball with a few triangles, compiled (numba).

:func:`planner.sim.touch.sweep_contact` solves, for the triangles a touch probe's rays met near
their first hit, where the stylus ball moving along its approach first touches each of them:
at its face (the tangent point inside the triangle), at one of its edges or at a corner. Written
with numpy it spent about 0.25 ms a search on a dozen passes over ``(K, 3, 3)`` arrays of a
handful of triangles; this loop does it in a few microseconds, with the same formulas (the
same contacts; travels within about 2e-14 m: ``tests/planner/sim/test_sweep_kernel.py`` holds
it to the numpy version).

numba takes its cache directory when this module is imported, which
:func:`~planner.sim.touch.sweep_contact` does at its first call, and compiles the kernel (or
loads it from that cache) at its first call.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

#: A face counts as facing the motion when ``n . a`` is below minus this.
FACING_COS = 1e-12
#: How far outside an edge the tangent point may lie and count as inside, as ``(e x w) . n``
#: (the edge's length times the point's distance inside it: m^2).
INSIDE_TOL_M2 = 1e-12
#: A quadratic's leading coefficient below this has no root (the motion parallel to an edge).
MIN_LEADING = 1e-18

#: What :func:`first_contact` met: nothing, a face, an edge, a corner.
NONE, FACE, EDGE, CORNER = -1, 0, 1, 2


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _first_root(A: float, half_b: float, c: float) -> float:  # pragma: no cover - compiled
    """The smaller root of ``A t^2 + 2 half_b t + c = 0``; ``inf`` when none."""
    disc = half_b * half_b - A * c
    if A > MIN_LEADING and disc >= 0.0:
        return (-half_b - math.sqrt(disc)) / A
    return math.inf


@numba.njit(cache=True, nogil=True, error_model="numpy")
def first_contact(
    normals: Any,
    offsets: Any,
    vertices: Any,
    triangles: Any,
    centre0: Any,
    a: Any,
    r: float,
) -> tuple[int, float, int, int, float]:  # pragma: no cover - compiled
    """Where a ball of radius ``r`` moving from ``centre0`` along unit ``a`` first meets
    ``triangles`` (mesh frame, m).

    Args:
        normals: ``(F, 3)`` the mesh's unit triangle normals.
        offsets: ``(F,)`` their plane offsets (``n . x = d``), m.
        vertices: ``(F, 3, 3)`` their corners, m.
        triangles: ``(K,)`` the triangles to test.
        centre0: ``(3,)`` the ball's centre at the start, m.
        a: ``(3,)`` the unit direction of motion.
        r: the ball's radius, m.

    Returns:
        ``(kind, travel, k, i, s)``: :data:`FACE`, :data:`EDGE`, :data:`CORNER` or :data:`NONE`;
        the travel to the contact (m, ``inf`` for none); the index into ``triangles`` of the
        triangle met; its edge ``i`` (from corner ``i`` to corner ``i + 1``) or corner ``i``;
        for an edge, how far along it from corner ``i`` the contact lies (m). On ties the face
        wins over an edge and an edge over a corner, and the first triangle over later ones.
    """
    best_f, kf = math.inf, -1
    best_e, ke, ie, se = math.inf, -1, -1, 0.0
    best_c, kc, ic = math.inf, -1, -1
    c0, c1, c2 = centre0[0], centre0[1], centre0[2]
    a0, a1, a2 = a[0], a[1], a[2]
    for k in range(triangles.shape[0]):
        f = triangles[k]
        n0, n1, n2 = normals[f, 0], normals[f, 1], normals[f, 2]
        v = vertices[f]
        cos = (n0 * a0 + n1 * a1) + n2 * a2
        if cos < -FACING_COS:  # the face: its plane at distance r, the tangent point inside
            tf = (((n0 * c0 + n1 * c1) + n2 * c2) - offsets[f] - r) / -cos
            q0, q1, q2 = c0 + tf * a0 - r * n0, c1 + tf * a1 - r * n1, c2 + tf * a2 - r * n2
            inside = True
            for i in range(3):
                j = (i + 1) % 3
                e0, e1, e2 = v[j, 0] - v[i, 0], v[j, 1] - v[i, 1], v[j, 2] - v[i, 2]
                w0, w1, w2 = q0 - v[i, 0], q1 - v[i, 1], q2 - v[i, 2]
                x0, x1, x2 = e1 * w2 - e2 * w1, e2 * w0 - e0 * w2, e0 * w1 - e1 * w0
                if (x0 * n0 + x1 * n1) + x2 * n2 < -INSIDE_TOL_M2:
                    inside = False
            if inside and tf < best_f:
                best_f, kf = tf, k
        for i in range(3):
            j = (i + 1) % 3
            e0, e1, e2 = v[j, 0] - v[i, 0], v[j, 1] - v[i, 1], v[j, 2] - v[i, 2]
            length = math.sqrt((e0 * e0 + e1 * e1) + e2 * e2)
            u0, u1, u2 = c0 - v[i, 0], c1 - v[i, 1], c2 - v[i, 2]
            te = math.inf  # a degenerate edge (its corners coincide) is met at its corner
            if length > 0.0:  # the edge: the moving centre's distance to its line reaches r
                e0, e1, e2 = e0 / length, e1 / length, e2 / length
                ue = (u0 * e0 + u1 * e1) + u2 * e2
                p0, p1, p2 = u0 - ue * e0, u1 - ue * e1, u2 - ue * e2
                ae = (e0 * a0 + e1 * a1) + e2 * a2
                b0, b1, b2 = a0 - ae * e0, a1 - ae * e1, a2 - ae * e2
                te = _first_root(
                    (b0 * b0 + b1 * b1) + b2 * b2,
                    (p0 * b0 + p1 * b1) + p2 * b2,
                    ((p0 * p0 + p1 * p1) + p2 * p2) - r * r,
                )
            if math.isfinite(te):
                s = ((c0 + te * a0 - v[i, 0]) * e0 + (c1 + te * a1 - v[i, 1]) * e1) + (
                    c2 + te * a2 - v[i, 2]
                ) * e2
                if 0.0 <= s <= length and te < best_e:
                    best_e, ke, ie, se = te, k, i, s
            # the corner i: the distance from the moving centre to it reaches r
            tc = _first_root(
                1.0, (u0 * a0 + u1 * a1) + u2 * a2, ((u0 * u0 + u1 * u1) + u2 * u2) - r * r
            )
            if tc < best_c:
                best_c, kc, ic = tc, k, i
    if math.isfinite(best_f) and best_f <= best_e and best_f <= best_c:
        return FACE, best_f, kf, -1, 0.0
    if math.isfinite(best_e) and best_e <= best_c:
        return EDGE, best_e, ke, ie, se
    if math.isfinite(best_c):
        return CORNER, best_c, kc, ic, 0.0
    return NONE, math.inf, -1, -1, 0.0


def load_kernel() -> None:
    """Load (or compile) the kernel now, for the argument types
    :func:`~planner.sim.touch.sweep_contact` passes: a fork server does it once for all its
    workers (:mod:`planner.sim.worker_preload`)."""
    tri = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    tri.setflags(write=False)  # as the caster's corners (trimesh's cached, read-only array)
    first_contact(
        np.zeros((1, 3)),
        np.zeros(1),
        tri,
        np.zeros(1, dtype=np.int64),
        np.zeros(3),
        np.ones(3),
        1.0,
    )
