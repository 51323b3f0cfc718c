"""The reachability heat map: surface samples checked as probe poses, drawn on the work object.

The samples go through the same batched check as a click (:func:`planner.cell.feasibility.
check_probes`: a broad phase decides most clearance parts, Bullet only the rest), in chunks
queued on the cell worker: clicks from any tab slip in between chunks, the map grows on screen
as chunks finish, and unticking the box stops it. A chunk's size adapts so that it takes about
:data:`CHUNK_SECONDS` (most samples cost well under a millisecond; a sample that collides in
every pose up to a few hundred). At the end the work object's vertices are coloured by their
nearest sample (red: infeasible, amber: marginal, green: feasible).
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
from planner.cell.reachability_map import sample_surface
from webui.scene import heat_rgb

if TYPE_CHECKING:
    from webui.backend import CellSession
    from webui.context import AppContext

logger = logging.getLogger(__name__)

#: Status name -> score in [0, 1] for the colour ramp.
SCORE = {"infeasible": 0.0, "marginal": 0.5, "feasible": 1.0}
#: Wall time a chunk aims at, s: a click waits at most about this long for the cell.
CHUNK_SECONDS = 0.15
#: Bounds of the adaptive chunk size, samples.
MAX_CHUNK = 512


def vertex_scores(
    mesh: trimesh.Trimesh, points: NDArray[np.float64], normals: NDArray[np.float64], score: Any
) -> NDArray[np.float64]:
    """Score of each mesh vertex: that of the nearest sample on a similarly facing face."""
    normal_weight = 0.05  # metres per unit of normal difference: keeps faces apart at edges
    tree = cKDTree(np.hstack([points, normal_weight * normals]))
    query = np.hstack([mesh.vertices, normal_weight * mesh.vertex_normals])
    _, idx = tree.query(query)
    return np.asarray(score, dtype=np.float64)[idx]


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
        self.done = threading.Event()
        self._chunk = 3
        self._tcp = "sensor"

    def start(self, n_samples: int = 1000, chunk: int = 16, seed: int = 0) -> None:
        """Sample the surface and queue the checks in chunks on the cell worker (``chunk``:
        the first chunk's size; later ones adapt to :data:`CHUNK_SECONDS`)."""
        view = self._app.view
        if view is None:
            raise InputError("the reachability map needs a work object: load a plan first")
        pts, nrm, _ = sample_surface(view.wobj_mesh, n_samples, np.random.default_rng(seed))
        self.points, self.normals = np.asarray(pts, float), np.asarray(nrm, float)
        self.scores, self._stop = [], threading.Event()
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
    ) -> tuple[list[float], float]:
        if stop.is_set() or session is None or session.cell is None:
            return [], 0.0
        t0 = time.perf_counter()
        res = session.cell.check_probes(pts, nrm, tcp=tcp)
        return [SCORE.get(str(r.status), 0.0) for r in res], time.perf_counter() - t0

    def _chunk_done(self, fut: Future[tuple[list[float], float]], stop: threading.Event) -> None:
        if stop is not self._stop:  # a chunk of an earlier, stopped map
            return
        if stop.is_set():
            self.done.set()
            return
        try:
            scores, seconds = fut.result()
            self.scores.extend(scores)
            if scores:  # the next chunk takes about CHUNK_SECONDS
                rate = len(scores) / max(seconds, 1e-3)
                self._chunk = int(min(MAX_CHUNK, max(1, CHUNK_SECONDS * rate)))
        except Exception as exc:
            logger.exception("reachability chunk failed")
            self._stop.set()
            self.done.set()
            self._app.notify("Reachability map stopped", f"{type(exc).__name__}: {exc}")
            return
        n = len(self.scores)
        self._app.scene.show_heat_map(self.points[:n], heat_rgb(np.asarray(self.scores)))
        if n == len(self.points):
            self._finish()
        self._submit_next()

    def _finish(self) -> None:
        view = self._app.view
        if view is None:
            return
        s = vertex_scores(view.wobj_mesh, self.points, self.normals, self.scores)
        self._app.scene.color_work_object(heat_rgb(s))
        feasible = float(np.mean(np.asarray(self.scores) > 0.25))
        self._app.notify(
            "Reachability map done",
            f"{feasible:.0%} of {len(self.scores)} surface samples reachable",
            error=False,
        )

    def stop(self) -> None:
        """Stop computing and hide the map."""
        self._stop.set()
        self._app.scene.show_heat_map(None)
        self._app.scene.color_work_object(None)
