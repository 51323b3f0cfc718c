"""The float64 step of a ray cast, compiled: hit distances from Embree's triangles, real edges.

Embree (float32) tells which triangle each ray meets first; :func:`finish_hits` turns that into
the float64 answer :class:`planner.sim.raycast.MeshRayCaster` gives, one ray at a time in one
compiled loop (numba) instead of a dozen numpy passes over gathered copies (the passes cost
three times Embree's own cast for a sensor's bundle):

- the distance to the hit triangle's plane, ``t = (offset - n . o) / (n . d)`` (0 for a ray
  parallel to it), at least 0; a face seen from behind (``n . d > 0``) means the ray starts
  inside the part: distance 0;
- a hit point outside its triangle across a real (non-coplanar) edge, by more than
  ``-outside_m``: first the triangle across that edge, when the ray meets it inside (float64)
  within ``same_m`` of the same distance (two triangles of one machined face stored in float32
  meet at a small angle); otherwise the ray is to be continued past the face
  (``cont``, its distance so far ``t_cont``), which the caster does with a new cast.

Every dot product is summed in the order numpy's ``einsum("ij,ij->i")`` sums three terms
(``(x0 y0 + x2 y2) + x1 y1``), so the distances are bit for bit those of the numpy version the
caster had before (``tests/planner/sim/test_hit_kernel.py`` holds it to that version, ray by ray).

The kernel is compiled (or loaded from numba's cache) on first use, in the process that uses
it: numba's cache directory is the one in force at that moment (wobjcal's, once the cell
package has set it; see :mod:`planner.cell.kernels.kernel_cache`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

_COMPILED: list[Any] = []


def _finish_hits(
    o: Any,
    d: Any,
    ids: Any,
    normals: Any,
    offsets: Any,
    has_sharp: Any,
    sharp: Any,
    en: Any,
    eo: Any,
    neighbour: Any,
    outside_m: float,
    same_m: float,
) -> tuple[Any, Any, Any, Any]:
    """The loop :func:`finish_hits` compiles (dot products written out in einsum's order)."""
    n = o.shape[0]
    out = np.full(n, np.inf)
    tri_out = np.full(n, -1, dtype=np.int64)
    cont = np.zeros(n, dtype=np.bool_)
    t_cont = np.zeros(n)
    dist = np.empty(3)
    for i in range(n):
        k = ids[i]
        if k < 0:
            continue
        o0, o1, o2, d0, d1, d2 = o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2]
        denom = (normals[k, 0] * d0 + normals[k, 2] * d2) + normals[k, 1] * d1
        num = offsets[k] - ((normals[k, 0] * o0 + normals[k, 2] * o2) + normals[k, 1] * o1)
        t = num / denom if abs(denom) > 1e-15 else 0.0
        t = t if t > 0.0 else 0.0  # np.maximum(t, 0.0)
        beyond = False
        worst = 0
        if has_sharp[k]:
            p0, p1, p2 = o0 + t * d0, o1 + t * d1, o2 + t * d2
            for e in range(3):
                dist[e] = ((en[k, e, 0] * p0 + en[k, e, 2] * p2) + en[k, e, 1] * p1) - eo[k, e]
                if dist[e] < dist[worst]:
                    worst = e
            beyond = dist[worst] < outside_m and sharp[k, worst]
        if beyond:  # the triangle across that edge, where the ray meets it inside it
            nb = neighbour[k, worst]
            if nb >= 0:
                dn = (normals[nb, 0] * d0 + normals[nb, 2] * d2) + normals[nb, 1] * d1
                on = (normals[nb, 0] * o0 + normals[nb, 2] * o2) + normals[nb, 1] * o1
                nn = offsets[nb] - on
                t_nb = nn / dn if abs(dn) > 1e-15 else np.inf
                s = t_nb if math.isfinite(t_nb) else 0.0
                q0, q1, q2 = o0 + s * d0, o1 + s * d1, o2 + s * d2
                low = np.inf
                for e in range(3):
                    de = ((en[nb, e, 0] * q0 + en[nb, e, 2] * q2) + en[nb, e, 1] * q1) - eo[nb, e]
                    low = min(low, de)
                if low >= outside_m and abs(t_nb - t) <= same_m:
                    k, denom, beyond = nb, dn, False
                    t = t_nb if t_nb > 0.0 else 0.0
        if beyond:
            cont[i] = True
            t_cont[i] = t
        else:
            out[i] = 0.0 if denom > 0 else t
            tri_out[i] = k
    return out, tri_out, cont, t_cont


def finish_hits(
    origins: FloatArray,
    directions: FloatArray,
    ids: NDArray[np.int64],
    arrays: tuple[NDArray[Any], ...],
    outside_m: float,
    same_m: float,
) -> tuple[FloatArray, NDArray[np.int64], NDArray[np.bool_], FloatArray]:
    """The float64 step of a cast (module docstring).

    Args:
        origins, directions: ``(N, 3)`` the rays, C-contiguous float64, mesh frame.
        ids: ``(N,)`` Embree's first triangle of each ray, ``-1``: none.
        arrays: the mesh's ``(normals (F, 3), offsets (F,), has_sharp (F,), sharp (F, 3),
            edge_normals (F, 3, 3), edge_offsets (F, 3), neighbour (F, 3))``.
        outside_m: how far outside its edge (negative, m) a hit point must lie to be off it.
        same_m: largest difference of distances to the triangle across an edge, m.

    Returns:
        ``(distance (N,), triangle (N,), continue (N,), distance so far (N,))``: distances
        ``inf`` and triangles ``-1`` for misses and for the rays to continue past a real edge.
    """
    if not _COMPILED:
        import numba

        _COMPILED.append(numba.njit(cache=True, nogil=True)(_finish_hits))
    out: tuple[FloatArray, NDArray[np.int64], NDArray[np.bool_], FloatArray] = _COMPILED[0](
        origins, directions, ids, *arrays, float(outside_m), float(same_m)
    )
    return out


def load_kernel() -> None:
    """Import numba and load (or compile) the kernel now, for the argument types a cast
    passes (:class:`planner.sim.raycast.MeshRayCaster`), without casting a ray: a fork
    server does it once for all its workers (:mod:`planner.sim.worker_preload`), which would
    otherwise pay about 0.4 s each at their first cast. Embree is not touched (its threads
    must not exist in a process that forks)."""
    one = np.zeros((1, 3))
    arrays = (
        np.array([[0.0, 0.0, 1.0]]),  # normals (F, 3)
        np.zeros(1),  # offsets (F,)
        np.zeros(1, dtype=np.bool_),  # has_sharp (F,)
        np.zeros((1, 3), dtype=np.bool_),  # sharp (F, 3)
        np.zeros((1, 3, 3)),  # edge_normals (F, 3, 3)
        np.zeros((1, 3)),  # edge_offsets (F, 3)
        np.full((1, 3), -1, dtype=np.int64),  # neighbour (F, 3)
    )
    finish_hits(one, one, np.full(1, -1, dtype=np.int64), arrays, -1e-12, 1e-7)
