"""The least-squares fit of a procedure's own measurements, fed as the procedure is fed.

To compare a procedure with the best fit fairly, the fit must see what the procedure used:

- a point measured more than once (the A-H procedure retakes C and D at the end, the iterative
  fit measures every point each round) counts by its *last* measurement, as in the procedure;
- an edge search counts only by its edge coordinate: its recorded point lies on the commanded
  track, so its coordinate across the face it slides over is the command's, not a measurement
  (:func:`calib.estimators.layout.search_constraint_set`);
- the sensor's known edge-event offset is removed from edge searches, as the procedure does.

Fitting the first C, D (commanded before z was known, often partly over a slot hole) and F's and
H's commanded side-face coordinates as if they were measurements made the stator's best fit look
worse than the A-H procedure in x; ``docs/simulation.md`` has the numbers.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from calib.estimators.best_fit import BestFitResult, best_fit
from calib.estimators.layout import ConstraintSet, search_constraint_set
from calib.probing import ProbePoint
from calib.procedures.base import FloatArray, ProcedureRun, edge_corrected


def last_measurements(run: ProcedureRun, point_ids: Sequence[str]) -> dict[str, FloatArray]:
    """``{id: (3,)}`` the last measurement of each point the run measured, base frame, m.

    ``run.measured_m`` keys are ``"<id>"`` for the first measurement and ``"<id>#<k>"`` for
    the k-th; points the run did not measure are left out.
    """
    best: dict[str, tuple[int, FloatArray]] = {}
    wanted = set(point_ids)
    for key, q in run.measured_m.items():
        pid, _, k = key.partition("#")
        n = int(k) if k else 1
        if pid in wanted and n >= best.get(pid, (0, q))[0]:
            best[pid] = (n, np.asarray(q, dtype=np.float64))
    return {pid: best[pid][1] for pid in point_ids if pid in best}


class FedFit:
    """The best fit of a procedure's measurements, fed as the procedure is fed.

    Build it once per layout (the constraint set is checked once) and call it per run.

    Args:
        points: the plan's probe points (wobj frame), with their plan ids.
        edge_offset_m: the sensor's edge-event offset the procedure removes, metres.
    """

    def __init__(self, points: Sequence[ProbePoint], edge_offset_m: float = 0.0) -> None:
        self.points = tuple(points)
        self.edge_offset_m = float(edge_offset_m)
        self._sets: dict[tuple[str, ...], ConstraintSet] = {}

    def constraints(self, ids: Sequence[str]) -> ConstraintSet:
        """The constraint set of the points ``ids`` (cached)."""
        key = tuple(ids)
        if key not in self._sets:
            self._sets[key] = search_constraint_set([p for p in self.points if p.id in key])
        return self._sets[key]

    def __call__(self, run: ProcedureRun) -> BestFitResult:
        """The fit of ``run``'s last measurements, started at ``run``'s frame.

        Raises:
            UnobservableError: the measured points do not fix all 6 degrees of freedom.
        """
        ids = [p.id for p in self.points]
        last = last_measurements(run, ids)
        pts = [p for p in self.points if p.id in last]
        q = np.array([last[p.id] for p in pts])
        q = edge_corrected(pts, q, run.T_base_wobj, self.edge_offset_m)
        cs = self.constraints([p.id for p in pts])
        return best_fit(cs, q, run.T_base_wobj)
