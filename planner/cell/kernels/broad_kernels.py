"""Compiled kernels of the broad phase: sphere trees against environment bodies and against
each other, then the exact (GJK) step where they leave a part open.

Everything here is a lower bound on a true (nominal-geometry) distance, m: the callers add
Bullet's own shape margins and a safety before they call a part clear
(:mod:`planner.cell.broad.broad_phase`). Compiled with numba (``cache=True``: the machine code is
kept in the user's cache after the first run, :mod:`planner.cell.kernels.kernel_cache`). The kernels
run on one core: on a shared machine numba's parallel loops waited for busy cores (up to 100x
slower in a measured run), and the batches of a UI click are small.

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
  mesh's bounding box (body frame); then their bucket grids and triangles
  (:func:`planner.cell.broad.broad_arrays.concat_fields`);
- shapes: :func:`planner.cell.broad.broad_arrays.shape_arrays`.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from planner.cell.kernels import gjk_kernels as G
from planner.cell.kernels.field_kernels import field_lb
from planner.cell.kernels.kernel_cache import configure
from planner.cell.kernels.mesh_kernels import shape_vs_mesh

configure()  # before the first @njit: numba picks the cache directory then

BOX, CYLINDER, SPHERE, FIELD = 0, 1, 2, 3
#: Depth of the traversal stacks (a binary tree of a few hundred leaves is ~10 deep).
_STACK = 256
#: Most leaves of one link the exact step looks at (beyond, the part is left to Bullet).
_LEAVES = 64


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
                    lb = field_lb(
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
                    r = shape_vs_mesh(
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
