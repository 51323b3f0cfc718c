"""Distance fields of triangle meshes: grid lower bounds of the distance to a mesh's surface.

Bullet treats a work object or a mesh fixture as a set of triangles (a shell, not a solid), so
the field holds the *unsigned* distance to the triangles. It is a grid of spacing ``h`` over the
mesh's box grown by :data:`PAD_M`; each node holds a lower bound of the distance, clamped at
:data:`CAP_M`:

- each triangle computes the exact distance of the nodes within ``band = BAND_CELLS * h`` of
  its box (:func:`planner.cell.kernels.field_kernels.rasterize_band`); a node whose smallest such
  distance is within the band has its exact distance (its nearest triangle was among them);
- the others are farther than the band from the mesh, and get the larger of the band and
  ``EDT - h * sqrt(3) / 2``: ``EDT`` is the distance to the nearest corner of a grid cell that
  a triangle's box touches, and the nearest surface point lies in such a cell, within
  ``h * sqrt(3) / 2`` of one of its corners.

A query (:func:`planner.cell.kernels.field_kernels.field_lower_bound`) interpolates trilinearly and
subtracts the interpolation's error bound, and outside the grid uses the distance to the
mesh's box.

Beside the field, a bucket grid of the triangles (cells of :data:`BUCKET_M`, each listing the
triangles whose box overlaps it) finds the triangles near a shape for the exact step of the
broad phase. The spacing is the larger of :data:`MIN_SPACING_M` and what keeps the grid within
:data:`MAX_NODES` nodes. Fields are built once per mesh and cached on disk
(:mod:`planner.cell.disk_cache`, kind ``distance_fields``) under a hash of the vertices, faces
and these settings.
"""

from __future__ import annotations

import hashlib
import logging
import math
import time
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import NDArray
from scipy import ndimage

from planner.cell.disk_cache import load_arrays, save_arrays
from planner.cell.kernels import field_kernels as kernels

log = logging.getLogger(__name__)
FloatArray = NDArray[np.float64]

#: Bump when the construction changes, so cached fields are rebuilt.
FIELD_VERSION = 2
#: Margin of the grid around the mesh's box, m.
PAD_M = 0.06
#: Node values are clamped at this distance, m (a lower bound stays a lower bound).
CAP_M = 0.25
#: Finest spacing, m, and the most nodes of one field.
MIN_SPACING_M = 0.004
MAX_NODES = 3_000_000
#: Nodes within this many cells of a triangle's box get exact distances.
BAND_CELLS = 2.0
#: Edge of the bucket cells, m, and the most cells of one bucket grid.
BUCKET_M = 0.01
MAX_BUCKETS = 1_000_000
CACHE_KIND = "distance_fields"


@dataclass(frozen=True)
class DistanceField:
    """Lower bounds of the distance to a mesh on a grid (mesh frame).

    Attributes:
        origin: ``(3,)`` position of node ``(0, 0, 0)``, m.
        spacing: grid spacing ``h``, m.
        values: ``(nx, ny, nz)`` float32 lower bounds of the distance at the nodes, m.
        lo, hi: ``(3,)`` the mesh's bounding box, m.
        bucket_origin: ``(3,)`` corner of bucket cell ``(0, 0, 0)``, m.
        bucket_size: edge of a bucket cell, m.
        bucket_n: ``(3,)`` bucket cells per axis.
        bucket_start: ``(B + 1,)`` int64: the triangles of cell ``b`` (flat index
            ``(i * ny + j) * nz + k``) are ``bucket_tris[bucket_start[b] : bucket_start[b + 1]]``.
        bucket_tris: ``(E,)`` int64 triangle indices.
        key: the content hash the field was built (and is cached) under.
        build_s: seconds spent building it (0 when it came from the cache).
    """

    origin: FloatArray
    spacing: float
    values: NDArray[np.float32]
    lo: FloatArray
    hi: FloatArray
    bucket_origin: FloatArray
    bucket_size: float
    bucket_n: NDArray[np.int64]
    bucket_start: NDArray[np.int64]
    bucket_tris: NDArray[np.int64]
    key: str
    build_s: float = 0.0

    @property
    def nbytes(self) -> int:
        """Memory of the node values and the bucket grid, bytes."""
        return int(self.values.nbytes + self.bucket_start.nbytes + self.bucket_tris.nbytes)

    def lower_bound(self, points: FloatArray) -> FloatArray:
        """Lower bounds ``(M,)`` of the distance from ``points (M, 3)`` (mesh frame) to the
        mesh, m."""
        pts = np.asarray(points, dtype=float).reshape(-1, 3)
        args = self.kernel_arrays()
        return np.array(
            [kernels.field_lower_bound(p[0], p[1], p[2], 0, *args) for p in pts], dtype=float
        )

    def kernel_arrays(
        self, offset: int = 0
    ) -> tuple[
        FloatArray,
        FloatArray,
        NDArray[np.int64],
        NDArray[np.int64],
        NDArray,
        FloatArray,
        FloatArray,
    ]:
        """``(f_origin, f_h, f_n, f_off, f_val, f_lo, f_hi)`` of this field alone (see
        :mod:`planner.cell.kernels.broad_kernels`)."""
        return (
            self.origin[None].copy(),
            np.array([self.spacing]),
            np.array([self.values.shape], dtype=np.int64),
            np.array([offset], dtype=np.int64),
            self.values.ravel(),
            self.lo[None].copy(),
            self.hi[None].copy(),
        )


