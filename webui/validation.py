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
from calib.plan_procedures import method_of
from webui.backend import NotAvailableError

Progress = Callable[[int, int], None]
#: Built-in stator meshes the Monte Carlo simulation knows -> StatorGeometry constructor.
STATOR_MESHES = {"builtin:stator_section": "full_section", "builtin:stator_prototype": "prototype"}


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
        return importlib.import_module("planner.montecarlo")
    except ImportError as exc:
        raise NotAvailableError(
            f"Monte Carlo validation is not available yet (planner.montecarlo: {exc})"
        ) from None


def check_available() -> None:
    """Raise :class:`NotAvailableError` when the validation cannot run here."""
    _montecarlo()


def check_supported(plan: Plan) -> None:
    """Raise :class:`NotAvailableError` when ``planner.montecarlo`` cannot simulate ``plan``."""
    if method_of(plan.procedure) != "hultman2013":
        raise NotAvailableError(
            "Monte Carlo validation simulates the paper's A-H procedure (hultman2013) only; "
            f"this plan uses {method_of(plan.procedure)}"
        )
    if plan.work_object.mesh not in STATOR_MESHES:
        raise NotAvailableError(
            "Monte Carlo validation simulates the built-in stator sections "
            f"({', '.join(STATOR_MESHES)}) only; this plan's work object is "
            f"{plan.work_object.mesh}"
        )


def run_validation(
    plan: Plan, plan_dir: Path, trials: int, progress: Progress
) -> ValidationSummary:
    """Simulate the plan's calibration ``trials`` times with its error models (in-process).

    Mirrors ``wobjcal validate`` (``planner.cli_validate.cmd_validate``): the same models,
    procedure settings and seed, but one in-process worker (no ``fork()`` of a threaded server).
    """
    mc = _montecarlo()
    check_supported(plan)
    plan_io = importlib.import_module("planner.plan_io")
    stator = importlib.import_module("planner.stator")
    sp = importlib.import_module("calib.stator_procedure")
    cli_validate = importlib.import_module("planner.cli_validate")
    models = cli_validate._models(plan)  # the plan -> sensor/robot/misplacement mapping
    edge_inset_m = getattr(mc, "DEFAULT_EDGE_INSET_M", 0.002)
    settings = plan.procedure
    edge_offset = getattr(settings, "edge_event_offset_m", None)
    if edge_offset is None:
        edge_offset = models["sensor"].edge_event_offset_m(edge_inset_m)
    stator_settings = sp.StatorSettings(
        beta1_rad=settings.beta1_rad,  # type: ignore[union-attr]
        p3_height_m=settings.p3_height_m,  # type: ignore[union-attr]
        retake_c_d=settings.retake_c_d,  # type: ignore[union-attr]
        edge_start_from_measured=settings.edge_start_from_measured,  # type: ignore[union-attr]
        edge_start_offset_m=settings.edge_start_offset_m,  # type: ignore[union-attr]
        edge_event_offset_m=edge_offset,
    )
    report = mc.validate(
        plan_io.hultman_points(plan),
        getattr(stator.StatorGeometry, STATOR_MESHES[plan.work_object.mesh])(),
        plan_io.nominal_T_base_wobj(plan),
        int(trials),
        np.random.default_rng(plan.validation.seed),
        workers=1,
        progress=progress,
        settings=stator_settings,
        edge_inset_m=edge_inset_m,
        **models,
    )
    return summarize(report)


def _histogram(samples: Any, scale: float, bins: int = 30) -> tuple[Any, Any]:
    x = np.asarray(samples, dtype=np.float64).ravel() * scale
    x = x[np.isfinite(x)]
    counts, edges = np.histogram(x, bins=bins)
    return edges, counts


def summarize(report: Any) -> ValidationSummary:
    """Shape a ``planner.montecarlo_report.ValidationReport`` for the panel."""
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
