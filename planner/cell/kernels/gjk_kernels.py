"""GJK distance bounds between convex shapes, compiled with numba (the broad phase's exact step).

A shape is given by its kind, its pose ``T (3, 4)`` (world from shape, C-contiguous: one
compiled specialisation for all callers) and its
dimensions: :data:`BOX` (half extents), :data:`CYLINDER` (radius, half length; axis = shape
z), :data:`SPHERE` (radius), :data:`CAPSULE` (radius, half length of the segment) or
:data:`HULL` (the convex hull of vertices ``verts[start : start + count]``, shape frame; a
triangle is a hull of three). :func:`gjk_separated` walks GJK on the Minkowski difference
``A - B`` and returns as soon as either

- a certified lower bound reaches the threshold: every direction ``v`` gives
  ``dist(A, B) >= (v . w) / |v|`` with ``w`` the support point of ``A - B`` along ``-v``
  (exact, whatever the simplex did), or
- a point of ``A - B`` (the closest point of the current simplex) is nearer than the threshold.

It answers "separated by at least the threshold" only with a certificate; anything unsure
(degenerate simplex, too many iterations) counts as not separated, so the caller asks Bullet.
:func:`gjk_classify` also certifies the other way: the shapes overlap, or a point of
``A - B`` (a pair of points, one on each) is nearer than a second threshold.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from planner.cell.kernels.kernel_cache import configure
from planner.cell.kernels.lazy_kernel import lazy_njit

configure()  # before the first @njit: numba picks the cache directory then

BOX, CYLINDER, SPHERE, CAPSULE, HULL = 0, 1, 2, 3, 4
_MAX_ITER = 40
# Explicit signatures: every caller shares one compiled version (constant arguments would
# otherwise make numba compile a literal-typed copy per call site, seconds each); compiled on
# first use, not at import (planner.cell.kernels.lazy_kernel).
_M = "float64[:, ::1]"
_V = "float64[::1]"
_SUPPORT = f"UniTuple(float64, 3)(int64, {_M}, {_V}, {_M}, int64, int64, float64, float64, float64)"
_SHAPE = f"int64, {_M}, {_V}, {_M}, int64, int64"
_CLASSIFY = f"int64({_SHAPE}, {_SHAPE}, float64, float64)"


@lazy_njit(_SUPPORT)
def support(
    kind: int,
    T: np.ndarray,
    dims: np.ndarray,
    verts: np.ndarray,
    start: int,
    count: int,
    dx: float,
    dy: float,
    dz: float,
) -> tuple[float, float, float]:
    """The point of the shape farthest along world direction ``d`` (world frame)."""
    lx = T[0, 0] * dx + T[1, 0] * dy + T[2, 0] * dz
    ly = T[0, 1] * dx + T[1, 1] * dy + T[2, 1] * dz
    lz = T[0, 2] * dx + T[1, 2] * dy + T[2, 2] * dz
    if kind == BOX:
        sx = dims[0] if lx >= 0.0 else -dims[0]
        sy = dims[1] if ly >= 0.0 else -dims[1]
        sz = dims[2] if lz >= 0.0 else -dims[2]
    elif kind in (CYLINDER, CAPSULE):
        r, hz = dims[0], dims[1]
        n = math.sqrt(lx * lx + ly * ly)
        if kind == CYLINDER:
            if n > 1e-300:
                sx, sy = r * lx / n, r * ly / n
            else:
                sx, sy = r, 0.0
            sz = hz if lz >= 0.0 else -hz
        else:
            m = math.sqrt(lx * lx + ly * ly + lz * lz)
            if m > 1e-300:
                sx, sy, sz = r * lx / m, r * ly / m, r * lz / m
            else:
                sx, sy, sz = r, 0.0, 0.0
            sz += hz if lz >= 0.0 else -hz
    elif kind == SPHERE:
        m = math.sqrt(lx * lx + ly * ly + lz * lz)
        r = dims[0]
        if m > 1e-300:
            sx, sy, sz = r * lx / m, r * ly / m, r * lz / m
        else:
            sx, sy, sz = r, 0.0, 0.0
    else:
        best = -np.inf
        sx, sy, sz = 0.0, 0.0, 0.0
        for k in range(start, start + count):
            d = verts[k, 0] * lx + verts[k, 1] * ly + verts[k, 2] * lz
            if d > best:
                best = d
                sx, sy, sz = verts[k, 0], verts[k, 1], verts[k, 2]
    return (
        T[0, 0] * sx + T[0, 1] * sy + T[0, 2] * sz + T[0, 3],
        T[1, 0] * sx + T[1, 1] * sy + T[1, 2] * sz + T[1, 3],
        T[2, 0] * sx + T[2, 1] * sy + T[2, 2] * sz + T[2, 3],
    )


@lazy_njit(f"void({_M}, int64, float64, float64, float64)")
def _set(W: np.ndarray, i: int, x: float, y: float, z: float) -> None:
    W[i, 0], W[i, 1], W[i, 2] = x, y, z


@nb.njit(cache=True)
def _closest_segment(W: np.ndarray, v: np.ndarray) -> int:
    """Closest point ``v`` of segment ``W[0] W[1]`` to the origin; reduce ``W``; new size."""
    ax, ay, az = W[0, 0], W[0, 1], W[0, 2]
    ex, ey, ez = W[1, 0] - ax, W[1, 1] - ay, W[1, 2] - az
    den = ex * ex + ey * ey + ez * ez
    tt = -(ax * ex + ay * ey + az * ez) / den if den > 0.0 else 0.0
    if tt <= 0.0:
        v[0], v[1], v[2] = ax, ay, az
        return 1
    if tt >= 1.0:
        _set(W, 0, W[1, 0], W[1, 1], W[1, 2])
        v[0], v[1], v[2] = W[0, 0], W[0, 1], W[0, 2]
        return 1
    v[0], v[1], v[2] = ax + tt * ex, ay + tt * ey, az + tt * ez
    return 2


@lazy_njit(f"int64({_M}, int64, int64, int64, {_M}, {_V})")
def _closest_triangle(
    W: np.ndarray, i0: int, i1: int, i2: int, out: np.ndarray, v: np.ndarray
) -> int:
    """Closest point ``v`` of triangle ``W[i0], W[i1], W[i2]`` to the origin (Ericson's
    regions); the vertices of its feature go to ``out[:n]``; returns ``n``."""
    ax, ay, az = W[i0, 0], W[i0, 1], W[i0, 2]
    bx, by, bz = W[i1, 0], W[i1, 1], W[i1, 2]
    cx, cy, cz = W[i2, 0], W[i2, 1], W[i2, 2]
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    d1 = -(abx * ax + aby * ay + abz * az)
    d2 = -(acx * ax + acy * ay + acz * az)
    if d1 <= 0.0 and d2 <= 0.0:
        _set(out, 0, ax, ay, az)
        v[0], v[1], v[2] = ax, ay, az
        return 1
    d3 = -(abx * bx + aby * by + abz * bz)
    d4 = -(acx * bx + acy * by + acz * bz)
    if d3 >= 0.0 and d4 <= d3:
        _set(out, 0, bx, by, bz)
        v[0], v[1], v[2] = bx, by, bz
        return 1
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        t = d1 / (d1 - d3)
        _set(out, 0, ax, ay, az)
        _set(out, 1, bx, by, bz)
        v[0], v[1], v[2] = ax + t * abx, ay + t * aby, az + t * abz
        return 2
    d5 = -(abx * cx + aby * cy + abz * cz)
    d6 = -(acx * cx + acy * cy + acz * cz)
    if d6 >= 0.0 and d5 <= d6:
        _set(out, 0, cx, cy, cz)
        v[0], v[1], v[2] = cx, cy, cz
        return 1
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        t = d2 / (d2 - d6)
        _set(out, 0, ax, ay, az)
        _set(out, 1, cx, cy, cz)
        v[0], v[1], v[2] = ax + t * acx, ay + t * acy, az + t * acz
        return 2
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        _set(out, 0, bx, by, bz)
        _set(out, 1, cx, cy, cz)
        v[0], v[1], v[2] = bx + t * (cx - bx), by + t * (cy - by), bz + t * (cz - bz)
        return 2
    den = 1.0 / (va + vb + vc)
    t, u = vb * den, vc * den
    _set(out, 0, ax, ay, az)
    _set(out, 1, bx, by, bz)
    _set(out, 2, cx, cy, cz)
    v[0], v[1], v[2] = ax + t * abx + u * acx, ay + t * aby + u * acy, az + t * abz + u * acz
    return 3


@nb.njit(cache=True)
def _side(W: np.ndarray, i: int, j: int, k: int, o: int) -> bool:
    """The origin lies beyond face ``i j k`` of the tetrahedron (opposite vertex ``o``)."""
    ax, ay, az = W[i, 0], W[i, 1], W[i, 2]
    ux, uy, uz = W[j, 0] - ax, W[j, 1] - ay, W[j, 2] - az
    wx, wy, wz = W[k, 0] - ax, W[k, 1] - ay, W[k, 2] - az
    nx, ny, nz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
    so = -(nx * ax + ny * ay + nz * az)
    sd = nx * (W[o, 0] - ax) + ny * (W[o, 1] - ay) + nz * (W[o, 2] - az)
    return so * sd < 0.0


@nb.njit(cache=True)
def _closest_tetra(W: np.ndarray, scratch: np.ndarray, v: np.ndarray) -> int:
    """Closest point of tetrahedron ``W[0:4]`` to the origin; 0 when it holds the origin."""
    best = np.inf
    nkeep = 0
    keep = scratch[0:3]
    tri = scratch[3:6]
    vx = vy = vz = 0.0
    for f in range(4):
        if f == 0:
            i, j, k, o = 0, 1, 2, 3
        elif f == 1:
            i, j, k, o = 0, 1, 3, 2
        elif f == 2:
            i, j, k, o = 0, 2, 3, 1
        else:
            i, j, k, o = 1, 2, 3, 0
        if not _side(W, i, j, k, o):
            continue
        m = _closest_triangle(W, i, j, k, tri, v)
        dist = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
        if dist < best:
            best, nkeep = dist, m
            vx, vy, vz = v[0], v[1], v[2]
            for r in range(m):
                _set(keep, r, tri[r, 0], tri[r, 1], tri[r, 2])
    if nkeep == 0:
        v[0], v[1], v[2] = 0.0, 0.0, 0.0
        return 0
    for r in range(nkeep):
        _set(W, r, keep[r, 0], keep[r, 1], keep[r, 2])
    v[0], v[1], v[2] = vx, vy, vz
    return nkeep


@nb.njit(cache=True)
def start_direction(TA: np.ndarray, TB: np.ndarray, v: np.ndarray) -> None:
    """GJK's first direction ``v``: from B's origin to A's (x when they coincide)."""
    v[0], v[1], v[2] = TA[0, 3] - TB[0, 3], TA[1, 3] - TB[1, 3], TA[2, 3] - TB[2, 3]
    if v[0] * v[0] + v[1] * v[1] + v[2] * v[2] < 1e-24:
        v[0] = 1.0


