"""Surface reachability map: area-weighted samples on the work object, feasibility per sample.

For the UI's heat map: sample ``n`` points uniformly by area on the work-object surface (with
their face normals as outward normals), run :func:`planner.cell.probe.check_probes` on all of
them in one batch, and return arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from calib.errors import ShapeError
from planner.cell.probe.feasibility import check_probes
from planner.reasons import Reason

if TYPE_CHECKING:
    from planner.cell.scene import CellScene

FloatArray = NDArray[np.float64]

#: ``status`` codes.
INFEASIBLE, MARGINAL, FEASIBLE = 0, 1, 2
_CODES = {"infeasible": INFEASIBLE, "marginal": MARGINAL, "feasible": FEASIBLE}


@dataclass(frozen=True)
class ReachabilityMap:
    """Feasibility of probe poses sampled on the work-object surface.

    Attributes:
        points_wobj: ``(M, 3)`` sample points, wobj frame, m.
        normals_wobj: ``(M, 3)`` unit outward face normals, wobj frame.
        face_index: ``(M,)`` index of the mesh face each sample lies on.
        status: ``(M,)`` int8: 0 infeasible, 1 marginal, 2 feasible.
        clearance_m: ``(M,)`` clearance of the chosen pose's limiting pair, m (NaN when no
            pose was checked).
        joint_margin_rad: ``(M,)`` smallest joint-limit distance of the chosen pose, rad (NaN
            when none).
        causes: ``(M,)`` why each sample is infeasible or marginal, with its kind (``None``
            for feasible samples).
    """

    points_wobj: FloatArray
    normals_wobj: FloatArray
    face_index: NDArray[np.int64]
    status: NDArray[np.int8]
    clearance_m: FloatArray
    joint_margin_rad: FloatArray
    causes: tuple[Reason | None, ...]

    @property
    def reasons(self) -> tuple[str, ...]:
        """``(M,)`` the words of :attr:`causes` (``""`` for feasible samples)."""
        return tuple("" if c is None else str(c) for c in self.causes)

    @property
    def feasible(self) -> NDArray[np.bool_]:
        """``(M,)`` True for feasible and marginal samples."""
        return self.status >= MARGINAL

    @property
    def fraction_feasible(self) -> float:
        """Share of samples that are feasible or marginal."""
        return float(self.feasible.mean()) if self.status.size else 0.0


def sample_surface(
    mesh: trimesh.Trimesh, n_samples: int, rng: np.random.Generator
) -> tuple[FloatArray, FloatArray, NDArray[np.int64]]:
    """``n_samples`` points uniform by area on ``mesh``, their face normals and face indices."""
    if int(n_samples) < 1:
        raise ShapeError(f"n_samples must be >= 1, got {n_samples}")
    area = mesh.area_faces
    face = rng.choice(area.size, size=int(n_samples), p=area / area.sum())
    u = rng.uniform(size=(int(n_samples), 2))
    flip = u.sum(axis=1) > 1.0
    u[flip] = 1.0 - u[flip]
    tri = mesh.triangles[face]
    pts = tri[:, 0] + u[:, :1] * (tri[:, 1] - tri[:, 0]) + u[:, 1:] * (tri[:, 2] - tri[:, 0])
    return pts, mesh.face_normals[face].copy(), face.astype(np.int64)


def reachability_map(
    cell: CellScene, n_samples: int, rng: np.random.Generator, **check_kw: Any
) -> ReachabilityMap:
    """Sample the cell's work object and check every sample as a probe pose.

    Args:
        cell: the cell, with a work object.
        n_samples: number of surface samples.
        rng: random generator for the samples.
        **check_kw: passed to :func:`planner.cell.probe.check_probes` (``tcp``, ``margin_m``,
            ``rotation_step_deg``, ...).

    Raises:
        ShapeError: no work object, or ``n_samples < 1``.
    """
    if cell.work_object is None:
        raise ShapeError("reachability_map needs a work object: call cell.set_work_object first")
    pts, nrm, face = sample_surface(cell.work_object.mesh, n_samples, rng)
    res = check_probes(cell, pts, nrm, **check_kw)
    return ReachabilityMap(
        points_wobj=pts,
        normals_wobj=nrm,
        face_index=face,
        status=np.array([_CODES[r.status] for r in res], dtype=np.int8),
        clearance_m=np.array([r.clearance_m for r in res], dtype=float),
        joint_margin_rad=np.array([r.joint_margin_rad for r in res], dtype=float),
        causes=tuple(r.cause for r in res),
    )
