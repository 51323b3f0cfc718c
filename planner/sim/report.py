"""The Monte Carlo validation report: every row simulated beside predicted, per-point outcomes.

Rows (:mod:`planner.sim.rows`): origin x/y/z, rotations about x/y/z, the error at each point of
interest and pooled over each region, at the plan's confidence levels, for the procedure and
for the least-squares fit of the same measurements fed as the procedure is fed
(:mod:`calib.procedures.comparison`). Each has the simulated half-width (``+- z sigma`` about
the mean, as the paper, which took the mean of its calibrations as the truth), the half-width
*predicted* from the procedure's linearisation with the same noise figures
(:mod:`calib.procedures.linearize`), and the bias (the simulation knows the truth). Optionally
the paper's protocol (positions x repeats, centred on each position's mean) stands beside it,
and for the built-in stator the paper's Table 1.

Per-point outcomes (:class:`PointOutcome`) count every search by the id the procedure gives it
(``"D"``, its retake ``"D2"``): failures with their reason, and landings off the face or with
part of the footprint over a hole or an edge (with the fraction of the footprint). Failures are
counted by their :class:`planner.reasons.Reason` (kind, words, pair), per search and per trial
(:class:`FailureCount`), so a reader sorts them by kind, never by their words.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from calib.paper.table1 import PAPER_TABLE1 as PAPER_TABLE1  # the paper's Table 1
from planner.reasons import Reason
from planner.sim.error_map import ErrorMap
from planner.sim.search_events import SearchFailure

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class IntervalRow:
    """One line of the report.

    Attributes:
        key: row key, e.g. ``"yz_epsilon"``.
        label: the row's name.
        unit: display unit, ``"mm"`` or ``"deg"``.
        level_percent: confidence level, percent.
        procedure: simulated half-width of the procedure's interval, display unit.
        procedure_predicted: half-width predicted from the procedure's linearisation.
        procedure_bias: mean error of the procedure (bias), display unit.
        best_fit: simulated half-width of the best fit fed as the procedure is fed.
        best_fit_predicted: predicted half-width of that best fit.
        best_fit_bias: mean error of that best fit.
        paper: the paper's half-width (built-in stator, A-H), or NaN.
        procedure_protocol: half-width under the paper's protocol (positions x repeats,
            centred on each position's mean), or NaN when not run.
        best_fit_protocol: the same for the best fit.
    """

    key: str
    label: str
    unit: str
    level_percent: float
    procedure: float
    procedure_predicted: float
    procedure_bias: float
    best_fit: float
    best_fit_predicted: float
    best_fit_bias: float
    paper: float = float("nan")
    procedure_protocol: float = float("nan")
    best_fit_protocol: float = float("nan")


@dataclass(frozen=True)
class PointOutcome:
    """How the searches of one point went over all trials.

    Attributes:
        point_id: the search's id as the procedure names it (``"D"``, a retake ``"D2"``).
        searches: searches run.
        failed: failures by reason (its kind, words and pair; the markdown and the JSON list
            the words, the JSON the kinds beside them).
        landed_off: approaches whose footprint centre was not on the face meant.
        partly_off: approaches with part of the footprint over a hole or an edge.
        off_fraction_mean: mean fraction of the footprint off the face over ``partly_off``.
        off_fraction_max: largest such fraction.
    """

    point_id: str
    searches: int
    failed: dict[Reason, int]
    landed_off: int
    partly_off: int
    off_fraction_mean: float
    off_fraction_max: float


@dataclass(frozen=True)
class FailureCount:
    """Trials that failed alike: the same search for the same reason (one line of the report's
    failures).

    Attributes:
        label: the line's words, ``"<search>: <reason>"``, ``"x-offset <search>: <reason>"``
            or ``"procedure: <why>"`` (a :attr:`ValidationReport.failures` key).
        run: ``"procedure"`` (the calibration) or ``"x-offset"`` (the x-offset run after it).
        failed: the search the run stopped at, with its reason (kind, words, pair); ``None``
            when no search failed (the measurements define no frame).
        count: trials.
    """

    label: str
    run: Literal["procedure", "x-offset"]
    failed: SearchFailure | None
    count: int


@dataclass(frozen=True)
class ValidationReport:
    """Result of a Monte Carlo validation (:func:`planner.sim.montecarlo.simulate`).

    Attributes:
        n_trials: trials run.
        n_ok: trials whose calibration finished.
        rows: the report's rows.
        samples_procedure: per row key, the procedure's centred error samples, SI (m, rad);
            point rows pool all their points.
        samples_best_fit: the same for the best fit.
        delta_procedure: ``(n_ok, 6)`` raw frame errors of the procedure (m, rad).
        delta_best_fit: ``(n_ok, 6)`` raw frame errors of the best fit (m, rad).
        failures: ``"<search>: <reason>"`` -> number of failed trials.
        failure_counts: the same trials by the search and reason (with its kind) they failed
            at, in the order of their labels.
        landings: ``"<search>: <landing>"`` -> number of such approaches.
        elapsed_s: wall time, seconds.
        workers: worker processes used.
        reach_checked: how many trials (the first ones) also vetted every commanded search for
            reachability and collisions in the cell; 0 when no cell was given.
        reach_failed: how many of those failed for a reason only the cell shows (reach, a
            joint limit, a singularity, a collision: :data:`planner.sim.summary.CELL_KINDS`):
            the others cannot fail so, so with ``reach_checked < n_trials`` this share is the
            better estimate of the runs that fail that way (:func:`reach_warning`).
        method: the procedure's method.
        sensor: the sensor kind.
        outcomes: per-search outcomes, in the order the searches were first run.
        predicted_cov_procedure: ``(6, 6)`` predicted covariance of the procedure's frame error.
        predicted_cov_best_fit: ``(6, 6)`` that of the best fit.
        noise: the noise figures the run used, SI, by name.
        protocol: ``""`` or ``"<positions> positions x <repeats> repeats"`` when the paper's
            protocol ran beside the default.
        notes: lines the markdown adds at the end (e.g. what the prediction leaves out).
        points_of_interest: per point row key, ``(3,)`` its point, wobj frame, metres.
        probe_points_wobj: ``(N, 3)`` the plan's probe points, wobj frame, metres.
        error_map: the procedure's error over the part (:mod:`planner.sim.error_map`), or None.
        program: the measuring program every trial executed, by name (e.g. ``"RAPID,
            adaptive A-H"``), and why it runs nominal when it does.
        program_steps: its steps, one line each.
        check_problems: every problem ``wobjcal check`` names for the plan and this program
            (``()``: it passes, or the plan was not checked): a report of a plan check refuses
            says so at the top.
    """

    n_trials: int
    n_ok: int
    rows: tuple[IntervalRow, ...]
    samples_procedure: dict[str, FloatArray]
    samples_best_fit: dict[str, FloatArray]
    delta_procedure: FloatArray
    delta_best_fit: FloatArray
    failures: dict[str, int]
    landings: dict[str, int]
    elapsed_s: float
    workers: int
    reach_checked: int = 0
    reach_failed: int = 0
    method: str = "hultman2013"
    sensor: str = "proximity"
    outcomes: tuple[PointOutcome, ...] = ()
    predicted_cov_procedure: FloatArray = field(default_factory=lambda: np.zeros((6, 6)))
    predicted_cov_best_fit: FloatArray = field(default_factory=lambda: np.zeros((6, 6)))
    noise: dict[str, float] = field(default_factory=dict)
    protocol: str = ""
    notes: tuple[str, ...] = ()
    points_of_interest: dict[str, FloatArray] = field(default_factory=dict)
    probe_points_wobj: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    error_map: ErrorMap | None = None
    program: str = ""
    program_steps: tuple[str, ...] = ()
    check_problems: tuple[str, ...] = ()
    failure_counts: tuple[FailureCount, ...] = ()

    def row(self, key: str, level_percent: float) -> IntervalRow:
        """The row ``key`` at ``level_percent``; raises KeyError when absent."""
        for r in self.rows:
            if r.key == key and abs(r.level_percent - level_percent) < 1e-9:
                return r
        raise KeyError(f"no row {key!r} at {level_percent} %")

    def to_markdown(self) -> str:
        """The rows, per-point outcomes, failures and notes, as Markdown."""
        return report_markdown(self)


#: Why the paper's rotation rows look 100x too small (``docs/simulation.md``).
ROTATION_NOTE = (
    "The paper's rotation rows (+-0.0002 deg about x, ...) are about 100x smaller than its own"
    " origin and epsilon rows imply (0.02 deg about x); they look like quaternion components"
    " rather than degrees: compare the origin and epsilon rows (docs/simulation.md)."
)


def _hw(x: float, digits: int, unit: str) -> str:
    return "—" if not math.isfinite(x) else f"± {x:.{digits}f} {unit}"


def _bias(x: float, digits: int) -> str:
    return "—" if not math.isfinite(x) else f"{x:+.{digits}f}"


def _row_cells(r: IntervalRow, protocol: bool, paper: bool) -> list[str]:
    d = 4 if r.unit == "deg" else 2
    cells = [
        r.label,
        f"{r.level_percent:g}",
        _hw(r.procedure, d, r.unit),
        _hw(r.procedure_predicted, d, r.unit),
        _bias(r.procedure_bias, d),
    ]
    if protocol:
        cells.append(_hw(r.procedure_protocol, d, r.unit))
    cells += [
        _hw(r.best_fit, d, r.unit),
        _hw(r.best_fit_predicted, d, r.unit),
        _bias(r.best_fit_bias, d),
    ]
    if protocol:
        cells.append(_hw(r.best_fit_protocol, d, r.unit))
    if paper:
        cells.append("" if math.isnan(r.paper) else _hw(r.paper, d, r.unit))
    return cells


def failed_by_words(failed: dict[Reason, int]) -> dict[str, int]:
    """``failed`` by the words users read, sorted (reasons of one text counted together)."""
    out: dict[str, int] = {}
    for cause, n in failed.items():
        out[str(cause)] = out.get(str(cause), 0) + n
    return dict(sorted(out.items()))


def reach_warning(report: ValidationReport) -> str:
    """``""``, or the warning a report needs when trials checked in the cell failed but most
    trials were not checked there: "calibrated: N" then counts trials that could not fail on
    reach or collisions, and overstates how many real runs succeed."""
    n, k = report.reach_checked, report.reach_failed
    if k == 0 or n >= report.n_trials:
        return ""
    from scipy.stats import beta

    lo = float(beta.ppf(0.025, k, n - k + 1))
    hi = float(beta.ppf(0.975, k + 1, n - k)) if k < n else 1.0
    return (
        f"ONLY {n} OF {report.n_trials} TRIALS WERE CHECKED IN THE CELL, AND {k} OF THEM FAILED "
        f"THERE ({k / n:.0%}; 95 % interval {lo:.0%} to {hi:.0%}; reach, limits, "
        f"singularities, collisions or moves): the {report.n_trials - n} unchecked trials "
        "could not fail so, so 'calibrated' above overstates how many runs succeed; validate "
        "with --reach-trials "
        f"{report.n_trials} for the figure"
    )


def report_markdown(report: ValidationReport) -> str:
    """The report's rows, per-point outcomes, failures and notes."""
    protocol = bool(report.protocol)
    paper = any(not math.isnan(r.paper) for r in report.rows)
    proc = report.method
    head = ["Quantity", "Conf. [%]", f"{proc} simulated", "predicted", "bias"]
    head += ["paper protocol"] if protocol else []
    head += ["best fit (fed as the procedure) simulated", "predicted", "bias"]
    head += ["paper protocol"] if protocol else []
    head += ["paper"] if paper else []
    lines = [
        f"Program: {report.program}" if report.program else "Program: not given",
        *(
            [f"CHECK REFUSES THIS PLAN (simulated anyway): {'; '.join(report.check_problems)}"]
            if report.check_problems
            else []
        ),
        f"Procedure: {report.method}, sensor: {report.sensor}. Trials: {report.n_trials}, "
        f"calibrated: {report.n_ok}, time: {report.elapsed_s:.2f} s on {report.workers} "
        "worker(s)" + (f"; paper protocol: {report.protocol}" if protocol else ""),
        *([warning] if (warning := reach_warning(report)) else []),
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    lines += ["| " + " | ".join(_row_cells(r, protocol, paper)) + " |" for r in report.rows]
    if report.noise:
        figures = ", ".join(f"{k} {v * 1e3:.4g} mm" for k, v in report.noise.items())
        lines += ["", f"Noise figures (1 sigma): {figures}."]
    if paper:
        lines += ["", ROTATION_NOTE]
    lines += [
        "",
        f"Reachability and collisions of the displaced searches checked in the cell on "
        f"{report.reach_checked} of {report.n_trials} trials."
        if report.reach_checked
        else "Reachability and collisions of the displaced searches: not checked.",
    ]
    if report.outcomes:
        lines += [
            "",
            "| Search | runs | failed | landed off its face | footprint partly over a hole "
            "or an edge | mean / max fraction off |",
            "|---|---|---|---|---|---|",
        ]
        for o in report.outcomes:
            failed = "; ".join(f"{w}: {n}" for w, n in failed_by_words(o.failed).items()) or "0"
            frac = f"{o.off_fraction_mean:.0%} / {o.off_fraction_max:.0%}" if o.partly_off else "—"
            lines.append(
                f"| {o.point_id} | {o.searches} | {failed} | {o.landed_off} | {o.partly_off} "
                f"| {frac} |"
            )
    lines += ["", "Failures:" if report.failures else "Failures: none"]
    lines += [f"- {k}: {v}" for k, v in sorted(report.failures.items())]
    lines += ["", "Landings:" if report.landings else "Landings: none over holes or off faces"]
    lines += [f"- {k}: {v}" for k, v in sorted(report.landings.items())]
    if report.notes:
        lines += [""] + [f"- {n}" for n in report.notes]
    return "\n".join(lines) + "\n"
