"""The paper's x-offset run (section 3.2, eq. 13-14) in the simulation, and its target errors.

After the procedure has fixed the frame, the side face is measured along WOCS x over every
second tooth at two slot-hole levels, each search commanded in the calibrated frame, and eq. 14
turns the measurements into the x-offset matrix (:func:`calib.paper.xoffset.xoffset_matrix`).
A slot target is then the slot hole's nominal y and z with the matrix's x
(:func:`calib.paper.xoffset.slot_positions_wobj`), placed with the calibrated frame; its error is
where that target lies in the true part minus where the hole really is (the stator's bolt bulge
moves the holes along x). The same targets without the matrix (x = 0) give the error "without".
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from calib.errors import ProbeFailedError
from calib.frames import invert_transform, transform_points
from calib.paper.settings import XOffsetRun
from calib.paper.xoffset import slot_positions_wobj, xoffset_matrix, xoffset_probe_points
from calib.probing import Probe, ProbePoint, ProbeResult, SearchCommand, SearchSpec

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class XOffsetSetup:
    """The x-offset run of a plan, with the true hole centres it is judged against.

    Attributes:
        run: the plan's settings of the run.
        points: ``K x L`` nominal measurements ``PX`` (levels x teeth), wobj frame.
        targets_wobj: ``(m, n, 3)`` nominal slot targets (x = 0), wobj frame, metres.
        holes_wobj: ``(m, n, 3)`` where the slot holes really are on the true part, metres.
    """

    run: XOffsetRun
    points: tuple[tuple[ProbePoint, ...], ...]
    targets_wobj: FloatArray = field(repr=False)
    holes_wobj: FloatArray = field(repr=False)

    @property
    def n_searches(self) -> int:
        """Searches of one run."""
        return sum(len(row) for row in self.points)

    def with_holes(self, holes_wobj: FloatArray) -> XOffsetSetup:
        """The same run judged against other true hole centres ``(m, n, 3)``."""
        return XOffsetSetup(self.run, self.points, self.targets_wobj, holes_wobj)


def xoffset_setup(run: XOffsetRun, holes_wobj: FloatArray | None = None) -> XOffsetSetup:
    """The x-offset run of ``run``; ``holes_wobj`` ``(m, n, 3)`` default the nominal holes."""
    grid = run.grid
    spec = SearchSpec("approach", run.start_offset_m, run.overtravel_m)
    points = xoffset_probe_points(grid, run.layers, run.teeth, spec)
    targets = slot_positions_wobj(grid)
    holes = targets if holes_wobj is None else np.asarray(holes_wobj, dtype=np.float64)
    if holes.shape != targets.shape:
        raise ValueError(f"holes_wobj must be {targets.shape}, got {holes.shape}")
    return XOffsetSetup(run, points, targets, holes)


def run_xoffset(
    xs: XOffsetSetup, probe: Probe, T_base_wobj_cal: FloatArray, T_base_wobj_true: FloatArray
) -> FloatArray:
    """Measure the ``PX`` points in the calibrated frame and return the target errors.

    Returns:
        ``(m * n, 3)`` error of every slot target placed with the x-offset matrix, in the true
        wobj axes (target in the true part minus the true hole), metres.

    Raises:
        ProbeFailedError: a search failed (its id and reason's words; its kind is on the
            probe's event of that search: :func:`planner.sim.trial.search_failure`).
    """
    T_wobj_base = invert_transform(T_base_wobj_cal)
    points = [p for row in xs.points for p in row]
    commands = [SearchCommand.from_point(p, T_base_wobj_cal) for p in points]
    results = in_turn(probe, commands)
    for p, res in zip(points, results, strict=False):
        if res.point_m is None:
            raise ProbeFailedError(p.id, res.reason or "no reason given")
    measured = np.array([r.point_m for r in results], dtype=np.float64)
    px = transform_points(T_wobj_base, measured).reshape(len(xs.points), len(xs.points[0]), 3)
    mx = xoffset_matrix(px, xs.run.grid)
    targets = xs.targets_wobj.copy()
    targets[..., 0] = mx
    T_true_cal = invert_transform(T_base_wobj_true) @ T_base_wobj_cal
    placed = transform_points(T_true_cal, targets.reshape(-1, 3))
    return placed - xs.holes_wobj.reshape(-1, 3)


def in_turn(probe: Probe, commands: list[SearchCommand]) -> list[ProbeResult]:
    """``probe`` on each of ``commands`` in turn, up to and including the first failure: at once
    where the probe can (``run_in_turn`` of :class:`planner.sim.proximity.SimulatedProbe`: one ray
    cast for all its approaches), else one by one."""
    batch = getattr(probe, "run_in_turn", None)
    if batch is not None:
        return list(batch(commands))
    out: list[ProbeResult] = []
    for cmd in commands:
        out.append(probe(cmd))
        if out[-1].point_m is None:
            break
    return out
