"""Flat regions of a triangle mesh: connected sets of triangles and their least-squares planes.

The numpy/scipy steps 1 and 2 of :func:`planner.faces.detection.find_planar_faces`: triangles joined
across flat enough edges form regions, each region's plane is fitted by area-weighted least
squares (exact second moments of the triangles), and triangles off their region's plane are
peeled off until nothing changes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: At most this many rounds of peeling triangles off their region's plane.
_MAX_ROUNDS = 6


@dataclass(frozen=True)
class RegionStats:
    """One flat region (planar face or not).

    Attributes:
        normal: ``(3,)`` unit outward plane normal (area-weighted mean of its triangle normals'
            side), mesh frame.
        offset_m: plane offset ``d`` in ``normal . x = d``, metres.
        area_m2: region area, m^2.
        rms_m: area-weighted RMS distance of the region's surface from its plane, metres.
        n_triangles: triangles in the region.
        holds_footprint: some spot of the region holds the whole sensor footprint (only tested
            for regions large and flat enough; ``False`` for the others).
    """

    normal: FloatArray
    offset_m: float
    area_m2: float
    rms_m: float
    n_triangles: int
    holds_footprint: bool = True


def triangle_components(n: int, edges: IntArray, active: NDArray[np.bool_]) -> IntArray:
    """Connected components of the active triangles over ``edges``; ``-1`` for inactive ones."""
    keep = active[edges[:, 0]] & active[edges[:, 1]]
    e = edges[keep]
    graph = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    labels = labels.astype(np.int64)
    labels[~active] = -1
    _, labels[active] = np.unique(labels[active], return_inverse=True)
    return labels


def fit_planes(
    tris: FloatArray, area: FloatArray, normals: FloatArray, labels: IntArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Area-weighted least-squares planes of every label: normals, offsets, areas, RMS."""
    k = int(labels.max()) + 1 if labels.size and labels.max() >= 0 else 0
    m = labels >= 0
    lab, a, t = labels[m], area[m], tris[m]
    g = t.mean(axis=1)
    # exact second moment of a triangle: A/12 (sum v v^T + 9 g g^T)
    second = (a / 12.0)[:, None, None] * (
        np.einsum("fvi,fvj->fij", t, t) + 9.0 * np.einsum("fi,fj->fij", g, g)
    )
    A = np.bincount(lab, weights=a, minlength=k)
    S1 = np.stack([np.bincount(lab, weights=a * g[:, i], minlength=k) for i in range(3)], 1)
    S2 = np.stack(
        [np.bincount(lab, weights=second[:, i // 3, i % 3], minlength=k) for i in range(9)], 1
    ).reshape(k, 3, 3)
    Nsum = np.stack(
        [np.bincount(lab, weights=a * normals[m][:, i], minlength=k) for i in range(3)], 1
    )
    c = S1 / A[:, None]
    cov = S2 / A[:, None, None] - np.einsum("ki,kj->kij", c, c)
    w, v = np.linalg.eigh(cov)
    n = v[:, :, 0]
    n = np.where((np.einsum("ki,ki->k", n, Nsum) < 0)[:, None], -n, n)
    d = np.einsum("ki,ki->k", n, c)
    rms = np.sqrt(np.clip(w[:, 0], 0.0, None))
    return n.astype(np.float64), d.astype(np.float64), A.astype(np.float64), rms


def flat_regions(
    tris: FloatArray,
    area: FloatArray,
    normals: FloatArray,
    edges: IntArray,
    angle_tol_rad: float,
    max_deviation_m: float,
) -> IntArray:
    """``(F,)`` region label of each triangle, ``-1`` for triangles peeled off (or of zero area).

    Regions are the components over ``edges`` (pairs of triangles whose dihedral angle is within
    tolerance); triangles whose normal leaves their region's plane normal by more than
    ``angle_tol_rad`` or with a vertex farther than ``max_deviation_m`` from it are peeled off and
    the rest is split again, for at most :data:`_MAX_ROUNDS` rounds.
    """
    nf = len(tris)
    active = area > 0
    cos_tol = math.cos(angle_tol_rad)
    labels = triangle_components(nf, edges, active)
    for _ in range(_MAX_ROUNDS):
        if labels.max(initial=-1) < 0:
            break
        n, d, _, _ = fit_planes(tris, area, normals, labels)
        m = labels >= 0
        pn, pd = n[labels[m]], d[labels[m]]
        dev = np.abs(np.einsum("fvi,fi->fv", tris[m], pn) - pd[:, None]).max(axis=1)
        bad = (np.einsum("fi,fi->f", normals[m], pn) < cos_tol) | (dev > max_deviation_m)
        if not bad.any():
            break
        idx = np.flatnonzero(m)[bad]
        active[idx] = False
        labels = triangle_components(nf, edges, active)
    return labels


def region_stats(
    n: FloatArray,
    d: FloatArray,
    area: FloatArray,
    rms: FloatArray,
    cnt: IntArray,
    holds: NDArray[np.bool_],
    i: int,
) -> RegionStats:
    """Region ``i`` of the per-label arrays of :func:`fit_planes`, as a :class:`RegionStats`."""
    return RegionStats(
        n[i].copy(), float(d[i]), float(area[i]), float(rms[i]), int(cnt[i]), bool(holds[i])
    )
