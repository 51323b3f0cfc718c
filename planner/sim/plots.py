"""PNG plots of a Monte Carlo validation: error histograms, a scatter, the error over the part.

``histograms.png`` shows the distribution of every row's quantity for the procedure and the
best fit fed as the procedure is fed, each with its fitted normal density and the predicted one
(paper Fig. 12). ``scatter.png`` shows the calibrated origin and a point of interest (the
paper's epsilon on the stator) in the true WOCS yz-plane, relative to their mean (Fig. 10-11).
``error_map.png`` colours the part's surface by the simulated error: the radius within which
95.5 % of calibrations place each point (:mod:`planner.sim.error_map`). Figures are drawn with
matplotlib's Agg canvas (no display, no global pyplot state) and written atomically.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import NDArray
from scipy.stats import norm

from calib.atomic_io import write_bytes_atomic
from calib.frames import small_motion
from planner.sim.report import ValidationReport
from planner.sim.rows import SCALE

FloatArray = NDArray[np.float64]


def _save(fig: Figure, path: Path) -> Path:
    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return write_bytes_atomic(path, buf.getvalue())


def _row_kinds(report: ValidationReport) -> list[tuple[str, str, str, float]]:
    """``(key, label, unit, predicted sigma in display units)`` of each distinct row."""
    out: dict[str, tuple[str, str, str, float]] = {}
    for r in report.rows:
        if r.key not in out:
            z = float(norm.ppf(0.5 + r.level_percent / 200.0))
            out[r.key] = (r.key, r.label, r.unit, r.procedure_predicted / z if z else math.nan)
    return list(out.values())


def histogram_figure(report: ValidationReport) -> Figure:
    """Histograms of every row's quantity, with fitted (solid) and predicted (dashed) normals."""
    kinds = _row_kinds(report)
    ncols = 3
    nrows = max(1, math.ceil(len(kinds) / ncols))
    fig = Figure(figsize=(12, 3.3 * nrows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, ncols)).ravel()
    for ax in axes[len(kinds) :]:
        ax.set_axis_off()
    for ax, (key, label, unit, sigma_pred) in zip(axes, kinds, strict=False):
        scale = SCALE[unit]
        proc = report.samples_procedure.get(key, np.zeros(0)) * scale
        fit = report.samples_best_fit.get(key, np.zeros(0)) * scale
        both = np.concatenate([proc, fit])
        both = both[np.isfinite(both)]
        if both.size == 0:
            ax.set_title(f"{label}: no data", fontsize=9)
            continue
        span = max(float(np.abs(both).max()), 1e-12)
        bins = np.linspace(-span, span, 41)
        x = np.linspace(-span, span, 200)
        for data, colour, name in (
            (proc, "tab:blue", report.method),
            (fit, "tab:orange", "best fit"),
        ):
            data = data[np.isfinite(data)]
            if data.size == 0:
                continue
            ax.hist(data, bins=bins, density=True, alpha=0.45, color=colour, label=name)
            sd = float(np.std(data, ddof=1)) if data.size > 1 else 0.0
            if sd > 0:
                ax.plot(x, norm.pdf(x, float(np.mean(data)), sd), color=colour)
        if math.isfinite(sigma_pred) and sigma_pred > 0:
            ax.plot(x, norm.pdf(x, 0.0, sigma_pred), "k--", lw=1, label="predicted")
        ax.set_title(label, fontsize=9)
        ax.set_xlabel(f"error about the mean [{unit}]", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=7)
    fig.suptitle(f"Monte Carlo validation, {report.n_ok} of {report.n_trials} trials calibrated")
    return fig


def _yz_errors(delta: FloatArray, p_wobj: FloatArray) -> FloatArray:
    """``(n, 2)`` yz error (m) of a wobj point placed with each calibrated frame."""
    T = small_motion(delta)
    e = np.einsum("nij,j->ni", T[:, :3, :3], p_wobj) + T[:, :3, 3] - p_wobj
    return e[:, 1:]


def scatter_figure(report: ValidationReport, point_m: FloatArray, name: str = "epsilon") -> Figure:
    """The calibrated origin (Fig. 10) and a point (Fig. 11) in the yz-plane, mm."""
    fig = Figure(figsize=(11, 5), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, p, title in (
        (axes[0], np.zeros(3), "WOCS origin (Fig. 10)"),
        (axes[1], np.asarray(point_m, float), f"{name} (Fig. 11)"),
    ):
        for delta, colour, label in (
            (report.delta_procedure, "tab:blue", report.method),
            (report.delta_best_fit, "tab:orange", "best fit"),
        ):
            if len(delta) == 0:
                continue
            yz = _yz_errors(delta, p) * 1e3
            rel = yz - yz.mean(axis=0)
            ax.plot(rel[:, 0], rel[:, 1], "x", ms=4, color=colour, alpha=0.6, label=label)
        ax.plot([0.0], [0.0], "s", color="red", ms=7, label="mean (the paper's 'correct')")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("y error about the mean [mm]")
        ax.set_ylabel("z error about the mean [mm]")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    return fig


def error_map_figure(report: ValidationReport) -> Figure:
    """The part's surface coloured by the simulated error (the map's level), probe points black."""
    emap = report.error_map
    fig = Figure(figsize=(9, 7), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    if emap is None or len(emap.points_wobj) == 0:
        ax.set_title("error map: no data")
        return fig
    P = emap.points_wobj * 1e3
    sc = ax.scatter(P[:, 0], P[:, 1], P[:, 2], c=emap.error_m * 1e3, cmap="viridis", s=6)
    Q = np.asarray(report.probe_points_wobj, float).reshape(-1, 3) * 1e3
    if len(Q):
        ax.scatter(Q[:, 0], Q[:, 1], Q[:, 2], c="k", marker="^", s=40, label="probe points")
        ax.legend(fontsize=8)
    ext = np.ptp(P, axis=0)
    ax.set_box_aspect(tuple(float(max(e, 1e-3 * ext.max())) for e in ext))
    ax.set_xlabel("wobj x [mm]")
    ax.set_ylabel("wobj y [mm]")
    ax.set_zlabel("wobj z [mm]")
    fig.colorbar(sc, ax=ax, shrink=0.7, label=f"error at {emap.level_percent:g} % [mm]")
    ax.set_title(
        f"{report.method}: {emap.level_percent:g} % of calibrations place each point within this"
    )
    return fig


def save_validation_plots(
    report: ValidationReport, out_dir: str | Path, point_m: FloatArray | None = None
) -> list[Path]:
    """Write ``histograms.png``, ``scatter.png`` and ``error_map.png`` into ``out_dir``.

    Args:
        report: the validation report.
        out_dir: output directory (created if missing).
        point_m: ``(3,)`` the point of the scatter's right panel, wobj, m (default the report's
            last point of interest, e.g. the paper's epsilon).

    Returns:
        The paths written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    name = "point"
    if point_m is None and report.points_of_interest:
        name, p = list(report.points_of_interest.items())[-1]
        point_m = p
    p_m = np.zeros(3) if point_m is None else np.asarray(point_m, float)
    paths = [
        _save(histogram_figure(report), out / "histograms.png"),
        _save(scatter_figure(report, p_m, name), out / "scatter.png"),
    ]
    if report.error_map is not None:
        paths.append(_save(error_map_figure(report), out / "error_map.png"))
    return paths
