"""Between the validate panel and ``planner.validate.job``: run it, shape its report for the UI.

Besides the report's Markdown and histograms, :func:`error_colours` paints the simulated error
over the part onto the work object's vertices (each vertex takes the error of the nearest
surface sample of :attr:`planner.sim.report.ValidationReport.error_map`), so the UI can show
where on the part the calibration is least accurate.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from calib.plan.file import Plan
from planner.sim.report import ValidationReport
from planner.validate.job import validate_plan
from webui.scene import heat_rgb

Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class ValidationSummary:
    """What the validate panel shows.

    Attributes:
        report: the report :func:`planner.validate.job.validate_plan` returned.
        markdown: the report's rows (simulated, predicted, bias), per-point outcomes, failures.
        histograms: ``(title, unit, bin_edges (B+1,), counts (B,))`` for each error
            histogram: edges in ``unit`` (``"mm"`` or ``"deg"``), counts of samples.
        headline: one line for the notification.
        T_world_wobj_example: ``(4, 4)`` one calibrated frame to draw, or ``None``.
    """

    report: ValidationReport
    markdown: str
    histograms: tuple[tuple[str, str, NDArray[np.float64], NDArray[np.float64]], ...]
    headline: str
    T_world_wobj_example: NDArray[np.float64] | None = None


def run_validation(
    plan: Plan, trials: int, progress: Progress, plan_dir: Path | None = None
) -> ValidationSummary:
    """Simulate the plan's calibration ``trials`` times with its error models and seed.

    The same :func:`planner.validate.job.validate_plan` as ``wobjcal validate`` (the same mesh,
    loaded from the plan, the same check first), with one in-process worker (no worker
    processes beside a threaded server). A plan ``wobjcal check`` refuses is simulated anyway, as
    ``validate --force`` does: the report and the headline say check refuses it and why.

    Raises:
        PlanError: the plan cannot be simulated (the message names the point or field).
    """
    report = validate_plan(
        plan, trials=int(trials), workers=1, progress=progress, plan_dir=plan_dir, check="report"
    )
    return summarize(report)


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
        title = f"{labels.get(key, key)} ({unit}, {int(counts.sum())} samples)"
        hists.append((title, unit, edges, counts.astype(np.float64)))
    failed = sum(report.failures.values())
    headline = f"{report.n_ok}/{report.n_trials} trials calibrated, {failed} failed"
    if report.check_problems:
        n = len(report.check_problems)
        problems = "1 problem" if n == 1 else f"{n} problems"
        headline = f"check refuses this plan ({problems}); " + headline
    return ValidationSummary(report, markdown, tuple(hists), headline)


def error_colours(
    report: ValidationReport, mesh: trimesh.Trimesh
) -> tuple[NDArray[np.uint8], float, float] | None:
    """Vertex colours of ``mesh`` (wobj) from the report's error map, and its range (m).

    Green is the smallest error on the part, red the largest; ``None`` without a map.
    """
    emap = report.error_map
    if emap is None or len(emap.points_wobj) == 0 or not np.all(np.isfinite(emap.error_m)):
        return None
    _, idx = cKDTree(emap.points_wobj).query(np.asarray(mesh.vertices, dtype=np.float64))
    err = emap.error_m[idx]
    lo, hi = float(emap.error_m.min()), float(emap.error_m.max())
    score = 1.0 - (err - lo) / max(hi - lo, 1e-12)
    return heat_rgb(score), lo, hi
