"""Upper bounds of distances with GJK, compiled with numba: how near two shapes surely are.

The broad phase (:mod:`planner.cell.kernels.broad_kernels`) shows parts far (clear) or below the
margin; the search among a point's candidates (:mod:`planner.cell.probe.probe_choice`) also needs
to know that a candidate *cannot* beat another one without asking Bullet. An upper bound does
that: GJK's simplex closest point ``v`` is a point of the Minkowski difference ``A - B``
(a convex combination of support points), so ``dist(A, B) <= |v|`` whatever the iteration
did; when the simplex holds the origin the shapes overlap and ``0`` bounds the signed distance,
or, against a box, cylinder or sphere body, minus the depth of the deepest of a few points of
the shape inside it (:func:`_depth_lower`: a translation that separates the shapes moves each
of their points out of the body).
:func:`slack_upper` turns these into an upper bound of each candidate's slack in Bullet's
query with Bullet's rounding of boxes and cylinders and a safety added
(:mod:`planner.cell.broad.slack_bounds`).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from planner.cell.kernels import gjk_kernels as G
from planner.cell.kernels.broad_kernels import _compose
from planner.cell.kernels.kernel_cache import configure
from planner.cell.kernels.lazy_kernel import lazy_njit

configure()  # before the first @njit: numba picks the cache directory then

_MAX_ITER = 64
_M = "float64[:, ::1]"
_V = "float64[::1]"
_SHAPE = f"int64, {_M}, {_V}, {_M}, int64, int64"


@lazy_njit(f"float64({_SHAPE}, {_SHAPE}, float64)")
def gjk_upper(
    kA: int, TA: np.ndarray, dA: np.ndarray, vA: np.ndarray, sA: int, cA: int,
    kB: int, TB: np.ndarray, dB: np.ndarray, vB: np.ndarray, sB: int, cB: int,
    tol: float,
) -> float:  # fmt: skip
    """An upper bound of the distance between shapes A and B (0 when they overlap), within
    ``tol`` of the distance when GJK converges (see the module docstring)."""
    W = np.empty((4, 3))
    scratch = np.empty((6, 3))
    v = np.empty(3)
    G.start_direction(TA, TB, v)
    n = 0
    lb = -np.inf
    ub = np.inf
    for _ in range(_MAX_ITER):
        ax, ay, az = G.support(kA, TA, dA, vA, sA, cA, -v[0], -v[1], -v[2])
        bx, by, bz = G.support(kB, TB, dB, vB, sB, cB, v[0], v[1], v[2])
        wx, wy, wz = ax - bx, ay - by, az - bz
        vn = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
        if n > 0:
            ub = min(ub, vn)  # v is a point of A - B
            if vn <= 0.0:
                return 0.0
        if vn > 0.0:
            lb = max(lb, (v[0] * wx + v[1] * wy + v[2] * wz) / vn)
        if n > 0 and ub - lb <= tol:
            return ub
        n = G.add_point(W, n, wx, wy, wz, scratch, v)
        if n == 0:
            return 0.0  # the origin is inside the simplex: the shapes overlap
    vn = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return min(ub, vn)


@nb.njit(cache=True)
def _depth(kind, T, dims, x, y, z):  # fmt: skip
    """How deep world point ``(x, y, z)`` lies inside a box, cylinder or sphere (pose ``T``),
    m; negative outside."""
    dx, dy, dz = x - T[0, 3], y - T[1, 3], z - T[2, 3]
    lx = T[0, 0] * dx + T[1, 0] * dy + T[2, 0] * dz
    ly = T[0, 1] * dx + T[1, 1] * dy + T[2, 1] * dz
    lz = T[0, 2] * dx + T[1, 2] * dy + T[2, 2] * dz
    if kind == G.BOX:
        return min(dims[0] - abs(lx), dims[1] - abs(ly), dims[2] - abs(lz))
    if kind == G.CYLINDER:
        return min(dims[0] - math.sqrt(lx * lx + ly * ly), dims[1] - abs(lz))
    return dims[0] - math.sqrt(lx * lx + ly * ly + lz * lz)


@nb.njit(cache=True)
def _depth_lower(kA, TA, dA, verts, sA, cA, kB, TB, dB):  # fmt: skip
    """A lower bound of the penetration depth of shape A into the primitive B (0 when none is
    shown): the deepest of some points of A (box corners, cylinder and capsule rims and tips,
    sphere poles, hull vertices) inside B. Any translation that separates them moves each
    point of A out of B, so it is at least that long."""
    best = 0.0
    if kA == G.HULL:
        for r in range(sA, sA + cA):
            px, py, pz = verts[r, 0], verts[r, 1], verts[r, 2]
            x = TA[0, 0] * px + TA[0, 1] * py + TA[0, 2] * pz + TA[0, 3]
            y = TA[1, 0] * px + TA[1, 1] * py + TA[1, 2] * pz + TA[1, 3]
            z = TA[2, 0] * px + TA[2, 1] * py + TA[2, 2] * pz + TA[2, 3]
            best = max(best, _depth(kB, TB, dB, x, y, z))
        return best
    n = 8 if kA == G.BOX else 16 if kA in (G.CYLINDER, G.CAPSULE) else 6
    for r in range(n):
        if kA == G.BOX:
            px = dA[0] if r & 1 else -dA[0]
            py = dA[1] if r & 2 else -dA[1]
            pz = dA[2] if r & 4 else -dA[2]
        elif kA == G.CYLINDER or kA == G.CAPSULE:
            a = (r % 8) * (math.pi / 4.0)
            # rim points (cylinder); for a capsule the sphere caps' equators
            px, py = dA[0] * math.cos(a), dA[0] * math.sin(a)
            pz = dA[1] if r < 8 else -dA[1]
        else:  # sphere: its six poles
            px = py = pz = 0.0
            sgn = dA[0] if r % 2 == 0 else -dA[0]
            if r < 2:
                px = sgn
            elif r < 4:
                py = sgn
            else:
                pz = sgn
        x = TA[0, 0] * px + TA[0, 1] * py + TA[0, 2] * pz + TA[0, 3]
        y = TA[1, 0] * px + TA[1, 1] * py + TA[1, 2] * pz + TA[1, 3]
        z = TA[2, 0] * px + TA[2, 1] * py + TA[2, 2] * pz + TA[2, 3]
        best = max(best, _depth(kB, TB, dB, x, y, z))
    return best


# Explicit: the constant arguments of one call site would otherwise get a literal-typed copy
# (1.4 s more of compile on first use); compiled on first use (planner.cell.kernels.lazy_kernel).
_I = "int64[::1]"
_LINK = (
    f"float64({G._M}, int64, int64, {G._M}, {G._V}, int64, int64, {_I}, float64[:, :, ::1], "
    f"{G._M}, {_I}, {_I}, {G._M}, {_I}, {_I}, {G._M})"
)


@lazy_njit(_LINK)
def _link_upper(
    Tl, k, kind, T, dims, vs, vc, sh_kind, sh_T, sh_dims, sh_vs, sh_vc, verts, link_sh0,
    link_shn, TA,
):  # fmt: skip
    """Upper bound of the distance of link ``k`` (pose ``Tl``) to one shape (``kind``, pose
    ``T``, ``dims``, hull vertices ``verts[vs : vs + vc]``)."""
    best = np.inf
    for i in range(link_sh0[k], link_sh0[k] + link_shn[k]):
        _compose(Tl, sh_T[i], TA)
        d = gjk_upper(
            sh_kind[i], TA, sh_dims[i], verts, sh_vs[i], sh_vc[i], kind, T, dims, verts, vs, vc,
            1e-7,
        )  # fmt: skip
        if d <= 0.0 and kind <= G.SPHERE:  # overlap with a primitive body: how deep, at least
            d = -_depth_lower(sh_kind[i], TA, sh_dims[i], verts, sh_vs[i], sh_vc[i], kind, T, dims)
        best = min(best, d)
    return best


@nb.njit(cache=True)
def slack_upper(
    T_links, todo_p, part_link, part_env, part_add, part_need, part_dist,
    todo_s, pair_a, pair_b, pair_add, pair_need, pair_dist,
    sh_kind, sh_T, sh_dims, sh_vs, sh_vc, verts, link_sh0, link_shn,
    env_kind, env_T, env_dims,
):  # fmt: skip
    """``(M,)`` upper bounds of the candidates' slack in Bullet's query (inf: none known).

    For each part ``p`` with ``todo_p[m, p]`` (a link against a box, cylinder or sphere) and
    each self pair ``s`` with ``todo_s[m, s]``: ``u`` = GJK's upper bound of the true distance
    plus ``*_add`` (Bullet's rounding of both sides and a safety): Bullet's distance is at most
    ``u``. When ``u`` is below the part's look distance ``*_dist`` Bullet reports the part, so
    the query's slack is at most ``u - *_need``; the bound is the least of these.
    """
    M = T_links.shape[0]
    out = np.full(M, np.inf)
    TA = np.empty((3, 4))
    TB = np.empty((3, 4))
    for m in range(M):
        best = np.inf
        for p in range(todo_p.shape[1]):
            if not todo_p[m, p]:
                continue
            k, e = part_link[p], part_env[p]
            d = _link_upper(
                T_links[m, k], k, env_kind[e], env_T[e], env_dims[e], 0, 0,
                sh_kind, sh_T, sh_dims, sh_vs, sh_vc, verts, link_sh0, link_shn, TA,
            )  # fmt: skip
            u = d + part_add[p]
            if u < part_dist[p]:
                best = min(best, u - part_need[p])
        for s in range(todo_s.shape[1]):
            if not todo_s[m, s]:
                continue
            a, b = pair_a[s], pair_b[s]
            d = np.inf
            for j in range(link_sh0[b], link_sh0[b] + link_shn[b]):
                _compose(T_links[m, b], sh_T[j], TB)
                e = _link_upper(
                    T_links[m, a], a, sh_kind[j], TB, sh_dims[j], sh_vs[j], sh_vc[j],
                    sh_kind, sh_T, sh_dims, sh_vs, sh_vc, verts, link_sh0, link_shn, TA,
                )  # fmt: skip
                d = min(d, e)
            u = d + pair_add[s]
            if u < pair_dist[s]:
                best = min(best, u - pair_need[s])
        out[m] = best
    return out
