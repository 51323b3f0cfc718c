"""Between the validate panel and ``planner.montecarlo``: run it, shape its report for the UI."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from calib.plan import Plan
from webui.backend import NotAvailableError

Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class ValidationSummary:
    """What the validate panel shows.

    Attributes:
        report: the ``planner.montecarlo`` report object, as returned.
        markdown: Table-1-style markdown (confidence intervals) and the per-point failures.
        histograms: ``(title, bin_edges (B+1,), counts (B,))`` for each error histogram.
        headline: one line for the notification.
        T_world_wobj_example: ``(4, 4)`` one calibrated frame to draw, or ``None``.
    """

    report: Any
    markdown: str
    histograms: tuple[tuple[str, NDArray[np.float64], NDArray[np.float64]], ...]
    headline: str
    T_world_wobj_example: NDArray[np.float64] | None = None


def _montecarlo() -> Any:
    try:
        mod = importlib.import_module("planner.montecarlo")
    except ImportError as exc:
        raise NotAvailableError(
            f"Monte Carlo validation is not available yet (planner.montecarlo: {exc})"
        ) from None
    if not hasattr(mod, "validate"):
        raise NotAvailableError("Monte Carlo validation is not available yet (no validate())")
    return mod


def check_available() -> None:
    """Raise :class:`NotAvailableError` when the validation cannot run here."""
    _montecarlo()


def run_validation(
    plan: Plan, plan_dir: Path, trials: int, progress: Progress
) -> ValidationSummary:
    """Run ``planner.montecarlo.validate`` on ``plan`` and summarise its report."""
    mod = _montecarlo()
    rng = np.random.default_rng(plan.validation.seed)
    report = mod.validate(plan, plan_dir=plan_dir, trials=trials, rng=rng, progress=progress)
    return summarize(report)


def summarize(report: Any) -> ValidationSummary:
    """Shape a validation report for the panel (markdown table, histograms, failures)."""
    table = report.table_markdown() if callable(getattr(report, "table_markdown", None)) else ""
    table = table or str(getattr(report, "markdown", ""))
    failures = getattr(report, "failures", {}) or {}
    lines = [table, ""]
    if failures:
        lines += ["**Failures**", "", "| point | count | reason |", "|---|---|---|"]
        for key, count in sorted(failures.items(), key=lambda kv: -kv[1]):
            pid, reason = key if isinstance(key, tuple) else (key, "")
            lines.append(f"| {pid} | {count} | {str(reason).replace('|', '/')} |")
    else:
        lines.append("No failed trials.")
    hists = []
    for title, (edges, counts) in (getattr(report, "histograms", {}) or {}).items():
        hists.append((str(title), np.asarray(edges, float), np.asarray(counts, float)))
    n_ok = getattr(report, "n_ok", None)
    n_total = getattr(report, "n_trials", None)
    headline = f"{n_ok}/{n_total} trials succeeded" if n_total else "validation finished"
    return ValidationSummary(report, "\n".join(lines), tuple(hists), headline)
