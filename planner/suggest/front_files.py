"""The accuracy-versus-time front written out: a CSV table and a plot (``wobjcal suggest
--front FILE``).

The plot puts each written plan of the front (:class:`planner.suggest.front.FrontRow`) at its
estimated cycle time (s, x) and predicted error at the points of interest (mm, y): the plans
in their landing order as circles, in the order of least move time as triangles, with their
searches steered (an adaptive program only) as squares, each labelled with its number of
points; the Pareto front as a line, the target as a dashed line, the plan written ringed,
and plans check refuses as crosses. Drawn with matplotlib's Agg canvas (no display, no global
pyplot state); both files are written atomically.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from calib.atomic_io import write_bytes_atomic, write_text_atomic

if TYPE_CHECKING:
    from planner.suggest.front import FrontRow

#: The CSV's columns, as :meth:`FrontRow.to_json` names them.
COLUMNS = (
    "points",
    "order",
    "searches",
    "error_mm",
    "cycle_time_s",
    "rating",
    "meets_target",
    "pareto",
    "check",
)
#: File types the plot can be written as.
PLOT_SUFFIXES = (".png", ".svg", ".pdf")


def front_csv(rows: Sequence[FrontRow]) -> str:
    """The front as CSV text: :data:`COLUMNS` and ``written`` (the plan written)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([*COLUMNS, "written"])
    for r in rows:
        j = r.to_json()
        w.writerow([_cell(j[c]) for c in COLUMNS] + [_cell(r.written)])
    return buf.getvalue()


def _style(row: FrontRow) -> str:
    """The row's marker: its searches when steered, else its order."""
    return "steered" if row.searches == "steered" else row.order


def _cell(v: object) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def plot_front(
    rows: Sequence[FrontRow],
    path: Path,
    *,
    title: str,
    target_m: float | None,
    level_percent: float,
) -> Path:
    """Draw the front to ``path`` (:data:`PLOT_SUFFIXES`; the plan written ringed) and its CSV
    beside it (``path`` with ``.csv``); return the plot's path."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    chosen = next((r for r in rows if r.written), None)
    fig = Figure(figsize=(7.5, 5.0))
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    timed = [r for r in rows if math.isfinite(r.cycle_s) and math.isfinite(r.worst_m)]
    styles = {
        "landing": ("o", "tab:blue"),
        "time": ("^", "tab:orange"),
        "steered": ("s", "tab:purple"),
    }
    names = {
        "landing": "landing order",
        "time": "least move time",
        "steered": "steered searches (adaptive only)",
    }
    for order, (marker, colour) in styles.items():
        ok = [r for r in timed if _style(r) == order and r.usable]
        bad = [r for r in timed if _style(r) == order and not r.usable]
        if ok:
            ax.scatter(
                [r.cycle_s for r in ok],
                [r.worst_m * 1e3 for r in ok],
                marker=marker,
                c=colour,
                label=names[order],
                zorder=3,
            )
        if bad:
            ax.scatter(
                [r.cycle_s for r in bad],
                [r.worst_m * 1e3 for r in bad],
                marker="x",
                c=colour,
                label=f"{names[order]}, check refuses or weak",
                zorder=3,
            )
        for r in ok + bad:
            ax.annotate(
                str(r.points),
                (r.cycle_s, r.worst_m * 1e3),
                textcoords="offset points",
                xytext=(5, 4),
                fontsize="small",
            )
    front = sorted((r for r in timed if r.pareto), key=lambda r: r.cycle_s)
    if len(front) > 1:
        ax.plot(
            [r.cycle_s for r in front],
            [r.worst_m * 1e3 for r in front],
            c="tab:green",
            lw=1.2,
            label="front (no plan better in both)",
            zorder=2,
        )
    if target_m is not None:
        ax.axhline(target_m * 1e3, c="tab:red", ls="--", lw=1.0, label="target")
    if chosen is not None and math.isfinite(chosen.cycle_s) and math.isfinite(chosen.worst_m):
        ax.scatter(
            [chosen.cycle_s],
            [chosen.worst_m * 1e3],
            s=220,
            facecolors="none",
            edgecolors="k",
            label="written",
            zorder=4,
        )
    ax.set_xlabel("estimated cycle time (s)")
    ax.set_ylabel(f"predicted error at the points of interest (mm, {level_percent:g} %)")
    ax.set_title(title, fontsize="medium")
    ax.grid(True, alpha=0.3)
    if timed:
        ax.legend(loc="best", fontsize="small")
    fig.tight_layout()
    buf = io.BytesIO()
    fmt = path.suffix.lower().lstrip(".")
    fig.savefig(buf, format=fmt, dpi=110)
    write_text_atomic(path.with_suffix(".csv"), front_csv(rows))
    return write_bytes_atomic(path, buf.getvalue())
