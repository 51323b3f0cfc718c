"""Compiled exact step of the broad phase against a mesh: a convex shape and the triangles near it.

The triangles come from the bucket grid of the mesh's distance field
(:mod:`planner.cell.broad.distance_field`); each is first tested for separation along the shape's
axes and along its own normal, then by GJK (:mod:`planner.cell.kernels.gjk_kernels`).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from planner.cell.kernels import gjk_kernels as G
from planner.cell.kernels.gjk_kernels import support
from planner.cell.kernels.kernel_cache import configure

configure()  # before the first @njit: numba picks the cache directory then

#: Most triangles examined for one shape; beyond, the part is left to Bullet.
MAX_TRIANGLE_TESTS = 4000


@nb.njit(cache=True, inline="always")
def separated_by_axes(
    T: np.ndarray, tri: np.ndarray, c0: float, c1: float, c2: float, h0: float, h1: float,
    h2: float, thr: float,
) -> bool:  # fmt: skip
    """Triangle ``tri`` (rows, the frame of ``T``) is ``thr`` beyond the shape's box
    (centre ``c``, half extents ``h``, shape frame) along one of the shape's axes."""
    for ax in range(3):
        mn, mx = np.inf, -np.inf
        for v in range(3):
            d = (
                T[0, ax] * (tri[v, 0] - T[0, 3])
                + T[1, ax] * (tri[v, 1] - T[1, 3])
                + T[2, ax] * (tri[v, 2] - T[2, 3])
            )
            mn, mx = min(mn, d), max(mx, d)
        c = c0 if ax == 0 else c1 if ax == 1 else c2
        h = h0 if ax == 0 else h1 if ax == 1 else h2
        if mn - (c + h) >= thr or (c - h) - mx >= thr:
            return True
    return False


@nb.njit(cache=True)
def shape_vs_mesh(
    Tms, kind, dims, center, half, verts, vs, vc, f,
    b_origin, b_size, b_n, b_soff, b_start, b_toff, b_tris, m_voff, m_foff, m_verts, m_faces,
    thr, near, tri, eye, qlo, qhi,
) -> int:  # fmt: skip
    """A shape (``kind``, ``dims``, box ``center``/``half``, hull ``verts[vs : vs + vc]``) at
    pose ``Tms`` in mesh ``f``'s frame against the triangles near the box ``qlo..qhi`` (mesh
    frame): 1 when certified ``thr`` from every triangle of the bucket cells that box and the
    shape's box grown by ``thr`` both touch (each by its separation along the shape's axes, its
    own normal, else GJK); -1 when the first triangle not so separated is certified nearer
    than ``near``; else 0."""
    lo = np.empty(3, np.int64)
    hi = np.empty(3, np.int64)
    for k in range(3):
        dx, dy, dz = (1.0 if k == 0 else 0.0), (1.0 if k == 1 else 0.0), (1.0 if k == 2 else 0.0)
        up = min(support(kind, Tms, dims, verts, vs, vc, dx, dy, dz)[k] + thr, qhi[k])
        dn = max(support(kind, Tms, dims, verts, vs, vc, -dx, -dy, -dz)[k] - thr, qlo[k])
        if dn > up:
            return 1
        a = math.floor((dn - b_origin[f, k]) / b_size[f])
        b = math.floor((up - b_origin[f, k]) / b_size[f])
        if b < 0 or a >= b_n[f, k]:
            return 1  # no triangle of the mesh comes that near
        lo[k], hi[k] = max(a, 0), min(b, b_n[f, k] - 1)
    so, to = b_soff[f], b_toff[f]
    ny, nz = b_n[f, 1], b_n[f, 2]
    work = 0
    c0, c1, c2 = center[0], center[1], center[2]
    h0, h1, h2 = half[0], half[1], half[2]
    for i in range(lo[0], hi[0] + 1):
        for j in range(lo[1], hi[1] + 1):
            for k in range(lo[2], hi[2] + 1):
                cell = (i * ny + j) * nz + k
                for q in range(b_start[so + cell], b_start[so + cell + 1]):
                    work += 1
                    if work > MAX_TRIANGLE_TESTS:
                        return 0  # too many to look at: left to Bullet
                    face = b_tris[to + q]
                    for v in range(3):
                        row = m_voff[f] + m_faces[m_foff[f] + face, v]
                        tri[v, 0], tri[v, 1], tri[v, 2] = (
                            m_verts[row, 0],
                            m_verts[row, 1],
                            m_verts[row, 2],
                        )
                    if separated_by_axes(Tms, tri, c0, c1, c2, h0, h1, h2, thr):
                        continue
                    # separation along the triangle's normal
                    ux, uy, uz = tri[1, 0] - tri[0, 0], tri[1, 1] - tri[0, 1], tri[1, 2] - tri[0, 2]
                    wx, wy, wz = tri[2, 0] - tri[0, 0], tri[2, 1] - tri[0, 1], tri[2, 2] - tri[0, 2]
                    nx, ny_, nz_ = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
                    nn = math.sqrt(nx * nx + ny_ * ny_ + nz_ * nz_)
                    if nn > 1e-300:
                        nx, ny_, nz_ = nx / nn, ny_ / nn, nz_ / nn
                        off = nx * tri[0, 0] + ny_ * tri[0, 1] + nz_ * tri[0, 2]
                        px, py, pz = support(kind, Tms, dims, verts, vs, vc, nx, ny_, nz_)
                        qx, qy, qz = support(kind, Tms, dims, verts, vs, vc, -nx, -ny_, -nz_)
                        s_hi = nx * px + ny_ * py + nz_ * pz
                        s_lo = nx * qx + ny_ * qy + nz_ * qz
                        if s_lo - off >= thr or off - s_hi >= thr:
                            continue
                    r = G.gjk_classify(
                        kind, Tms, dims, verts, vs, vc, G.HULL, eye, dims, tri, 0, 3, thr, near
                    )
                    if r != 1:
                        return r
    return 1
