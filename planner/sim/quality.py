"""How good a point layout is, before the robot measures: :class:`LayoutQuality`.

From the predicted covariance of the plan's calibration (:func:`planner.sim.predict.predict`:
the procedure linearised with the plan's noise figures, the same prediction the validation
report puts beside its simulated intervals) and the layout's observability
(:func:`calib.estimators.observability.analyze_layout` on the searches' constraints):

- the predicted 1 sigma of each degree of freedom (origin x/y/z, rotation about x/y/z);
- the noise gain (worst-case frame motion per unit measurement noise, scaled by the layout
  size) and the condition number of the scaled constraint Jacobian;
- the weakest motion in words, with how far it moves per 0.1 mm of measurement noise
  (``"rotation about wobj y: 0.4 deg per 0.1 mm of noise"``): the covariance's largest
  eigenvector in scaled centroid coordinates;
- the predicted error at each point of interest at the plan's confidence levels: the report's
  own rows (:func:`planner.sim.report_points.poi_rows`), ``z * sigma`` as
  :func:`planner.sim.rows.predicted_sigma` gives it, so ``wobjcal validate`` simulates the same
  numbers.

A layout whose noise gain exceeds :data:`calib.estimators.observability.WEAK_NOISE_GAIN` is
``weak`` (the check shows it as ``marginal`` with the weakest motion as the reason); one that
leaves a degree of freedom free is ``unobservable`` (the check fails).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from calib.estimators.layout import search_constraint_set
from calib.estimators.observability import WEAK_NOISE_GAIN, analyze_layout, name_motion
from planner.sim.predict import predict
from planner.sim.rows import RowSpec, predicted_sigma, z_values
from planner.sim.setup import SimulationSetup

FloatArray = NDArray[np.float64]
Rating = Literal["ok", "weak", "unobservable"]

#: Names of the six degrees of freedom, in the order of a frame error.
DOF_NAMES = ("origin x", "origin y", "origin z", "rotation x", "rotation y", "rotation z")
#: The weakest motion is quoted per this much measurement noise, metres.
NOISE_QUOTE_M = 1e-4


@dataclass(frozen=True)
class PoiError:
    """The predicted error at one point of interest.

    Attributes:
        key: the report row's key, e.g. ``"xyz_farthest"``.
        label: the row's label.
        position_m: ``(3,)`` the point, wobj frame, metres.
        components: which components of the error count (see :mod:`calib.plan.report_spec`).
        sigma_m: predicted 1 sigma of the row's measure, metres.
        levels_percent: the row's confidence levels, percent.
        half_width_m: predicted half-width ``z * sigma`` at each level, metres.
    """

    key: str
    label: str
    position_m: FloatArray = field(repr=False)
    components: str
    sigma_m: float
    levels_percent: tuple[float, ...]
    half_width_m: tuple[float, ...]

    def at(self, level_percent: float) -> float:
        """Predicted half-width at ``level_percent`` (any level, not only the row's), m."""
        return float(z_values((level_percent,))[0]) * self.sigma_m

    def to_json(self) -> dict[str, Any]:
        """JSON-ready (millimetres)."""
        return {
            "key": self.key,
            "label": self.label,
            "position_mm": [round(float(c) * 1e3, 6) for c in self.position_m],
            "components": self.components,
            "sigma_mm": self.sigma_m * 1e3,
            "levels_percent": list(self.levels_percent),
            "half_width_mm": [h * 1e3 for h in self.half_width_m],
        }


@dataclass(frozen=True)
class LayoutQuality:
    """The predicted quality of a layout (see the module docstring).

    Attributes:
        sigma: ``(6,)`` predicted 1 sigma of (dx, dy, dz, rx, ry, rz), m and rad, the
            estimated frame's axes.
        covariance: ``(6, 6)`` the predicted covariance (m, rad).
        noise_sigma_m: the 1 sigma of one search's event (sensor, repeatability, TCP), metres.
        noise_gain: worst-case scaled frame motion per unit noise (``inf``: unobservable).
        condition: condition number of the scaled constraint Jacobian (``inf``: unobservable).
        rating: ``"ok"``, ``"weak"`` or ``"unobservable"``.
        weakest: the weakest motion in words, e.g. ``"rotation about wobj y"``.
        weakest_amount: how far it moves (1 sigma) per 0.1 mm of noise, ``weakest_unit``.
        weakest_unit: ``"deg"`` or ``"mm"``.
        poi: the predicted error at each point of interest.
        free: the motions no measurement sees (unobservable layouts), in words.
        program: the measuring program predicted (its name, e.g. ``"RAPID, adaptive A-H"``),
            ``""`` when not known.
    """

    sigma: FloatArray = field(repr=False)
    covariance: FloatArray = field(repr=False)
    noise_sigma_m: float
    noise_gain: float
    condition: float
    rating: Rating
    weakest: str
    weakest_amount: float
    weakest_unit: str
    poi: tuple[PoiError, ...]
    free: tuple[str, ...] = ()
    program: str = ""

    @property
    def weakest_text(self) -> str:
        """E.g. ``"rotation about wobj y, 0.4 deg per 0.1 mm of noise"``."""
        if self.rating == "unobservable":
            return "; ".join(self.free)
        digits = 3 if self.weakest_unit == "deg" else 2
        return f"{self.weakest}, {self.weakest_amount:.{digits}f} {self.weakest_unit} per 0.1 mm"

    @property
    def problem(self) -> str:
        """Why the layout is weak or unobservable, ``""`` when it is ok."""
        if self.rating == "unobservable":
            return "the layout does not fix all 6 degrees of freedom: " + "; ".join(self.free)
        if self.rating == "weak":
            return (
                f"weak layout (noise gain {self.noise_gain:.1f} > {WEAK_NOISE_GAIN:g}): "
                f"{self.weakest_text}"
            )
        return ""

    def worst_poi_m(self, level_percent: float) -> float:
        """The largest predicted half-width over the points of interest at a level, m."""
        return max((p.at(level_percent) for p in self.poi), default=float("nan"))

    def to_json(self) -> dict[str, Any]:
        """JSON-ready (millimetres and degrees; infinities as ``null``)."""
        scale = np.array([1e3] * 3 + [math.degrees(1.0)] * 3)
        return {
            "program": self.program,
            "rating": self.rating,
            "problem": self.problem,
            "sigma": {
                n.replace(" ", "_") + ("_mm" if i < 3 else "_deg"): _finite(float(v))
                for i, (n, v) in enumerate(zip(DOF_NAMES, self.sigma * scale, strict=True))
            },
            "noise_sigma_mm": self.noise_sigma_m * 1e3,
            "noise_gain": _finite(self.noise_gain),
            "condition": _finite(self.condition),
            "weakest": self.weakest_text,
            "points_of_interest": [p.to_json() for p in self.poi],
        }


def _finite(x: float) -> float | None:
    return x if math.isfinite(x) else None


def unobservable_quality(free: Sequence[str], noise_m: float = 0.0) -> LayoutQuality:
    """The quality of a layout that leaves the motions ``free`` (in words) unconstrained."""
    inf = math.inf
    return LayoutQuality(
        np.full(6, inf), np.full((6, 6), inf), noise_m, inf, inf, "unobservable", "", inf, "",
        (), tuple(free),
    )  # fmt: skip


def noise_sigma(setup: SimulationSetup) -> float:
    """1 sigma of one approach search's event travel: the sensor, the robot's repeatability
    and the TCP error together, metres."""
    s = setup.sensor.search_noise("approach", setup.edge_inset_m).sensor_sigma_m
    r = setup.robot_error
    return float(math.sqrt(s**2 + r.repeatability_sigma_m**2 + r.tcp_sigma_m**2))


def layout_quality(setup: SimulationSetup, rows: Sequence[RowSpec]) -> LayoutQuality:
    """The quality of the layout of ``setup`` (its points, procedure and noise figures).

    Args:
        setup: the plan's simulation setup (faces and x-offset run are not needed).
        rows: the point-of-interest rows (:func:`planner.sim.report_points.poi_rows`).

    Raises:
        InputError: the procedure cannot calibrate even from exact measurements.
    """
    obs = analyze_layout(search_constraint_set([rp.point for rp in setup.points]))
    noise = noise_sigma(setup)
    if not obs.observable:
        return unobservable_quality(obs.messages, noise)
    cov = least_squares_covariance(setup)
    if cov is None:
        cov = predict(setup, best_fit=False).cov_procedure
    return quality_from_covariance(cov, setup, rows, obs.noise_gain, obs.singular_values, noise)


def least_squares_covariance(setup: SimulationSetup) -> FloatArray | None:
    """The procedure's predicted covariance in closed form, ``(A^T W A)^-1`` of its searches'
    constraint rows (:func:`calib.estimators.layout.constraint_jacobian`) weighted by each
    search's event variance, when that is what its linearisation gives: a procedure marked
    ``least_squares`` (the best fit, 3-2-1), approach searches only, no TCP error shared by all
    searches. ``None`` otherwise (then :func:`planner.sim.predict.predict` linearises it).
    A few hundred microseconds instead of one run of the procedure per search."""
    from calib.estimators.layout import constraint_jacobian
    from calib.procedures import procedure_kind

    kind = procedure_kind(setup.method)
    pts = [rp.point for rp in setup.points]
    if (
        not getattr(kind, "least_squares", False)
        or setup.robot_error.tcp_sigma_m
        or any(p.search.kind != "approach" for p in pts)
    ):
        return None
    N = np.array([p.normal for p in pts], dtype=np.float64)
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    A = constraint_jacobian(N, np.array([p.position_m for p in pts], dtype=np.float64))
    s = setup.sensor.search_noise("approach", setup.edge_inset_m).sensor_sigma_m
    var = s**2 + setup.robot_error.repeatability_sigma_m**2  # |b| = 1 for an approach
    M = A.T @ A / var
    cov = np.linalg.inv(M)
    return 0.5 * (cov + cov.T)


def quality_from_covariance(
    cov: FloatArray,
    setup: SimulationSetup,
    rows: Sequence[RowSpec],
    noise_gain: float,
    singular_values: FloatArray,
    noise_m: float,
) -> LayoutQuality:
    """The quality for a given predicted covariance ``(6, 6)`` of the layout of ``setup``."""
    pts = np.array([rp.point.position_m for rp in setup.points], dtype=np.float64)
    c = pts.mean(axis=0)
    scale = max(float(np.sqrt(np.mean(np.sum((pts - c) ** 2, axis=1)))), 1e-3)
    S = np.zeros((6, 6))  # origin motion -> (translation at the centroid, rotation * scale)
    S[:3, :3] = np.eye(3)
    S[:3, 3:] = -np.array([[0.0, -c[2], c[1]], [c[2], 0.0, -c[0]], [-c[1], c[0], 0.0]])
    S[3:, 3:] = scale * np.eye(3)
    w, V = np.linalg.eigh(S @ cov @ S.T)
    v = np.linalg.solve(S, V[:, -1]) * math.sqrt(max(float(w[-1]), 0.0))  # 1 sigma, origin
    name = name_motion(v, c, scale)
    per = NOISE_QUOTE_M / noise_m if noise_m > 0 else math.nan
    if name.startswith("rotation"):
        amount, unit = math.degrees(float(np.linalg.norm(v[3:]))) * per, "deg"
    else:
        amount, unit = float(np.linalg.norm(v[:3] + np.cross(v[3:], c))) * 1e3 * per, "mm"
    poi = []
    for row in rows:
        sigma = predicted_sigma(row, cov)
        if row.points_wobj is None:
            continue
        poi.append(
            PoiError(
                key=row.key,
                label=row.label,
                position_m=np.asarray(row.points_wobj[0], dtype=np.float64),
                components=row.components,
                sigma_m=sigma,
                levels_percent=tuple(row.levels_percent),
                half_width_m=tuple(float(z) * sigma for z in z_values(row.levels_percent)),
            )
        )
    rating: Rating = "weak" if noise_gain > WEAK_NOISE_GAIN else "ok"
    sv = np.asarray(singular_values, dtype=np.float64)
    return LayoutQuality(
        sigma=np.sqrt(np.maximum(np.diag(cov), 0.0)),
        covariance=cov,
        noise_sigma_m=noise_m,
        noise_gain=float(noise_gain),
        condition=float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf,
        rating=rating,
        weakest=name,
        weakest_amount=amount,
        weakest_unit=unit,
        poi=tuple(poi),
    )


def error_radius(points_wobj: FloatArray, cov: FloatArray, level_percent: float) -> FloatArray:
    """``(M,)`` predicted radius within which ``level_percent`` of calibrations place each
    point, metres: ``sqrt(chi2_3(level) * trace(S) / 3)`` for the point's Gaussian error of
    covariance ``S = J cov J^T``: exact for an isotropic error, and for any other the radius of
    the isotropic error with the same mean squared length (fast enough for the UI's colour map
    on every edit: no eigenvalues). The UI paints it on the part.
    """
    from scipy.special import chdtri

    P = np.asarray(points_wobj, dtype=np.float64).reshape(-1, 3)
    C = np.asarray(cov, dtype=np.float64)
    k = float(chdtri(3, 1.0 - level_percent / 100.0)) / 3.0
    # e = t + w x p: E|e|^2 = tr Ctt + 2 E[t . (w x p)] + |p|^2 tr Cww - p^T Cww p, all
    # quadratic in p (E[t . (w x p)] = p . E[t x w]), so no (M, 3, 6) Jacobian is built
    Ctw = C[:3, 3:]
    txw = np.array([Ctw[1, 2] - Ctw[2, 1], Ctw[2, 0] - Ctw[0, 2], Ctw[0, 1] - Ctw[1, 0]])
    Cww = C[3:, 3:]
    trace = (
        np.trace(C[:3, :3])
        + 2.0 * P @ txw
        + np.einsum("mi,mi->m", P, P) * np.trace(Cww)
        - np.einsum("mi,mi->m", P @ Cww, P)
    )
    return np.sqrt(k * np.maximum(trace, 0.0))
