"""Compiled kernels of the distance fields: their build and their lower-bound query.

Point-triangle distances (Ericson), the exact band of a field, and the trilinear lower bound
(see :mod:`planner.cell.broad.distance_field`). Compiled with numba (``cache=True``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from planner.cell.kernels.kernel_cache import configure

configure()  # before the first @njit: numba picks the cache directory then


@nb.njit(cache=True, fastmath=False)
def point_triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    """Distance from point ``p`` to triangle ``abc`` (Ericson, Real-Time Collision Detection)."""
    abx, aby, abz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    acx, acy, acz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    apx, apy, apz = p[0] - a[0], p[1] - a[1], p[2] - a[2]
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return math.sqrt(apx * apx + apy * apy + apz * apz)
    bpx, bpy, bpz = p[0] - b[0], p[1] - b[1], p[2] - b[2]
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return math.sqrt(bpx * bpx + bpy * bpy + bpz * bpz)
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        x, y, z = apx - v * abx, apy - v * aby, apz - v * abz
        return math.sqrt(x * x + y * y + z * z)
    cpx, cpy, cpz = p[0] - c[0], p[1] - c[1], p[2] - c[2]
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return math.sqrt(cpx * cpx + cpy * cpy + cpz * cpz)
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        x, y, z = apx - w * acx, apy - w * acy, apz - w * acz
        return math.sqrt(x * x + y * y + z * z)
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        x = bpx - w * (c[0] - b[0])
        y = bpy - w * (c[1] - b[1])
        z = bpz - w * (c[2] - b[2])
        return math.sqrt(x * x + y * y + z * z)
    denom = 1.0 / (va + vb + vc)
    v = vb * denom
    w = vc * denom
    x = apx - v * abx - w * acx
    y = apy - v * aby - w * acy
    z = apz - v * abz - w * acz
    return math.sqrt(x * x + y * y + z * z)


@nb.njit(cache=True)
def rasterize_band(
    vertices: np.ndarray,
    faces: np.ndarray,
    origin: np.ndarray,
    h: float,
    n: np.ndarray,
    band: float,
    out: np.ndarray,
) -> None:
    """Exact distances to the mesh at the grid nodes within ``band`` of some triangle's box.

    ``out (nx, ny, nz)`` holds +inf (or earlier values) and is lowered in place to the exact
    distance from each node near a triangle to the nearest such triangle.
    """
    p = np.empty(3)
    for f in range(faces.shape[0]):
        a, b, c = vertices[faces[f, 0]], vertices[faces[f, 1]], vertices[faces[f, 2]]
        lo = np.empty(3, np.int64)
        hi = np.empty(3, np.int64)
        for k in range(3):
            mn = min(a[k], b[k], c[k]) - band
            mx = max(a[k], b[k], c[k]) + band
            lo[k] = max(0, math.ceil((mn - origin[k]) / h))
            hi[k] = min(n[k] - 1, math.floor((mx - origin[k]) / h))
        for i in range(lo[0], hi[0] + 1):
            p[0] = origin[0] + i * h
            for j in range(lo[1], hi[1] + 1):
                p[1] = origin[1] + j * h
                for k in range(lo[2], hi[2] + 1):
                    p[2] = origin[2] + k * h
                    d = point_triangle_distance(p, a, b, c)
                    if d < out[i, j, k]:
                        out[i, j, k] = d


@nb.njit(cache=True, inline="always")
def field_lb(
    f_val: np.ndarray, x: float, y: float, z: float, o0: float, o1: float, o2: float, h: float,
    nx: int, ny: int, nz: int, off: int, lo0: float, lo1: float, lo2: float, hi0: float,
    hi1: float, hi2: float,
) -> float:  # fmt: skip
    """:func:`field_lower_bound` with the field's parameters as scalars (one array argument:
    array arguments cost reference counting on every call)."""
    dx = max(lo0 - x, 0.0, x - hi0)
    dy = max(lo1 - y, 0.0, y - hi1)
    dz = max(lo2 - z, 0.0, z - hi2)
    box = math.sqrt(dx * dx + dy * dy + dz * dz)
    gx, gy, gz = (x - o0) / h, (y - o1) / h, (z - o2) / h
    if not (gx >= 0.0 and gy >= 0.0 and gz >= 0.0):
        return box
    i, j, k = int(gx), int(gy), int(gz)
    if i >= nx - 1 or j >= ny - 1 or k >= nz - 1:
        return box
    tx, ty, tz = gx - i, gy - j, gz - k
    base = off + (i * ny + j) * nz + k
    sy, sx = nz, ny * nz
    v000, v001 = f_val[base], f_val[base + 1]
    v010, v011 = f_val[base + sy], f_val[base + sy + 1]
    v100, v101 = f_val[base + sx], f_val[base + sx + 1]
    v110, v111 = f_val[base + sx + sy], f_val[base + sx + sy + 1]
    c00 = v000 + (v001 - v000) * tz
    c01 = v010 + (v011 - v010) * tz
    c10 = v100 + (v101 - v100) * tz
    c11 = v110 + (v111 - v110) * tz
    c0 = c00 + (c01 - c00) * ty
    c1 = c10 + (c11 - c10) * ty
    val = c0 + (c1 - c0) * tx
    err = h * math.sqrt(tx * (1.0 - tx) + ty * (1.0 - ty) + tz * (1.0 - tz))
    return max(box, val - err)


@nb.njit(cache=True)
def field_lower_bound(
    x: float,
    y: float,
    z: float,
    f: int,
    f_origin: np.ndarray,
    f_h: np.ndarray,
    f_n: np.ndarray,
    f_off: np.ndarray,
    f_val: np.ndarray,
    f_lo: np.ndarray,
    f_hi: np.ndarray,
) -> float:
    """Lower bound of the distance from body-frame point ``(x, y, z)`` to mesh ``f``, m.

    The distance to the mesh's bounding box, and inside the grid the trilinear interpolation
    of the node values minus its error bound ``h * sqrt(sum t (1 - t))`` (the distance is
    1-Lipschitz; see ``docs/cell.md``): whichever is larger.
    """
    return field_lb(
        f_val, x, y, z, f_origin[f, 0], f_origin[f, 1], f_origin[f, 2], f_h[f],
        f_n[f, 0], f_n[f, 1], f_n[f, 2], f_off[f], f_lo[f, 0], f_lo[f, 1], f_lo[f, 2],
        f_hi[f, 0], f_hi[f, 1], f_hi[f, 2],
    )  # fmt: skip
