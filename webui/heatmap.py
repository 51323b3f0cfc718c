"""The reachability heat map: surface samples checked as probe poses, drawn on the work object.

The samples go through :func:`planner.cell.probe.probe_statuses`: the statuses of the
fast batched check of a click (a broad phase decides most clearance parts, Bullet only the
rest) without the least-bad pose of a point that cannot be probed (the map asks whether and
why not, not which pose: it stops at the first candidate that settles the status), with a
coarser search over the sensor's rotation (:data:`ROTATION_STEP_DEG`, :data:`MAX_CHECKS`: a
map, not a verdict; a click checks its point fully), in chunks queued on the cell worker:
clicks from any tab slip in between chunks, the map grows on screen as chunks finish, and
unticking the box stops it. A chunk's size adapts so that it takes about
:data:`CHUNK_SECONDS`. Each sample is coloured by what fails (:data:`CATEGORY_RGB`: out of
reach, joint limit or singular wrist, collision, sensor footprint off a planar face: the kind
of its reason, :data:`CATEGORY_OF_KIND`) or by its status; at the end each face of a refined
copy of the surface takes one of those colours by a vote of the samples near it
(:func:`face_colours`): one colour per face, never a blend.
"""

from __future__ import annotations

import logging
import threading
import time
from concurrent.futures import Future
from typing import TYPE_CHECKING, Any

import numpy as np
import trimesh
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from calib.errors import InputError
from planner.cell.probe import probe_statuses, sample_surface
from planner.faces.checks import check_probe_faces
from planner.reasons import Reason
from webui.scene import STATUS_RGB

if TYPE_CHECKING:
    from webui.backend import CellSession
    from webui.context import AppContext

logger = logging.getLogger(__name__)

#: Status name -> score in [0, 1] (1: feasible) of each sample.
SCORE = {"infeasible": 0.0, "marginal": 0.5, "feasible": 1.0}
#: What a sample's colour says, in legend order.
CATEGORY_RGB: dict[str, tuple[int, int, int]] = {
    "feasible": STATUS_RGB["feasible"],  # the markers' colours, so the legend agrees
    "marginal": STATUS_RGB["marginal"],
    "reach": (150, 20, 20),
    "joint limit": (150, 70, 200),
    "collision": (235, 80, 30),
    "footprint": (60, 110, 220),
}
CATEGORY_MEANING: dict[str, str] = {
    "feasible": "reachable and clear",
    "marginal": "little clearance or near a joint limit",
    "reach": "out of reach",
    "joint limit": "only at a joint limit or singular wrist",
    "collision": "robot or tool collides",
    "footprint": "sensor footprint off a planar face",
}
#: The colour of an infeasible sample by the kind of its reason (any other, or none: ``reach``).
CATEGORY_OF_KIND: dict[str, str] = {
    "reach": "reach",
    "joint_limit": "joint limit",
    "singularity": "joint limit",
    "collision": "collision",
    "footprint": "footprint",
}
#: The map's search over the sensor's rotation: coarser than a click's (15 deg, 48 checks).
ROTATION_STEP_DEG = 45.0
MAX_CHECKS = 4
#: Samples of the map.
N_SAMPLES = 500
#: Wall time a chunk aims at, s: a click waits at most about this long for the cell.
CHUNK_SECONDS = 0.15
#: Bounds of the adaptive chunk size, samples.
MAX_CHUNK = 512
#: Edge length of the refined surface the colours are spread over, as a share of the
#: part's largest extent.
REFINE_SHARE = 0.02
#: A mesh with at least this many triangles is dense enough as it is (not refined).
DENSE_FACES = 20_000
#: Samples that vote on each face's colour.
BLEND_K = 6


def category_of(status: str, cause: Reason | None, on_face: bool) -> str:
    """What a sample's colour says (a key of :data:`CATEGORY_RGB`): its status where it can
    be probed, the footprint where that is off a planar face, else the kind of its ``cause``
    (:data:`CATEGORY_OF_KIND`)."""
    if status in ("feasible", "marginal"):
        return status if on_face else "footprint"
    return "reach" if cause is None else CATEGORY_OF_KIND.get(cause.kind, "reach")


def _features(points: NDArray[np.float64], normals: NDArray[np.float64]) -> NDArray[np.float64]:
    normal_weight = 0.05  # metres per unit of normal difference: keeps faces apart at edges
    return np.hstack([points, normal_weight * normals])


