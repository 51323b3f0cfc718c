"""Gross measurement errors: which measured point does not fit, and which one to re-measure.

A calibration procedure turns any set of measurements into a frame; one point measured 10 mm
off (a burr, a chip, the wrong spot) turns into a frame tilted by degrees, silently. This module
screens the measurements against the noise the plan expects:

1. all measured points are fitted by least squares (:func:`calib.estimators.best_fit.best_fit`,
   started from the nominal frame), whatever the procedure, because only a fit of every point
   spreads a gross error over the residuals where it can be seen (the A-H procedure, for
   instance, puts C, D, F and H exactly on their faces by construction);
2. a point is *flagged* when one of its point-to-face residuals exceeds ``k_sigma * sigma_m``;
3. with redundant points (more constraints than the 6 degrees of freedom), every point is left
   out in turn (leave-one-out): the point whose removal lets all the others fit within the limit
   is the one to re-measure. When no single point does, more than one point is off (or the part
   is not the part of the plan) and the screen says so.

Without redundancy (exactly 6 constraints, a plain 3-2-1) nothing can be screened; the result
says so instead of passing silently.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import DegenerateGeometryError
from calib.estimators.best_fit import BestFitResult, best_fit
from calib.estimators.layout import constraint_set
from calib.estimators.observability import analyze_layout
from calib.probing import ProbePoint
from calib.validation import check_points, check_positive

FloatArray = NDArray[np.float64]

#: Default limit on a residual, in units of the expected noise.
K_SIGMA = 5.0


@dataclass(frozen=True)
class LeaveOneOut:
    """The fit of all measured points but one.

    Attributes:
        point_id: the point left out.
        worst_m: largest absolute residual of the remaining points, metres.
        left_out_m: largest absolute distance of the left-out point from its face(s) of that
            fit, metres (how far off it is).
    """

    point_id: str
    worst_m: float
    left_out_m: float


@dataclass(frozen=True)
class GrossErrorScreen:
    """The screen of one set of measurements.

    Attributes:
        sigma_m: expected noise of a measured point along its face normal, metres.
        k_sigma: a residual beyond ``k_sigma * sigma_m`` flags its point.
        redundancy: constraints beyond the 6 degrees of freedom (0: nothing can be screened).
        residuals_m: ``{id: (r1[, r2])}`` least-squares point-to-face residuals, metres.
        flagged: the points with a residual beyond the limit, worst first.
        remeasure: the point(s) whose removal makes all others fit (leave-one-out); one id
            when the screen can name the point, several when any of them explains the misfit,
            none when no single point does (or nothing is flagged).
        leave_one_out: the fit without each point, for the points that could be left out.
        fit: the least-squares fit of all points (``None`` when the points fix no frame).
        note: why the screen could not run, or ``""``.
    """

    sigma_m: float
    k_sigma: float
    redundancy: int
    residuals_m: dict[str, tuple[float, ...]]
    flagged: tuple[str, ...]
    remeasure: tuple[str, ...]
    leave_one_out: tuple[LeaveOneOut, ...] = ()
    fit: BestFitResult | None = field(default=None, repr=False)
    note: str = ""

    @property
    def limit_m(self) -> float:
        """Largest residual accepted, metres."""
        return self.k_sigma * self.sigma_m

    @property
    def ok(self) -> bool:
        """No point is flagged."""
        return not self.flagged

    def worst_m(self, point_id: str) -> float:
        """Largest absolute residual of ``point_id``, metres (0 when not screened)."""
        return max((abs(r) for r in self.residuals_m.get(point_id, ())), default=0.0)

    def messages(self) -> list[str]:
        """What is wrong, in words, with the numbers (empty when nothing is flagged)."""
        if not self.flagged:
            return []
        mm = self.limit_m * 1e3
        worst = ", ".join(f"{p} {self.worst_m(p) * 1e3:.3f} mm" for p in self.flagged)
        out = [
            f"measured points off their faces beyond {self.k_sigma:g} sigma "
            f"({mm:.3f} mm; expected noise {self.sigma_m * 1e3:.3f} mm): {worst}"
        ]
        if len(self.remeasure) == 1:
            pid = self.remeasure[0]
            loo = next(x for x in self.leave_one_out if x.point_id == pid)
            out.append(
                f"re-measure {pid}: without it every other point fits within "
                f"{loo.worst_m * 1e3:.3f} mm, and {pid} lies {loo.left_out_m * 1e3:.3f} mm "
                "off its face (leave-one-out)"
            )
        elif self.remeasure:
            out.append(
                f"re-measure one of {', '.join(self.remeasure)}: leaving out any one of them "
                "makes the others fit (leave-one-out cannot tell which)"
            )
        elif not self.leave_one_out:
            out.append(
                f"only {self.redundancy} redundant constraint(s): the misfit shows, but no point "
                "can be left out to find which one is off; re-measure them all"
            )
        else:
            out.append(
                "no single point explains the misfit: more than one point is off, or the part "
                "is not shaped or placed as the plan says; re-measure them all"
            )
        return out


def screen_measurements(
    points: Sequence[ProbePoint],
    measured_base: ArrayLike,
    T_base_wobj_nominal: ArrayLike,
    sigma_m: float,
    k_sigma: float = K_SIGMA,
) -> GrossErrorScreen:
    """Screen measured points for gross errors (see the module docstring).

    Args:
        points: the nominal probe points that were measured, wobj frame.
        measured_base: ``(N, 3)`` their measurements in the same order, base frame, metres
            (known sensor offsets already removed, e.g. an edge search's event offset).
        T_base_wobj_nominal: ``(4, 4)`` the nominal frame the fits start from.
        sigma_m: expected noise of one measured point along its face normal, metres (> 0).
        k_sigma: a residual beyond ``k_sigma * sigma_m`` flags its point.

    Raises:
        ShapeError, NonFiniteError: malformed measurements (the argument is named).
    """
    sigma = check_positive(sigma_m, "sigma_m")
    k = check_positive(k_sigma, "k_sigma")
    pts = tuple(points)
    q = check_points(measured_base, "measured_base")
    cs = constraint_set(pts, "measured points")
    redundancy = cs.n_constraints - 6
    report = analyze_layout(cs)
    if not report.observable:
        note = "the measured points do not fix all 6 degrees of freedom: " + "; ".join(
            report.messages
        )
        return GrossErrorScreen(sigma, k, redundancy, {}, (), (), note=note)
    fit = best_fit(cs, q, T_base_wobj_nominal, sigma_m=sigma)
    residuals = _by_point(fit)
    limit = k * sigma
    worst = {pid: max(abs(r) for r in rs) for pid, rs in residuals.items()}
    flagged = tuple(sorted((p for p, w in worst.items() if w > limit), key=lambda p: -worst[p]))
    if redundancy <= 0:
        note = (
            f"{cs.n_constraints} constraints for 6 degrees of freedom: no redundancy, so a "
            "gross error in one point cannot be seen in the residuals"
        )
        return GrossErrorScreen(sigma, k, redundancy, residuals, (), (), (), fit, note)
    loo = _leave_one_out(pts, q, T_base_wobj_nominal, sigma) if flagged else ()
    remeasure = tuple(x.point_id for x in loo if x.worst_m <= limit and x.left_out_m > limit)
    return GrossErrorScreen(sigma, k, redundancy, residuals, flagged, remeasure, loo, fit)


def _by_point(fit: BestFitResult) -> dict[str, tuple[float, ...]]:
    out: dict[str, list[float]] = {pid: [] for pid in fit.point_ids}
    for pid, r in zip(fit.residual_ids, fit.residuals_m.tolist(), strict=True):
        out[pid].append(float(r))
    return {pid: tuple(rs) for pid, rs in out.items()}


def _leave_one_out(
    points: tuple[ProbePoint, ...], q: FloatArray, T_nominal: ArrayLike, sigma: float
) -> tuple[LeaveOneOut, ...]:
    """The fit without each point that leaves a redundant, observable layout."""
    out = []
    for j, left in enumerate(points):
        keep = [i for i in range(len(points)) if i != j]
        sub = constraint_set([points[i] for i in keep], "measured points")
        if sub.n_constraints - 6 < 1 or not analyze_layout(sub).observable:
            continue
        try:
            fit = best_fit(sub, q[keep], T_nominal, sigma_m=sigma)
        except DegenerateGeometryError:
            continue
        T_wobj_base = np.linalg.inv(fit.T_base_wobj)
        x = T_wobj_base[:3, :3] @ q[j] + T_wobj_base[:3, 3] - np.asarray(left.position_m)
        off = float(np.max(np.abs(left.constraint_normals @ x)))
        out.append(LeaveOneOut(left.id, float(np.max(np.abs(fit.residuals_m))), off))
    return tuple(out)


__all__ = ["K_SIGMA", "GrossErrorScreen", "LeaveOneOut", "screen_measurements"]
