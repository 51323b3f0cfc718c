"""``wobjcal suggest``: propose probe points that meet a target error at the points of interest.

Calls :func:`planner.suggest.suggest_plan` (the same job the web UI's "Suggest" button runs)
and writes the plan atomically.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from calib.limits import MAX_REPORT_ROWS
from calib.procedures import DESIGNED, GROWN
from planner.cli.common import count_arg, read_plan, stdout
from planner.program.controllers import CONTROLLERS, DEFAULT_CONTROLLER
from planner.suggest import DEFAULT_PROCEDURE

if TYPE_CHECKING:
    from rich.table import Table

    from planner.suggest import SuggestResult


def _points_mm(text: str) -> np.ndarray:
    """``"X,Y,Z[;X,Y,Z...]"`` in millimetres, wobj frame -> ``(K, 3)`` metres."""
    try:
        rows = [[float(v) for v in part.split(",")] for part in text.split(";") if part.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"points are X,Y,Z[;X,Y,Z...] in mm, got {text!r}"
        ) from None
    if not rows or any(len(r) != 3 for r in rows) or not np.all(np.isfinite(rows)):
        raise argparse.ArgumentTypeError(f"points are X,Y,Z[;X,Y,Z...] in mm, got {text!r}")
    if len(rows) > MAX_REPORT_ROWS:
        raise argparse.ArgumentTypeError(
            f"{len(rows):,} points, at most {MAX_REPORT_ROWS} (each is a row of the design's "
            "prediction, as validation.report.points_of_interest)"
        )
    return np.asarray(rows, dtype=np.float64) * 1e-3


def _positive_mm(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a distance in mm, got {text!r}") from None
    if not (v > 0 and np.isfinite(v)):
        raise argparse.ArgumentTypeError(f"a positive distance in mm, got {text!r}")
    return v * 1e-3


def _percent(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a percentage, got {text!r}") from None
    if not 0 < v <= 99.9999:
        raise argparse.ArgumentTypeError(f"a confidence in (0, 99.9999] percent, got {text!r}")
    return v


def _plot_path(text: str) -> Path:
    from planner.suggest.front_files import PLOT_SUFFIXES

    path = Path(text)
    if path.suffix.lower() not in PLOT_SUFFIXES:
        raise argparse.ArgumentTypeError(
            f"a plot file ending in {', '.join(PLOT_SUFFIXES)}, got {text!r}"
        )
    if not path.resolve().parent.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r}: its folder does not exist")
    return path


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``suggest`` to the subparsers ``sub``."""
    p = add(
        sub,
        "suggest",
        "propose probe points that meet a target error at the points of interest",
        "Sample candidate approach searches on the part's planar faces (the sensor footprint,\n"
        "grown by the misplacement's translation, on the face), keep those whose probe pose\n"
        "and search path are feasible in the plan's cell, and choose the set that minimises\n"
        "the predicted error at the points of interest (greedy plus exchange on the\n"
        "information matrix), adding points until the target holds at the confidence or\n"
        "--max-points is reached. Writes the plan (atomically) and prints its predicted\n"
        "quality. --procedure is any procedure whose registry entry has a layout design: the\n"
        "best fit and the iterative best fit grow point by point, the 3-2-1 puts 3, 2 and 1\n"
        "points on three faces. With --add N the plan's points are kept and N are added (a\n"
        "procedure that grows; a 3-2-1 or A-H plan becomes one of all its points, since those\n"
        "take exactly their own). With --objective time (a procedure that grows, needs\n"
        "--target) every size from 6 to --max-points is designed, written in its landing order\n"
        "and in the order of least joint-move time, and, when the --format controller steers\n"
        "the procedure adaptively, once more with its later searches started nearer\n"
        "(search_sizing steered: only an adaptive program runs it), checked and timed as\n"
        "'wobjcal check' does, and the plan of least cycle time that meets\n"
        "the target is written; the accuracy-versus-time front is printed as a table, and with\n"
        "--front FILE plotted (PNG, SVG or PDF; the table beside it as FILE.csv).\n\n"
        "exit codes: 0 target met (or none given) and the plan passes 'wobjcal check' for\n"
        "--format, 1 target not reached or check refuses the plan (named; the best plan found\n"
        "is still written), 2 bad input or no feasible layout (faces tried and why)",
        "wobjcal suggest plan.json --target 0.3 -o suggested.json\n"
        "wobjcal suggest plan.json --procedure three_two_one -o plan_321.json\n"
        "wobjcal suggest plan.json --at 0,-600,-150 --confidence 99 --target 0.2 -o out.json\n"
        "wobjcal suggest suggested.json --add 1 -o plus_one.json\n"
        "wobjcal suggest plan.json --target 0.3 --objective time --front front.png -o fast.json",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1): cell, part, models")
    p.add_argument(
        "--target",
        type=_positive_mm,
        metavar="MM",
        help="largest predicted error at the points of interest, mm",
    )
    p.add_argument(
        "--confidence",
        type=_percent,
        metavar="PCT",
        help="confidence of the target, percent (default: the plan's first level)",
    )
    p.add_argument(
        "--at",
        type=_points_mm,
        metavar="POINTS",
        help="points of interest X,Y,Z[;X,Y,Z...] in mm, wobj frame (default: the plan's)",
    )
    p.add_argument(
        "--max-points",
        type=count_arg(6, 40),
        default=8,
        metavar="N",
        help="most points to suggest (default 8; the number used without --target)",
    )
    p.add_argument(
        "--procedure",
        choices=DESIGNED,
        default=DEFAULT_PROCEDURE,
        help=f"the procedure of the suggested plan (default {DEFAULT_PROCEDURE})",
    )
    p.add_argument(
        "--add",
        type=count_arg(1, 40),
        default=0,
        metavar="N",
        help="keep the plan's points and add the N best (a procedure whose layout grows: "
        + ", ".join(GROWN)
        + ")",
    )
    p.add_argument(
        "--format",
        choices=list(CONTROLLERS),
        default=DEFAULT_CONTROLLER,
        help="design for the program this controller's export runs (default: "
        f"{DEFAULT_CONTROLLER}; a nominal program lands every search anywhere the whole "
        "misplacement allows)",
    )
    p.add_argument(
        "--objective",
        choices=("accuracy", "time"),
        default="accuracy",
        help="accuracy (default): the least error, points added until the target holds; time: "
        "the least cycle time whose predicted error holds --target",
    )
    p.add_argument(
        "--front",
        type=_plot_path,
        metavar="FILE",
        help="plot the accuracy-versus-time front to FILE (.png, .svg or .pdf) and write its "
        "table to FILE.csv (a procedure that grows)",
    )
    p.add_argument("-o", "--output", metavar="OUT", required=True, help="plan file to write")
    p.set_defaults(handler=cmd_suggest)


