"""The broad phase's compiled numba kernels, and where and when they are compiled.

The lowest layer of :mod:`planner.cell` but :mod:`planner.cell.disk_cache`: numpy and numba,
no PyBullet. Each kernel module calls :func:`~planner.cell.kernels.kernel_cache.configure`
before its first ``@njit``: numba caches the machine code under the user cache directory, in a
folder keyed by the sources of every module here (so they stay in this one folder), and the
first import may start the background compile of :mod:`~planner.cell.kernels.warmup`
(``python -m planner.cell.kernels.warmup`` at install). So this ``__init__`` imports nothing:
its public names are modules, each a namespace of kernels (``from planner.cell.kernels import
gjk_kernels as G``), imported when asked for.

Modules:

- :mod:`~planner.cell.kernels.bound_kernels`: upper bounds of distances with GJK, compiled with
  numba: how near two shapes surely are;
- :mod:`~planner.cell.kernels.broad_kernels`: compiled kernels of the broad phase: sphere trees
  against environment bodies and against each other, then the exact (GJK) step where they leave a
  part open;
- :mod:`~planner.cell.kernels.field_kernels`: compiled kernels of the distance fields: their build
  and their lower-bound query;
- :mod:`~planner.cell.kernels.gjk_kernels`: GJK distance bounds between convex shapes, compiled with
  numba (the broad phase's exact step);
- :mod:`~planner.cell.kernels.kernel_cache`: where numba keeps the machine code of the broad phase's
  kernels: wobjcal's per-user cache;
- :mod:`~planner.cell.kernels.lazy_kernel`: a numba kernel with one fixed signature, compiled on
  first use instead of at import;
- :mod:`~planner.cell.kernels.mesh_kernels`: compiled exact step of the broad phase against a mesh:
  a convex shape and the triangles near it;
- :mod:`~planner.cell.kernels.warmup`: compile the broad phase's numba kernels ahead of use and keep
  them in numba's cache.
"""

__all__ = [
    "bound_kernels",
    "broad_kernels",
    "field_kernels",
    "gjk_kernels",
    "kernel_cache",
    "warmup",
]
