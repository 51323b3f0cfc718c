"""PNG plots of a Monte Carlo validation: error histograms and the origin/epsilon scatter.

``histograms.png`` shows the distribution of every Table-1 quantity for the A-H procedure and
the least-squares fit, each with its fitted normal density (paper Fig. 12). ``scatter.png`` shows
the calibrated origin and epsilon in the true WOCS yz-plane, relative to their mean (paper
Fig. 10-11), with the true position as a red mark. Figures are drawn with matplotlib's Agg
canvas (no display, no global pyplot state) and written atomically.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import NDArray
from scipy.stats import norm

from calib.atomic_io import write_bytes_atomic
from calib.frames import small_motion
from planner.sim.report import TABLE1_ROWS, ValidationReport

FloatArray = NDArray[np.float64]
_SCALE = {"mm": 1e3, "deg": float(np.degrees(1.0))}


def _save(fig: Figure, path: Path) -> Path:
    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return write_bytes_atomic(path, buf.getvalue())


def histogram_figure(report: ValidationReport) -> Figure:
    """3 x 3 histograms of the Table-1 quantities with fitted normal densities."""
    fig = Figure(figsize=(12, 10), layout="constrained")
    axes = fig.subplots(3, 3).ravel()
    for ax, (key, label, unit, _levels) in zip(axes, TABLE1_ROWS, strict=True):
        scale = _SCALE[unit]
        proc = report.samples_procedure[key] * scale
        fit = report.samples_best_fit[key] * scale
        both = np.concatenate([proc, fit])
        if both.size == 0 or not np.all(np.isfinite(both)):
            ax.set_title(f"{label}: no data")
            continue
        span = max(float(np.abs(both).max()), 1e-12)
        bins = np.linspace(-span, span, 41)
        x = np.linspace(-span, span, 200)
        for data, colour, name in ((proc, "tab:blue", "A-H"), (fit, "tab:orange", "best fit")):
            ax.hist(data, bins=bins, density=True, alpha=0.45, color=colour, label=name)
            sd = float(np.std(data, ddof=1)) if data.size > 1 else 0.0
            if sd > 0:
                ax.plot(x, norm.pdf(x, float(np.mean(data)), sd), color=colour)
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


def scatter_figure(report: ValidationReport, epsilon_m: FloatArray) -> Figure:
    """The calibrated origin (Fig. 10) and epsilon (Fig. 11) in the yz-plane, mm."""
    fig = Figure(figsize=(11, 5), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, p, title in (
        (axes[0], np.zeros(3), "WOCS origin (Fig. 10)"),
        (axes[1], np.asarray(epsilon_m, float), "epsilon (Fig. 11)"),
    ):
        for delta, colour, name in (
            (report.delta_procedure, "tab:blue", "A-H procedure"),
            (report.delta_best_fit, "tab:orange", "best fit"),
        ):
            if len(delta) == 0:
                continue
            yz = _yz_errors(delta, p) * 1e3
            rel = yz - yz.mean(axis=0)
            ax.plot(rel[:, 0], rel[:, 1], "x", ms=4, color=colour, alpha=0.6, label=name)
        ax.plot([0.0], [0.0], "s", color="red", ms=7, label="mean (the paper's 'correct')")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("y error about the mean [mm]")
        ax.set_ylabel("z error about the mean [mm]")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    return fig


def save_validation_plots(
    report: ValidationReport, out_dir: str | Path, epsilon_m: FloatArray | None = None
) -> list[Path]:
    """Write ``histograms.png`` and ``scatter.png`` into ``out_dir`` (created if missing).

    Args:
        report: the validation report.
        out_dir: output directory.
        epsilon_m: ``(3,)`` the far slot hole, wobj, m (default the paper's (0, -1, -0.1)).

    Returns:
        The paths written.
    """
    from planner.parts.stator import EPSILON_M

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    eps = np.asarray(EPSILON_M if epsilon_m is None else epsilon_m, float)
    return [
        _save(histogram_figure(report), out / "histograms.png"),
        _save(scatter_figure(report, eps), out / "scatter.png"),
    ]