@lazy_njit(f"int64({_M}, int64, float64, float64, float64, {_M}, {_V})")
def add_point(
    W: np.ndarray, n: int, wx: float, wy: float, wz: float, scratch: np.ndarray, v: np.ndarray
) -> int:
    """Add the support point ``w`` to the simplex ``W[:n]``, reduce it to the feature nearest
    the origin and put that feature's closest point in ``v``; returns the new size, 0 when the
    tetrahedron holds the origin (the shapes overlap)."""
    _set(W, n, wx, wy, wz)
    n += 1
    if n == 1:
        v[0], v[1], v[2] = wx, wy, wz
    elif n == 2:
        n = _closest_segment(W, v)
    elif n == 3:
        n = _closest_triangle(W, 0, 1, 2, scratch, v)
        for r in range(n):
            _set(W, r, scratch[r, 0], scratch[r, 1], scratch[r, 2])
    else:
        n = _closest_tetra(W, scratch, v)
    return n


@lazy_njit(_CLASSIFY)
def gjk_classify(
    kA: int, TA: np.ndarray, dA: np.ndarray, vA: np.ndarray, sA: int, cA: int,
    kB: int, TB: np.ndarray, dB: np.ndarray, vB: np.ndarray, sB: int, cB: int,
    clear_thr: float, near_thr: float,
) -> int:  # fmt: skip
    """1: A and B are certified at least ``clear_thr`` apart; -1: they overlap or a point of
    ``A - B`` is nearer than ``near_thr`` (their distance is below it); 0: unsure."""
    W = np.empty((4, 3))
    scratch = np.empty((6, 3))
    v = np.empty(3)
    start_direction(TA, TB, v)
    n = 0
    lb = -np.inf
    for _ in range(_MAX_ITER):
        ax, ay, az = support(kA, TA, dA, vA, sA, cA, -v[0], -v[1], -v[2])
        bx, by, bz = support(kB, TB, dB, vB, sB, cB, v[0], v[1], v[2])
        wx, wy, wz = ax - bx, ay - by, az - bz
        vn = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
        if vn <= 0.0:
            return -1 if near_thr > 0.0 else 0
        lb = max(lb, (v[0] * wx + v[1] * wy + v[2] * wz) / vn)
        if lb >= clear_thr:
            return 1
        if n > 0 and vn < near_thr:
            return -1  # a point of A - B nearer than near_thr
        if n > 0 and vn < clear_thr and lb >= near_thr:
            return 0  # neither: nearer than clear_thr, not nearer than near_thr
        # stalled: the new point does not get closer than the current one
        if n > 0 and vn - lb <= 1e-12 * max(vn, 1e-3):
            return 0
        n = add_point(W, n, wx, wy, wz, scratch, v)
        if n == 0:
            return -1 if near_thr > 0.0 else 0  # the origin is inside: overlap
    return 0


@lazy_njit(f"boolean({_SHAPE}, {_SHAPE}, float64)")
def gjk_separated(
    kA: int, TA: np.ndarray, dA: np.ndarray, vA: np.ndarray, sA: int, cA: int,
    kB: int, TB: np.ndarray, dB: np.ndarray, vB: np.ndarray, sB: int, cB: int,
    thr: float,
) -> bool:  # fmt: skip
    """True only when shapes A and B are certified at least ``thr`` apart (see module)."""
    return gjk_classify(kA, TA, dA, vA, sA, cA, kB, TB, dB, vB, sB, cB, thr, -np.inf) == 1
