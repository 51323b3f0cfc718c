"""Detection's footprint test (:func:`planner.faces.footprint.holds_footprint`), kept on disk.

The test is most of the time of :func:`planner.faces.detection.find_planar_faces` (1.6 of
1.8 s for the stator: ray casts around candidate spots, then the roomiest spot of each region
that failed), and its answer, one bool per region, depends only on what it reads. With a store
(:class:`planner.faces.array_cache.ArrayCache`: the cell's disk cache, kind
:data:`CACHE_KIND`), a mesh seen by an earlier command skips it.

The key hashes everything the answer depends on: the mesh (its content digest), the region of
each triangle, the regions tested with their planes, the footprint radius and tolerance, the
source of :mod:`planner.faces.footprint` and the versions of trimesh, its ray engine and
shapely. So an edited test or another engine misses the cache instead of reading an answer it
would not give; :data:`CACHE_VERSION` covers what the key cannot see.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
from functools import cache
from pathlib import Path

import numpy as np
import trimesh
from numpy.typing import NDArray

from planner.faces import footprint
from planner.faces.array_cache import ArrayCache

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: The disk cache kind of footprint answers, and the version of what it stores.
CACHE_KIND = "planar_faces"
CACHE_VERSION = 1


@cache
def _code_stamp() -> str:
    """The footprint test's source and the libraries its answer depends on."""
    try:
        source = Path(footprint.__file__).read_bytes()
    except OSError:  # no source beside the module: its version alone
        source = b""
    versions = []
    for dist in ("trimesh", "shapely", "embreex"):
        try:
            versions.append(f"{dist}={importlib.metadata.version(dist)}")
        except importlib.metadata.PackageNotFoundError:
            versions.append(f"{dist}=none")
    embree = bool(getattr(trimesh.ray, "has_embree", False))
    return hashlib.sha256(source).hexdigest() + " ".join(versions) + f" embree={embree}"


def footprint_key(
    mesh_digest: str,
    labels: IntArray,
    regions: IntArray,
    n: FloatArray,
    d: FloatArray,
    radius_m: float,
    tol_m: float,
) -> str:
    """The cache key of :func:`holds_footprint_cached`'s answer (its arguments as there)."""
    h = hashlib.sha256(f"{mesh_digest} {radius_m!r} {tol_m!r} {_code_stamp()}".encode())
    for a in (labels, regions, n[regions], d[regions]):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:40]


def holds_footprint_cached(
    mesh: trimesh.Trimesh,
    mesh_digest: str,
    labels: IntArray,
    regions: IntArray,
    n: FloatArray,
    d: FloatArray,
    radius_m: float,
    tol_m: float,
    cache: ArrayCache | None,
) -> NDArray[np.bool_]:
    """:func:`planner.faces.footprint.holds_footprint`, read from ``cache`` when it has it.

    Args:
        mesh: the part, its own frame, metres.
        mesh_digest: its content hash (:func:`planner.faces.detection.mesh_digest`).
        labels: ``(F,)`` flat region of each triangle (``-1``: none).
        regions: ``(K,)`` the regions to test.
        n: ``(R, 3)`` unit plane normals of every region, wobj frame.
        d: ``(R,)`` their offsets along the normals, metres.
        radius_m: the footprint radius, metres.
        tol_m: how far from the plane a hit may be, metres.
        cache: the store (``None``: computed, not kept).

    Returns:
        ``(K,)`` whether each region holds the footprint somewhere.
    """
    if cache is None or len(regions) == 0:
        return footprint.holds_footprint(mesh, labels, regions, n, d, radius_m, tol_m)
    key = footprint_key(mesh_digest, labels, regions, n, d, radius_m, tol_m)
    stored = cache.load_arrays(CACHE_KIND, key, CACHE_VERSION)
    if stored is not None:
        holds = np.asarray(stored.get("holds", np.zeros(0)))
        if holds.dtype == np.bool_ and holds.shape == regions.shape:
            return holds
    out = footprint.holds_footprint(mesh, labels, regions, n, d, radius_m, tol_m)
    cache.save_arrays(CACHE_KIND, key, CACHE_VERSION, {"holds": np.asarray(out, dtype=bool)})
    return out
