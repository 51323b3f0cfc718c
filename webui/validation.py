"""Between the validate panel and ``planner.validate``: run it, shape its report for the UI."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.plan.file import Plan
from planner.sim.report import ValidationReport
from planner.validate import validate_plan

Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class ValidationSummary:
    """What the validate panel shows.

    Attributes:
        report: the report :func:`planner.validate.validate_plan` returned.
        markdown: Table-1-style markdown (confidence intervals) and the per-point failures.
        histograms: ``(title, bin_edges (B+1,), counts (B,))`` for each error histogram.
        headline: one line for the notification.
        T_world_wobj_example: ``(4, 4)`` one calibrated frame to draw, or ``None``.
    """

    report: ValidationReport
    markdown: str
    histograms: tuple[tuple[str, NDArray[np.float64], NDArray[np.float64]], ...]
    headline: str
    T_world_wobj_example: NDArray[np.float64] | None = None


def run_validation(plan: Plan, trials: int, progress: Progress) -> ValidationSummary:
    """Simulate the plan's calibration ``trials`` times with its error models and seed.

    The same :func:`planner.validate.validate_plan` as ``wobjcal validate``, with one
    in-process worker (no ``fork()`` of a threaded server).

    Raises:
        PlanError: the plan cannot be simulated (the message names the field).
    """
    return summarize(validate_plan(plan, trials=int(trials), workers=1, progress=progress))


def _histogram(
    samples: ArrayLike, scale: float, bins: int = 30
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    x = np.asarray(samples, dtype=np.float64).ravel() * scale
    x = x[np.isfinite(x)]
    counts, edges = np.histogram(x, bins=bins)
    return edges, counts


def summarize(report: ValidationReport) -> ValidationSummary:
    """Shape a ``planner.sim.report.ValidationReport`` for the panel."""
    markdown = report.to_markdown()
    units = {r.key: r.unit for r in report.rows}
    labels = {r.key: r.label for r in report.rows}
    hists = []
    for key, samples in report.samples_procedure.items():
        unit = units.get(key, "mm")
        scale = 1000.0 if unit == "mm" else float(np.degrees(1.0))
        edges, counts = _histogram(samples, scale)
        hists.append((f"{labels.get(key, key)} ({unit})", edges, counts.astype(np.float64)))
    failed = sum(report.failures.values())
    headline = f"{report.n_ok}/{report.n_trials} trials calibrated, {failed} failed"
    return ValidationSummary(report, markdown, tuple(hists), headline)
