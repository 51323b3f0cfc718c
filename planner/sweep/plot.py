"""``sweep.png``: where the robot base may stand, coloured by what the check says there.

Two panels over the base offsets (x, y in mm from the plan's base): left, each placement's
status (feasible, infeasible, error) sized by how many of its points are feasible; right, the
feasible placements coloured by the predicted accuracy (``accuracy_mm``) with a colour bar. The
part's offsets are not drawn (they are columns of ``sweep.csv``). Drawn with matplotlib's Agg
canvas (no display, no global pyplot state) and written atomically.
"""

from __future__ import annotations

import io
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from calib.atomic_io import write_bytes_atomic
from planner.sweep.files import COLUMNS

_COLOURS = {"feasible": "tab:green", "infeasible": "tab:red", "error": "tab:gray"}


def _column(rows: list[list[str]], name: str) -> list[str]:
    i = COLUMNS.index(name)
    return [r[i] for r in rows]


def plot_sweep(rows: list[list[str]], path: Path, title: str) -> Path:
    """Draw the sweep's ``rows`` (CSV cells, :data:`~planner.sweep.files.COLUMNS`) to the PNG
    ``path``; return it."""
    fig = Figure(figsize=(11, 4.8))
    FigureCanvasAgg(fig)
    ax_status, ax_acc = fig.subplots(1, 2)
    x = [float(v) for v in _column(rows, "base_dx_mm")]
    y = [float(v) for v in _column(rows, "base_dy_mm")]
    status = _column(rows, "status")
    share = [
        int(f) / int(t) if int(t) else 0.0
        for f, t in zip(
            _column(rows, "points_feasible"), _column(rows, "points_total"), strict=True
        )
    ]
    for name, colour in _COLOURS.items():
        idx = [i for i, s in enumerate(status) if s == name]
        if idx:
            ax_status.scatter(
                [x[i] for i in idx],
                [y[i] for i in idx],
                s=[10 + 40 * share[i] for i in idx],
                c=colour,
                label=f"{name} ({len(idx)})",
                alpha=0.8,
            )
    ax_status.set_title("status (size: share of points feasible)")
    if rows:
        ax_status.legend(loc="best", fontsize="small")
    acc = _column(rows, "accuracy_mm")
    ok = [i for i, s in enumerate(status) if s == "feasible" and acc[i]]
    if ok:
        sc = ax_acc.scatter(
            [x[i] for i in ok], [y[i] for i in ok], c=[float(acc[i]) for i in ok], cmap="viridis"
        )
        fig.colorbar(sc, ax=ax_acc, label="accuracy, mm (worst point of interest)")
    ax_acc.set_title("predicted accuracy of the feasible placements")
    for ax in (ax_status, ax_acc):
        ax.set_xlabel("base x offset from the plan, mm")
        ax.set_ylabel("base y offset from the plan, mm")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"wobjcal sweep {title}: {len(rows)} placements")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    return write_bytes_atomic(path, buf.getvalue())