def vertex_scores(
    mesh: trimesh.Trimesh, points: NDArray[np.float64], normals: NDArray[np.float64], score: Any
) -> NDArray[np.float64]:
    """Score of each mesh vertex: that of the nearest sample on a similarly facing face."""
    tree = cKDTree(_features(points, normals))
    _, idx = tree.query(_features(np.asarray(mesh.vertices), np.asarray(mesh.vertex_normals)))
    return np.asarray(score, dtype=np.float64)[idx]


def refined(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """A copy of ``mesh`` with no edge longer than :data:`REFINE_SHARE` of its size (a mesh of
    :data:`DENSE_FACES` triangles or more is kept as it is) and unshared vertices (each face
    its own normal: colours do not bleed round edges)."""
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    if len(f) < DENSE_FACES:
        size = float(np.max(mesh.extents)) * REFINE_SHARE
        v, f = trimesh.remesh.subdivide_to_size(v, f, max_edge=size, max_iter=8)
    out = trimesh.Trimesh(v, f, process=False)
    out.unmerge_vertices()
    return out


def face_colours(
    mesh: trimesh.Trimesh,
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    rgb: NDArray[np.uint8],
) -> NDArray[np.uint8]:
    """``(F, 3)`` one colour per face of ``mesh``: the colour that wins a vote, at the face's
    centre, of the :data:`BLEND_K` nearest similarly facing samples, each weighted by inverse
    squared distance. Colours are never mixed (a mix of "reach" and "footprint" would read as
    another category)."""
    centres = np.asarray(mesh.triangles_center, dtype=np.float64)
    fn = np.asarray(mesh.face_normals, dtype=np.float64)
    k = min(BLEND_K, len(points))
    dist, idx = cKDTree(_features(points, normals)).query(_features(centres, fn), k=k)
    dist, idx = dist.reshape(len(centres), k), idx.reshape(len(centres), k)
    palette, label = np.unique(np.asarray(rgb, dtype=np.uint8), axis=0, return_inverse=True)
    votes = np.zeros((len(centres), len(palette)))
    w = 1.0 / np.maximum(dist, 1e-6) ** 2
    np.add.at(votes, (np.arange(len(centres))[:, None], label.reshape(-1)[idx]), w)
    return np.asarray(palette[np.argmax(votes, axis=1)], dtype=np.uint8)


def smooth_vertex_colours(
    mesh: trimesh.Trimesh,
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    rgb: NDArray[np.uint8],
) -> NDArray[np.uint8]:
    """``(V, 3)`` colours of ``mesh``'s vertices: every corner of a face takes that face's
    colour (:func:`face_colours`), so the renderer, which interpolates vertex colours across a
    face, never blends two categories into a stripe of a colour that means nothing. ``mesh``
    must have unshared vertices (:func:`refined` makes them); a vertex shared by faces of
    different colours takes the last one's. On a refined surface the borders between colours
    follow its small triangles (edges at most :data:`REFINE_SHARE` of the part's size)."""
    per_face = face_colours(mesh, points, normals, rgb)
    out = np.zeros((len(mesh.vertices), 3), dtype=np.uint8)
    out[np.asarray(mesh.faces).reshape(-1)] = np.repeat(per_face, 3, axis=0)
    return out


class HeatMap:
    """A reachability map being computed or shown for one app.

    Args:
        app: the app whose cell and work object are used.
    """

    def __init__(self, app: AppContext) -> None:
        self._app = app
        self._stop = threading.Event()
        self.points: NDArray[np.float64] = np.zeros((0, 3))
        self.normals: NDArray[np.float64] = np.zeros((0, 3))
        self.scores: list[float] = []
        self.categories: list[str] = []
        self.on_face: NDArray[np.bool_] = np.zeros(0, dtype=bool)
        self.done = threading.Event()
        #: Wall time of the last complete map, s (``nan`` until one completes).
        self.seconds = float("nan")
        self._t0 = 0.0
        self._chunk = 3
        self._tcp = "sensor"
        #: One line on the last complete map (usable share, what fails, time).
        self.summary = ""

    def start(self, n_samples: int = N_SAMPLES, chunk: int = 16, seed: int = 0) -> None:
        """Sample the surface and queue the checks in chunks on the cell worker (``chunk``:
        the first chunk's size; later ones adapt to :data:`CHUNK_SECONDS`)."""
        view = self._app.view
        if view is None:
            raise InputError("the reachability map needs a work object: load a plan first")
        self._t0 = time.perf_counter()
        pts, nrm, _ = sample_surface(view.wobj_mesh, n_samples, np.random.default_rng(seed))
        self.points, self.normals = np.asarray(pts, float), np.asarray(nrm, float)
        source = self._app.state.doc.source
        radius = 0.0 if source is None else float(source.validation.sensor.footprint_radius_m)
        faces = check_probe_faces(
            view.wobj_mesh, self.points, self.normals, footprint_radius_m=radius
        )
        self.on_face = np.array([f.ok for f in faces], dtype=bool)
        self.scores, self.categories, self._stop = [], [], threading.Event()
        self.done = threading.Event()
        self._chunk = chunk
        source = self._app.state.doc.source
        self._tcp = source.cell.tool.tcp if source is not None else "sensor"
        self._submit_next()

    def _submit_next(self) -> None:
        """Queue the next chunk; one at a time, so clicks queue between chunks, not after all."""
        n = len(self.scores)
        if self._stop.is_set() or n >= len(self.points):
            self.done.set()
            return
        sl = slice(n, n + self._chunk)
        stop = self._stop
        fut = self._app.worker.submit(self._job, self.points[sl], self.normals[sl], self._tcp, stop)
        fut.add_done_callback(lambda f: self._chunk_done(f, stop))

    @staticmethod
    def _job(
        session: CellSession | None,
        pts: NDArray[np.float64],
        nrm: NDArray[np.float64],
        tcp: str,
        stop: threading.Event,
    ) -> tuple[list[tuple[str, Reason | None]], float]:
        if stop.is_set() or session is None or session.cell is None:
            return [], 0.0
        t0 = time.perf_counter()
        res = probe_statuses(
            session.cell, pts, nrm, tcp=tcp, rotation_step_deg=ROTATION_STEP_DEG,
            max_checks=MAX_CHECKS,
        )  # fmt: skip
        return list(zip(res.statuses, res.causes)), time.perf_counter() - t0

    def rgb(self) -> NDArray[np.uint8]:
        """``(n, 3)`` colours of the samples checked so far (by :data:`CATEGORY_RGB`)."""
        return np.array([CATEGORY_RGB[c] for c in self.categories], dtype=np.uint8).reshape(-1, 3)

    def _chunk_done(
        self, fut: Future[tuple[list[tuple[str, Reason | None]], float]], stop: threading.Event
    ) -> None:
        if stop is not self._stop:  # a chunk of an earlier, stopped map
            return
        if stop.is_set():
            self.done.set()
            return
        try:
            results, seconds = fut.result()
            n0 = len(self.scores)
            for i, (status, cause) in enumerate(results):
                self.scores.append(SCORE.get(status, 0.0))
                self.categories.append(category_of(status, cause, bool(self.on_face[n0 + i])))
            if results:  # the next chunk takes about CHUNK_SECONDS
                rate = len(results) / max(seconds, 1e-3)
                self._chunk = int(min(MAX_CHUNK, max(1, CHUNK_SECONDS * rate)))
        except Exception as exc:
            logger.exception("reachability chunk failed")
            self._stop.set()
            self.done.set()
            self._app.notify("Reachability map stopped", f"{type(exc).__name__}: {exc}")
            return
        n = len(self.scores)
        self._app.scene.show_heat_map(self.points[:n], self.rgb())
        if n == len(self.points):
            self._finish()
        self._submit_next()

    def _finish(self) -> None:
        view = self._app.view
        if view is None:
            return
        fine = refined(view.wobj_mesh)
        colours = smooth_vertex_colours(fine, self.points, self.normals, self.rgb())
        self._app.scene.color_work_object(colours, mesh=fine)
        self._app.scene.show_heat_map(None)
        self.seconds = time.perf_counter() - self._t0
        counts = {c: self.categories.count(c) for c in CATEGORY_RGB}
        usable = counts["feasible"] + counts["marginal"]
        failing = ", ".join(f"{c} {n}" for c, n in counts.items() if n and c not in SCORE)
        self.summary = (
            f"{usable / max(len(self.categories), 1):.0%} of {len(self.categories)} surface "
            f"samples usable ({failing or 'none fail'}); {self.seconds:.1f} s"
        )
        self._app.notify("Reachability map done", self.summary, error=False)

    def stop(self) -> None:
        """Stop computing and hide the map."""
        self._stop.set()
        self._app.scene.show_heat_map(None)
        self._app.scene.color_work_object(None)
