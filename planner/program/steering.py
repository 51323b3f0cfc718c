"""The frame update an adaptive best-fit or 3-2-1 program computes between its searches.

After some of its searches the program moves its estimate of the work object by the smallest
motion that puts the points measured so far on their nominal faces
(:func:`calib.estimators.runners.min_norm_update`: Gauss-Newton, rotations about the whole
layout's centroid scaled by its RMS size, the step restricted to the motions the *nominal*
layout of those points fixes), and commands the later searches in that estimate. After the
last search the update uses every point: with a layout that fixes all six degrees of freedom it
is the least-squares best fit (a 3-2-1's six constraints: its exact solution), the frame the
program leaves on the controller and the one ``wobjcal calibrate`` computes from its results.

The executor (:func:`planner.program.execute.execute`) runs :func:`steer` (that update,
compiled: :mod:`planner.program.update_kernel`); a robot-language
writer writes the same iteration with the basis of each update (:func:`update_basis`) as
constants, so the two compute one estimate (the RAPID interpreter test holds them to 1e-6 mm).
Only approach searches are steered this way: an edge search's point counts only by its edge
coordinate, which the writers do not yet carry.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from calib.errors import NonFiniteError
from calib.estimators.layout import constraint_set
from calib.estimators.runners import fixed_motions
from calib.frames import check_transform
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


@dataclass(frozen=True)
class _UpdateLayout:
    """What an update from some points fits (nominal: computed once), as the compiled loop
    takes it: float64, C-contiguous.

    Attributes:
        rows: ``(M,)`` the point of each constraint row.
        normals: ``(M, 3)`` unit face normals, wobj frame.
        nominal_m: ``(M, 3)`` nominal points, wobj frame, m.
        basis: ``(6, r)`` the scaled motions the nominal points fix (:func:`update_basis`).
        pivot_m: ``(3,)`` the point rotations are taken about, wobj frame, m.
    """

    rows: NDArray[np.intp]
    normals: FloatArray
    nominal_m: FloatArray
    basis: FloatArray
    pivot_m: FloatArray


@lru_cache(maxsize=1024)
def _update_layout(
    points: tuple[ProbePoint, ...], pivot_m: tuple[float, ...], scale_m: float
) -> _UpdateLayout:
    """The constraints of ``points`` and their update basis (nominal: computed once).

    Raises:
        NonFiniteError: the pivot or the scale is NaN or infinite.
    """
    pivot = np.asarray(pivot_m, dtype=np.float64)
    if not (np.isfinite(pivot).all() and np.isfinite(scale_m)):
        raise NonFiniteError("a steered update: the pivot or the scale is NaN or infinite")
    cs = constraint_set(points)
    V = fixed_motions(cs, pivot, float(scale_m))

    def c(a: FloatArray) -> FloatArray:
        return np.ascontiguousarray(a, dtype=np.float64)

    return _UpdateLayout(np.asarray(cs.point_index), c(cs.normals), c(cs.nominal_m), c(V), pivot)


def steer(
    points: Sequence[ProbePoint],
    measured_base: Mapping[str, FloatArray],
    T_base_wobj: FloatArray,
    pivot_m: FloatArray | tuple[float, ...],
    scale_m: float,
    *,
    checked: bool = False,
) -> FloatArray:
    """``(4, 4)`` the estimate after an update from ``points`` (their last measurements in
    ``measured_base``, base frame, metres), starting at ``T_base_wobj``: the frame
    :func:`~calib.estimators.runners.min_norm_update` computes, compiled
    (:mod:`planner.program.update_kernel`). ``checked``: ``T_base_wobj`` is known to be a
    rigid transform (checked by the caller, or an earlier update's result), not checked again.

    Raises:
        NonFiniteError: a measurement, the pivot or the scale is NaN or infinite, or the update
            diverged.
        ShapeError, DegenerateGeometryError: ``T_base_wobj`` is not a rigid transform.
    """
    from planner.program.update_kernel import gauss_newton  # numba: imported when used

    given = pivot_m if isinstance(pivot_m, tuple) else np.asarray(pivot_m, float).tolist()
    pivot = tuple(float(v) for v in given)
    L = float(scale_m)
    lay = _update_layout(tuple(points), pivot, L)
    T = T_base_wobj if checked else check_transform(T_base_wobj, "T_base_wobj")
    q = np.array([measured_base[p.id] for p in points], dtype=np.float64)[lay.rows]
    if not np.isfinite(q).all():
        raise NonFiniteError("a steered update: a measurement is NaN or infinite")
    out: FloatArray = gauss_newton(
        np.ascontiguousarray(T),
        q,
        lay.normals,
        lay.nominal_m,
        lay.pivot_m,
        L,
        lay.basis,
        ITERATIONS,
    )
    if not np.isfinite(out).all():
        raise NonFiniteError("a steered update did not converge to a finite frame")
    return out


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