def mesh_key(mesh: trimesh.Trimesh) -> str:
    """Content hash of a mesh's geometry and the field settings."""
    h = hashlib.sha256(
        f"field{FIELD_VERSION}:{PAD_M}:{CAP_M}:{MIN_SPACING_M}:{MAX_NODES}:{BAND_CELLS}".encode()
    )
    h.update(np.ascontiguousarray(mesh.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype=np.int64).tobytes())
    return h.hexdigest()[:40]


def _grid(lo: FloatArray, hi: FloatArray) -> tuple[FloatArray, float, NDArray[np.int64]]:
    origin = lo - PAD_M
    ext = (hi + PAD_M) - origin
    h = max(MIN_SPACING_M, float(np.prod(ext) / MAX_NODES) ** (1 / 3))
    n = np.ceil(ext / h - 1e-9).astype(np.int64) + 1
    while int(np.prod(n)) > MAX_NODES:  # rounding up may overshoot by a few planes
        h *= 1.01
        n = np.ceil(ext / h - 1e-9).astype(np.int64) + 1
    return origin, h, n


def build_field(mesh: trimesh.Trimesh) -> DistanceField:
    """Build the distance field of ``mesh`` (no cache); see the module docstring."""
    t0 = time.perf_counter()
    V = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
    F = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    lo, hi = V.min(axis=0), V.max(axis=0)
    origin, h, n = _grid(lo, hi)
    exact = np.full(tuple(int(v) for v in n), np.inf)
    kernels.rasterize_band(V, F, origin, h, n, BAND_CELLS * h, exact)
    # far nodes: distance to the nearest corner of a cell that a triangle's box touches
    tri = V[F]
    c_lo = np.floor((tri.min(axis=1) - origin) / h).astype(np.int64)
    c_hi = np.floor((tri.max(axis=1) - origin) / h).astype(np.int64)
    marked = np.zeros(tuple(int(v) for v in n), dtype=bool)
    _mark_corners(marked, np.clip(c_lo, 0, n - 2), np.clip(c_hi, 0, n - 2))
    edt = ndimage.distance_transform_edt(~marked) * h
    far = np.maximum(edt - h * math.sqrt(3) / 2, 0.0)
    # an exact value within the band is the distance (the nearest triangle was rasterized);
    # a node with none within the band is farther than the band from every triangle
    band = BAND_CELLS * h
    values = np.where(exact <= band, exact, np.maximum(far, band))
    values = np.minimum(values, CAP_M)
    # float32, rounded down so that a stored value never exceeds the bound
    v32 = values.astype(np.float32)
    v32 = np.where(v32.astype(np.float64) > values, np.nextafter(v32, np.float32(-1)), v32)
    b_origin, b_size, b_n, b_start, b_tris = _buckets(tri, lo, hi)
    return DistanceField(
        origin, h, v32.astype(np.float32), lo, hi, b_origin, b_size, b_n, b_start, b_tris,
        mesh_key(mesh), time.perf_counter() - t0,
    )  # fmt: skip


