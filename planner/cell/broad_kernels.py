"""Compiled kernels of the broad phase: point-triangle distances, the distance-field build,
lower bounds of sphere trees against environment bodies and against each other.

Everything here is a lower bound on a true (nominal-geometry) distance, m: the callers add
Bullet's own shape margins and a safety before they call a part clear
(:mod:`planner.cell.broad_phase`). Compiled with numba (``cache=True``: the machine code is
kept next to this file after the first run). The kernels run on one core: on a shared machine
numba's parallel loops waited for busy cores (up to 100x slower in a measured run), and the
batches of a UI click are small.

Array layouts (all float64 unless said):

- sphere trees, all links concatenated: ``node_c (Nn, 3)`` centres in their link frame,
  ``node_r (Nn,)`` radii, ``node_child (Nn,)`` int64 index of the first of two consecutive
  children, -1 for a leaf; ``link_root (L,)`` int64 the root node of each link;
- link poses: ``T_links (M, L, 3, 4)`` world pose of every link for every candidate;
- environment bodies: ``env_kind (E,)`` int64 (:data:`BOX`, :data:`CYLINDER`, :data:`SPHERE`,
  :data:`FIELD`), ``env_Tinv (E, 3, 4)`` world -> body frame, ``env_dims (E, 3)`` box half
  extents, cylinder (radius, half height, 0), sphere (radius, 0, 0); ``env_field (E,)`` int64;
- distance fields: ``f_origin (F, 3)``, ``f_h (F,)`` spacing, ``f_n (F, 3)`` int64 node counts,
  ``f_off (F,)`` int64 offset into the flat float32 ``f_val``, ``f_lo``/``f_hi (F, 3)`` the
  mesh's bounding box (body frame).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from planner.cell import gjk_kernels as G
from planner.cell.gjk_kernels import support

BOX, CYLINDER, SPHERE, FIELD = 0, 1, 2, 3
#: Depth of the traversal stacks (a binary tree of a few hundred leaves is ~10 deep).
_STACK = 256
#: Most triangles the exact step examines for one shape; beyond, the part is left to Bullet.
MAX_TRIANGLE_TESTS = 4000
#: Most leaves of one link the exact step looks at (beyond, the part is left to Bullet).
_LEAVES = 64


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
def _field_lb(
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
    return _field_lb(
        f_val, x, y, z, f_origin[f, 0], f_origin[f, 1], f_origin[f, 2], f_h[f],
        f_n[f, 0], f_n[f, 1], f_n[f, 2], f_off[f], f_lo[f, 0], f_lo[f, 1], f_lo[f, 2],
        f_hi[f, 0], f_hi[f, 1], f_hi[f, 2],
    )  # fmt: skip


@nb.njit(cache=True, inline="always")
def _world(T: np.ndarray, c: np.ndarray) -> tuple[float, float, float]:
    return (
        T[0, 0] * c[0] + T[0, 1] * c[1] + T[0, 2] * c[2] + T[0, 3],
        T[1, 0] * c[0] + T[1, 1] * c[1] + T[1, 2] * c[2] + T[1, 3],
        T[2, 0] * c[0] + T[2, 1] * c[1] + T[2, 2] * c[2] + T[2, 3],
    )


@nb.njit(cache=True, inline="always")
def _compose(A: np.ndarray, B: np.ndarray, out: np.ndarray) -> None:
    """``out = A @ B`` for 3x4 rigid transforms."""
    for i in range(3):
        for j in range(4):
            v = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]
            out[i, j] = v + A[i, 3] if j == 3 else v


@nb.njit(cache=True, inline="always")
def _primitive_lb(
    kind: int, x: float, y: float, z: float, d0: float, d1: float, d2: float
) -> float:
    """Distance from body-frame point ``(x, y, z)`` to a box (half extents ``d``), a cylinder
    (radius ``d0``, half height ``d1``) or a sphere (radius ``d0``); 0 inside."""
    if kind == BOX:
        dx = max(abs(x) - d0, 0.0)
        dy = max(abs(y) - d1, 0.0)
        dz = max(abs(z) - d2, 0.0)
        return math.sqrt(dx * dx + dy * dy + dz * dz)
    if kind == CYLINDER:
        dr = max(math.sqrt(x * x + y * y) - d0, 0.0)
        dz = max(abs(z) - d1, 0.0)
        return math.sqrt(dr * dr + dz * dz)
    return max(math.sqrt(x * x + y * y + z * z) - d0, 0.0)


@nb.njit(cache=True, inline="always")
def _separated_by_axes(
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
def _shape_vs_mesh(
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
                    if _separated_by_axes(Tms, tri, c0, c1, c2, h0, h1, h2, thr):
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


@nb.njit(cache=True)
def parts_state(
    T_links, todo, part_link, part_env, part_thr, part_near,
    node_c, node_r, node_child, link_root, node_shape,
    sh_kind, sh_T, sh_dims, sh_center, sh_half, sh_vs, sh_vc, verts, link_sh0, link_shn,
    env_kind, env_Tinv, env_T, env_dims, env_field,
    f_origin, f_h, f_n, f_off, f_val, f_lo, f_hi,
    b_origin, b_size, b_n, b_soff, b_start, b_toff, b_tris, m_voff, m_foff, m_verts, m_faces,
    exact,
):  # fmt: skip
    """``(state (M, P) int8, opened (M,))`` of the env parts (link, body, clear and near
    thresholds) for the ``todo (M, P)`` entries (others 0): 1 when the link's sphere tree
    clears it or (``exact``) GJK certifies its shapes ``part_thr`` from the body (for a mesh:
    from the triangles near the leaves not cleared); -1 when (``exact``) GJK certifies a shape
    nearer than ``part_near``; else 0. ``opened``: the leaves not cleared by the trees, per
    candidate (a rough measure of how deep it sits in the obstacles)."""
    M, P = todo.shape
    out = np.zeros((M, P), dtype=np.int8)
    opened = np.zeros(M, dtype=np.int64)
    stack = np.empty(_STACK, np.int64)
    leaves = np.empty(_LEAVES, np.int64)
    Ts = np.empty((3, 4))
    Tms = np.empty((3, 4))
    Tml = np.empty((3, 4))
    tri = np.empty((3, 3))
    eye = np.zeros((3, 4))
    eye[0, 0] = eye[1, 1] = eye[2, 2] = 1.0
    qlo = np.empty(3)
    qhi = np.empty(3)
    for m in range(M):
        for p in range(P):
            if not todo[m, p]:
                continue
            link, e, thr, near = part_link[p], part_env[p], part_thr[p], part_near[p]
            T = T_links[m, link]
            # the body: world -> body frame, its kind and sizes, its field (as scalars: array
            # arguments cost reference counting on every call)
            Ti = env_Tinv[e]
            t00, t01, t02, t03 = Ti[0, 0], Ti[0, 1], Ti[0, 2], Ti[0, 3]
            t10, t11, t12, t13 = Ti[1, 0], Ti[1, 1], Ti[1, 2], Ti[1, 3]
            t20, t21, t22, t23 = Ti[2, 0], Ti[2, 1], Ti[2, 2], Ti[2, 3]
            kind = env_kind[e]
            d0, d1, d2 = env_dims[e, 0], env_dims[e, 1], env_dims[e, 2]
            f = env_field[e]
            if kind == FIELD:
                o0, o1, o2, h = f_origin[f, 0], f_origin[f, 1], f_origin[f, 2], f_h[f]
                nx, ny, nz, off = f_n[f, 0], f_n[f, 1], f_n[f, 2], f_off[f]
                lo0, lo1, lo2 = f_lo[f, 0], f_lo[f, 1], f_lo[f, 2]
                hi0, hi1, hi2 = f_hi[f, 0], f_hi[f, 1], f_hi[f, 2]
            else:
                o0 = o1 = o2 = lo0 = lo1 = lo2 = hi0 = hi1 = hi2 = 0.0
                h = 1.0
                nx = ny = nz = off = 0
            a00, a01, a02, a03 = T[0, 0], T[0, 1], T[0, 2], T[0, 3]
            a10, a11, a12, a13 = T[1, 0], T[1, 1], T[1, 2], T[1, 3]
            a20, a21, a22, a23 = T[2, 0], T[2, 1], T[2, 2], T[2, 3]
            top = 0
            stack[0] = link_root[link]
            nf = 0
            n_open = 0
            full = False  # more open leaves than examined: the part cannot be cleared here
            while top >= 0:
                node = stack[top]
                top -= 1
                cx, cy, cz = node_c[node, 0], node_c[node, 1], node_c[node, 2]
                px = a00 * cx + a01 * cy + a02 * cz + a03
                py = a10 * cx + a11 * cy + a12 * cz + a13
                pz = a20 * cx + a21 * cy + a22 * cz + a23
                x = t00 * px + t01 * py + t02 * pz + t03
                y = t10 * px + t11 * py + t12 * pz + t13
                z = t20 * px + t21 * py + t22 * pz + t23
                if kind == FIELD:
                    lb = _field_lb(
                        f_val, x, y, z, o0, o1, o2, h, nx, ny, nz, off, lo0, lo1, lo2, hi0, hi1, hi2
                    )
                else:
                    lb = _primitive_lb(kind, x, y, z, d0, d1, d2)
                if lb - node_r[node] >= thr:
                    continue
                child = node_child[node]
                if child < 0:
                    n_open += 1
                    if nf == _LEAVES:
                        full = True
                        break
                    leaves[nf] = node
                    nf += 1
                    continue
                if top + 2 >= _STACK:
                    full = True
                    break
                stack[top + 1] = child
                stack[top + 2] = child + 1
                top += 2
            opened[m] += n_open
            if nf == 0 and not full:
                out[m, p] = 1
                continue
            if not exact:
                continue
            state = 0 if full else 1
            if env_kind[e] == FIELD:
                f = env_field[e]
                _compose(env_Tinv[e], T, Tml)
                last = -1
                for q in range(nf):
                    leaf = leaves[q]
                    s = node_shape[leaf]
                    if s != last:
                        _compose(Tml, sh_T[s], Tms)
                        last = s
                    cx, cy, cz = _world(Tml, node_c[leaf])
                    reach = node_r[leaf] + thr
                    qlo[0], qlo[1], qlo[2] = cx - reach, cy - reach, cz - reach
                    qhi[0], qhi[1], qhi[2] = cx + reach, cy + reach, cz + reach
                    r = _shape_vs_mesh(
                        Tms, sh_kind[s], sh_dims[s], sh_center[s], sh_half[s], verts,
                        sh_vs[s], sh_vc[s], f, b_origin, b_size, b_n, b_soff, b_start, b_toff,
                        b_tris, m_voff, m_foff, m_verts, m_faces, thr, near, tri, eye, qlo, qhi,
                    )  # fmt: skip
                    if r == -1:
                        state = -1
                        break
                    if r == 0:
                        state = 0  # not clear; a later leaf may still show it below
            else:
                k = env_kind[e]
                gk = G.BOX if k == BOX else G.CYLINDER if k == CYLINDER else G.SPHERE
                for s in range(link_sh0[link], link_sh0[link] + link_shn[link]):
                    _compose(T, sh_T[s], Ts)
                    r = G.gjk_classify(
                        sh_kind[s], Ts, sh_dims[s], verts, sh_vs[s], sh_vc[s],
                        gk, env_T[e], env_dims[e], verts, 0, 0, thr, near,
                    )  # fmt: skip
                    if r == -1:
                        state = -1
                        break
                    if r == 0:
                        state = 0
            out[m, p] = state
    return out, opened


@nb.njit(cache=True)
def pairs_state(
    T_links, todo, pair_a, pair_b, pair_thr, pair_near,
    node_c, node_r, node_child, link_root, node_shape,
    sh_kind, sh_T, sh_dims, sh_center, sh_half, sh_vs, sh_vc, verts, link_sh0, link_shn,
    exact,
):  # fmt: skip
    """``state (M, S)`` int8 of link pairs for the ``todo (M, S)`` entries (others 0): 1
    when their sphere trees lie ``pair_thr`` apart or (``exact``) GJK certifies every pair of
    their shapes that far apart; -1 when (``exact``) GJK certifies a pair of shapes nearer
    than ``pair_near``; else 0."""
    M, S = todo.shape
    out = np.zeros((M, S), dtype=np.int8)
    sa = np.empty(_STACK, np.int64)
    sb = np.empty(_STACK, np.int64)
    TA = np.empty((3, 4))
    TB = np.empty((3, 4))
    for m in range(M):
        for s in range(S):
            if not todo[m, s]:
                continue
            a, b, thr, near = pair_a[s], pair_b[s], pair_thr[s], pair_near[s]
            Ta, Tb = T_links[m, a], T_links[m, b]
            a00, a01, a02, a03 = Ta[0, 0], Ta[0, 1], Ta[0, 2], Ta[0, 3]
            a10, a11, a12, a13 = Ta[1, 0], Ta[1, 1], Ta[1, 2], Ta[1, 3]
            a20, a21, a22, a23 = Ta[2, 0], Ta[2, 1], Ta[2, 2], Ta[2, 3]
            b00, b01, b02, b03 = Tb[0, 0], Tb[0, 1], Tb[0, 2], Tb[0, 3]
            b10, b11, b12, b13 = Tb[1, 0], Tb[1, 1], Tb[1, 2], Tb[1, 3]
            b20, b21, b22, b23 = Tb[2, 0], Tb[2, 1], Tb[2, 2], Tb[2, 3]
            top = 0
            sa[0], sb[0] = link_root[a], link_root[b]
            clear = True
            while top >= 0:
                na, nb_ = sa[top], sb[top]
                top -= 1
                cx, cy, cz = node_c[na, 0], node_c[na, 1], node_c[na, 2]
                ax = a00 * cx + a01 * cy + a02 * cz + a03
                ay = a10 * cx + a11 * cy + a12 * cz + a13
                az = a20 * cx + a21 * cy + a22 * cz + a23
                cx, cy, cz = node_c[nb_, 0], node_c[nb_, 1], node_c[nb_, 2]
                bx = b00 * cx + b01 * cy + b02 * cz + b03
                by = b10 * cx + b11 * cy + b12 * cz + b13
                bz = b20 * cx + b21 * cy + b22 * cz + b23
                d = math.sqrt((ax - bx) ** 2 + (ay - by) ** 2 + (az - bz) ** 2)
                if d - node_r[na] - node_r[nb_] >= thr:
                    continue
                ca, cb = node_child[na], node_child[nb_]
                if (ca < 0 and cb < 0) or top + 2 >= _STACK:
                    clear = False
                    break
                if cb < 0 or (ca >= 0 and node_r[na] >= node_r[nb_]):
                    sa[top + 1], sb[top + 1] = ca, nb_
                    sa[top + 2], sb[top + 2] = ca + 1, nb_
                else:
                    sa[top + 1], sb[top + 1] = na, cb
                    sa[top + 2], sb[top + 2] = na, cb + 1
                top += 2
            if clear:
                out[m, s] = 1
                continue
            if not exact:
                continue
            state = 1
            for i in range(link_sh0[a], link_sh0[a] + link_shn[a]):
                _compose(Ta, sh_T[i], TA)
                for j in range(link_sh0[b], link_sh0[b] + link_shn[b]):
                    _compose(Tb, sh_T[j], TB)
                    r = G.gjk_classify(
                        sh_kind[i], TA, sh_dims[i], verts, sh_vs[i], sh_vc[i],
                        sh_kind[j], TB, sh_dims[j], verts, sh_vs[j], sh_vc[j], thr, near,
                    )  # fmt: skip
                    if r == -1:
                        state = -1
                        break
                    if r == 0:
                        state = 0
                if state == -1:
                    break
            out[m, s] = state
    return out