def front_table(res: SuggestResult) -> Table:
    """The accuracy-versus-time front of ``res`` as a table (the written plan marked ``*``)."""
    from rich.table import Table

    t = Table(
        title=f"accuracy versus cycle time (predicted error at {res.confidence_percent:g} %; "
        "each plan written, checked and timed; * written)"
    )
    for name in ("points", "order", "error mm", "cycle time s", "target", "front", "check"):
        t.add_column(
            name, justify="right" if name in ("points", "error mm", "cycle time s") else "left"
        )
    for r in res.front:
        if r.problems:
            verdict = "; ".join(r.problems)
            verdict = verdict if len(verdict) <= 70 else verdict[:69] + "…"
        else:
            verdict = "passes" if r.rating == "ok" else f"passes, layout {r.rating or 'unrated'}"
        t.add_row(
            f"{r.points}{' *' if r.written else ''}",
            ("least move time" if r.order == "time" else "landing")
            + (", steered searches" if r.searches == "steered" else ""),
            f"{r.worst_m * 1e3:.3f}" if math.isfinite(r.worst_m) else "-",
            f"{r.cycle_s:.1f}" if math.isfinite(r.cycle_s) else "-",
            "meets" if r.meets_target else "misses",
            "yes" if r.pareto else "",
            verdict,
        )
    return t


def cmd_suggest(args: argparse.Namespace) -> int:
    """Suggest, write the plan, print its quality; exit 0 when the target holds, else 1."""
    from calib.plan.file import save_plan
    from planner.cli.check import quality_table
    from planner.suggest import suggest_plan

    plan, plan_dir = read_plan(args.plan, "suggest")
    out = stdout()
    res = suggest_plan(
        plan,
        plan_dir,
        target_m=args.target,
        confidence_percent=args.confidence,
        at_m=args.at,
        max_points=args.max_points,
        procedure=args.procedure,
        add=args.add,
        fmt=args.format,
        objective=args.objective,
        front=args.front is not None,
        progress=lambda stage, done, total: print(
            f"wobjcal suggest: {stage} {done}/{total}", file=sys.stderr
        ),
    )
    target = Path(args.output)
    plan_out = res.plan
    if target.resolve().parent != plan_dir.resolve():  # keep relative file references working
        from planner.suggest import moved_plan

        plan_out = moved_plan(plan_out, plan_dir, target.resolve().parent)
    save_plan(plan_out, target)
    for pt in res.plan.points[len(res.plan.points) - (args.add or len(res.plan.points)) :]:
        pos = ", ".join(f"{c * 1e3:.1f}" for c in pt.position_m)
        nrm = ", ".join(f"{c:.3f}" for c in pt.normal)
        out.print(f"{pt.id} ({pt.role}): ({pos}) mm, normal ({nrm})", markup=False)
    if res.quality is not None:
        out.print(
            quality_table(res.quality, "feasible" if res.quality.rating == "ok" else "marginal")
        )
    if res.front:
        out.print(front_table(res), markup=False)
    if args.front is not None and res.front:
        from planner.suggest.front_files import plot_front

        plot_front(
            res.front,
            args.front,
            title=f"{Path(args.plan).name}: accuracy versus cycle time ({args.format})",
            target_m=res.target_m,
            level_percent=res.confidence_percent,
        )
        out.print(f"front: {args.front} and {args.front.with_suffix('.csv')}", markup=False)
    kept = ", ".join(f"{k} {v}" for k, v in sorted(res.rejected.items()))
    out.print(
        f"{res.n_feasible} of {res.n_candidates} candidates feasible"
        + (f" (dropped: {kept})" if kept else "")
        + f"; {res.elapsed_s:.1f} s",
        markup=False,
    )
    out.print(f"{res.message}; wrote {target}", markup=False, style=None if res.met else "red")
    return 0 if res.met else 1