def _buckets(
    tri: FloatArray, lo: FloatArray, hi: FloatArray
) -> tuple[FloatArray, float, NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """The bucket grid of triangles ``tri (T, 3, 3)`` over the box ``lo..hi``."""
    ext = np.maximum(hi - lo, 1e-9)
    size = max(BUCKET_M, float(np.prod(ext) / MAX_BUCKETS) ** (1 / 3))
    n = np.maximum(1, np.ceil(ext / size - 1e-9)).astype(np.int64)
    while int(np.prod(n)) > MAX_BUCKETS:
        size *= 1.01
        n = np.maximum(1, np.ceil(ext / size - 1e-9)).astype(np.int64)
    c_lo = np.clip(np.floor((tri.min(axis=1) - lo) / size).astype(np.int64), 0, n - 1)
    c_hi = np.clip(np.floor((tri.max(axis=1) - lo) / size).astype(np.int64), 0, n - 1)
    span = c_hi - c_lo + 1
    count = np.prod(span, axis=1)
    tri_id = np.repeat(np.arange(len(tri), dtype=np.int64), count)
    # the k-th cell of a triangle's box, k = 0 .. count - 1 (x slowest)
    k = np.arange(int(count.sum()), dtype=np.int64) - np.repeat(np.cumsum(count) - count, count)
    sy, sz = span[tri_id, 1], span[tri_id, 2]
    ix = c_lo[tri_id, 0] + k // (sy * sz)
    iy = c_lo[tri_id, 1] + (k // sz) % sy
    iz = c_lo[tri_id, 2] + k % sz
    flat = (ix * n[1] + iy) * n[2] + iz
    order = np.argsort(flat, kind="stable")
    start = np.searchsorted(flat[order], np.arange(int(np.prod(n)) + 1)).astype(np.int64)
    return lo.copy(), size, n, start, tri_id[order]


def _mark_corners(
    marked: NDArray[np.bool_], c_lo: NDArray[np.int64], c_hi: NDArray[np.int64]
) -> None:
    """Mark the corner nodes of every cell in each box ``c_lo..c_hi`` (cell indices)."""
    span = c_hi - c_lo + 2  # corner nodes per axis
    small = np.all(span <= 3, axis=1)
    for dx in range(3):
        for dy in range(3):
            for dz in range(3):
                d = np.array([dx, dy, dz])
                sel = small & np.all(d < span, axis=1)
                idx = c_lo[sel] + d
                marked[idx[:, 0], idx[:, 1], idx[:, 2]] = True
    for a, b in zip(c_lo[~small], c_hi[~small]):  # large triangles, one by one
        marked[a[0] : b[0] + 2, a[1] : b[1] + 2, a[2] : b[2] + 2] = True


def distance_field(mesh: trimesh.Trimesh, use_cache: bool = True) -> DistanceField:
    """The distance field of ``mesh``: from the disk cache when a valid one is there, else
    built (and stored). A corrupt, partial or foreign cache file is ignored and replaced."""
    key = mesh_key(mesh)
    if use_cache:
        arrays = load_arrays(CACHE_KIND, key, FIELD_VERSION)
        field = _from_arrays(arrays, key, len(mesh.faces)) if arrays is not None else None
        if field is not None:
            return field
    field = build_field(mesh)
    log.info(
        "distance field of %d triangles: %s nodes, %.1f mm spacing, %.1f MB, %.2f s",
        len(mesh.faces), "x".join(map(str, field.values.shape)), field.spacing * 1e3,
        field.nbytes / 1e6, field.build_s,
    )  # fmt: skip
    if use_cache:
        save_arrays(
            CACHE_KIND,
            key,
            FIELD_VERSION,
            {
                "origin": field.origin,
                "spacing": np.array(field.spacing),
                "values": field.values,
                "lo": field.lo,
                "hi": field.hi,
                "bucket_origin": field.bucket_origin,
                "bucket_size": np.array(field.bucket_size),
                "bucket_n": field.bucket_n,
                "bucket_start": field.bucket_start,
                "bucket_tris": field.bucket_tris,
            },
        )
    return field


def _from_arrays(a: dict[str, NDArray], key: str, n_faces: int) -> DistanceField | None:
    """A field from cached arrays, or ``None`` when they are not a consistent field of a mesh
    of ``n_faces`` triangles."""
    try:
        origin = np.asarray(a["origin"], dtype=float)
        spacing = float(a["spacing"])
        values = np.asarray(a["values"])
        lo, hi = np.asarray(a["lo"], dtype=float), np.asarray(a["hi"], dtype=float)
        b_origin = np.asarray(a["bucket_origin"], dtype=float)
        b_size = float(a["bucket_size"])
        b_n = np.asarray(a["bucket_n"])
        b_start = np.asarray(a["bucket_start"])
        b_tris = np.asarray(a["bucket_tris"])
    except (KeyError, TypeError, ValueError):
        return None
    ok = (
        origin.shape == (3,)
        and lo.shape == (3,)
        and hi.shape == (3,)
        and values.dtype == np.float32
        and values.ndim == 3
        and min(values.shape) >= 2
        and math.isfinite(spacing)
        and spacing > 0
        and np.all(np.isfinite(values))
        and np.all(values >= 0)
        and np.all(np.isfinite(origin))
        and b_origin.shape == (3,)
        and math.isfinite(b_size)
        and b_size > 0
        and b_n.shape == (3,)
        and b_n.dtype == np.int64
        and np.all(b_n >= 1)
        and b_start.dtype == np.int64
        and b_start.shape == (int(np.prod(b_n)) + 1,)
        and b_tris.dtype == np.int64
        and b_tris.ndim == 1
        and b_start[0] == 0
        and b_start[-1] == b_tris.size
        and np.all(np.diff(b_start) >= 0)
        and (b_tris.size == 0 or (b_tris.min() >= 0 and b_tris.max() < n_faces))
    )
    if not ok:
        return None
    return DistanceField(
        origin, spacing, values, lo, hi, b_origin, b_size, b_n, b_start, b_tris, key
    )
