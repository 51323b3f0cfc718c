"""The frame update an adaptive best-fit or 3-2-1 program computes between its searches.

After some of its searches the program moves its estimate of the work object by the smallest
motion that puts the points measured so far on their nominal faces
(:func:`calib.estimators.runners.min_norm_update`: Gauss-Newton, rotations about the whole
layout's centroid scaled by its RMS size, the step restricted to the motions the *nominal*
layout of those points fixes), and commands the later searches in that estimate. After the
last search the update uses every point: with a layout that fixes all six degrees of freedom it
is the least-squares best fit (a 3-2-1's six constraints: its exact solution), the frame the
program leaves on the controller and the one ``wobjcal calibrate`` computes from its results.

The executor (:func:`planner.program.execute.execute`) runs :func:`steer`; a robot-language
writer writes the same iteration with the basis of each update (:func:`update_basis`) as
constants, so the two compute one estimate (the RAPID interpreter test holds them to 1e-6 mm).
Only approach searches are steered this way: an edge search's point counts only by its edge
coordinate, which the writers do not yet carry.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from calib.estimators.layout import ConstraintSet, constraint_set
from calib.estimators.runners import fixed_motions, min_norm_update
from calib.probing import ProbePoint
from calib.procedures import PROCEDURES, procedure_kind
from planner.program.model import MeasuringProgram

FloatArray = NDArray[np.float64]

#: Gauss-Newton iterations of one update at most (as :func:`min_norm_update`).
ITERATIONS = 10
#: An update stops when its step is below this, metres (and radians times the scale).
STEP_TOL_M = 1e-9


def update_groups(method: str, ordered_ids: Sequence[str]) -> list[tuple[str, ...]]:
    """The points each update of an adaptive ``method`` program fits, for points measured in
    ``ordered_ids`` order (``[]``: the program does not steer itself), as the procedure's
    registry entry says (:attr:`calib.procedures.base.ProcedureKind.steering`): the best fit
    after every point, the points so far (the progressive best fit; the last update is the fit
    of them all); the 3-2-1 after the three primary points, after the two secondary ones, after
    the tertiary one (the order of its roles).

    Raises:
        PlanError: ``method`` is no procedure (the message lists the known ones).
    """
    ids = tuple(ordered_ids)
    steering = procedure_kind(method).steering
    if steering is None:
        return []
    return [ids[:k] for k in steering.update_counts(len(ids))]


#: The procedures whose adaptive programs steer by :func:`steer` (approach searches only): those
#: whose registry entry has a :class:`~calib.procedures.base.Steering`.
STEERED_METHODS = tuple(m for m, kind in PROCEDURES.items() if kind.steering is not None)


def layout_pivot_scale(points: Sequence[ProbePoint]) -> tuple[FloatArray, float]:
    """``(centroid (3,), RMS size)`` of the whole layout, wobj frame, metres: what every
    update turns about and scales rotations by."""
    cs = constraint_set(points)
    return cs.centroid_m.copy(), float(cs.scale_m)


def update_basis(points: Sequence[ProbePoint], pivot_m: FloatArray, scale_m: float) -> FloatArray:
    """``(6, r)`` orthonormal basis of the scaled motions the nominal ``points`` fix: the
    subspace an update after measuring them moves the estimate in."""
    return fixed_motions(constraint_set(points), np.asarray(pivot_m, float), float(scale_m))


@lru_cache(maxsize=1024)
def _update_layout(
    points: tuple[ProbePoint, ...], pivot_m: tuple[float, ...], scale_m: float
) -> tuple[ConstraintSet, FloatArray]:
    """The constraints of ``points`` and their update basis (nominal: computed once)."""
    cs = constraint_set(points)
    return cs, fixed_motions(cs, np.asarray(pivot_m, float), float(scale_m))


def steer(
    points: Sequence[ProbePoint],
    measured_base: Mapping[str, FloatArray],
    T_base_wobj: FloatArray,
    pivot_m: FloatArray,
    scale_m: float,
) -> FloatArray:
    """``(4, 4)`` the estimate after an update from ``points`` (their last measurements in
    ``measured_base``, base frame, metres), starting at ``T_base_wobj``."""
    pivot = tuple(float(v) for v in np.asarray(pivot_m, float))
    cs, V = _update_layout(tuple(points), pivot, float(scale_m))
    q = np.array([measured_base[p.id] for p in points], dtype=np.float64)
    return min_norm_update(
        cs, q, T_base_wobj, np.asarray(pivot), float(scale_m), ITERATIONS, basis=V
    )


def update_bases(program: MeasuringProgram) -> list[tuple[int, FloatArray]]:
    """``(k, basis (6, r))`` of each update of a steered ``program``, in order: it fits the
    first ``k`` points the program records, and moves the estimate in the ``r`` scaled
    motions their nominal layout fixes (:func:`update_basis`): what a writer puts in its
    constants.

    Raises:
        ValueError: the program has no pivot, or an update does not fit the first points of
            its order (every steered program's does).
    """
    order = [s.point_id for s in program.searches if s.recorded]
    by_id = {rp.point.id: rp.point for rp in program.points}
    if program.pivot_m is None:
        raise ValueError(f"{program.name}: a steered program without a pivot")
    out = []
    for u in program.updates:
        k = len(u.uses)
        if list(u.uses) != order[:k]:
            raise ValueError(f"update of {u.uses} does not fit the first points of {order}")
        V = update_basis([by_id[i] for i in u.uses], np.asarray(program.pivot_m), program.scale_m)
        out.append((k, V))
    return out
