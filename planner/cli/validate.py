"""``wobjcal validate``: Monte Carlo validation of a plan, reported like Table 1 of the paper."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from calib.atomic_io import write_text_atomic
from calib.plan.models import MAX_SEED, MAX_TRIALS
from planner.cli.common import count_arg, read_plan, stderr, stdout

#: Most worker processes a validation may start.
MAX_WORKERS = 64

if TYPE_CHECKING:
    from planner.sim.report import ValidationReport


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``validate`` to the subparsers ``sub``."""
    p = add(
        sub,
        "validate",
        "simulate the calibration many times and report confidence intervals (Table 1)",
        "Simulate the whole calibration TRIALS times with the plan's sensor model, robot\n"
        "error model and part misplacement, and print the confidence intervals of the frame\n"
        "and slot-position errors beside the paper's Table 1, plus which points failed how\n"
        "often. Runs the A-H procedure (hultman2013) on a built-in stator work object.\n\n"
        "exit codes: 0 every trial calibrated, 1 some trials failed (listed), 2 bad input",
        "wobjcal validate assets/plans/stator_section_ah.json --trials 400 --seed 1\n"
        "wobjcal validate plan.json --json report.json --plots plots/",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1)")
    p.add_argument(
        "--trials",
        type=count_arg(2, MAX_TRIALS),
        help=f"number of trials, 2 to {MAX_TRIALS:,} (default: the plan's)",
    )
    p.add_argument(
        "--seed", type=count_arg(0, MAX_SEED), help="random seed >= 0 (default: the plan's)"
    )
    p.add_argument(
        "--workers",
        type=count_arg(1, MAX_WORKERS),
        help=f"worker processes, at most {MAX_WORKERS} (default: up to 2)",
    )
    p.add_argument(
        "--reach-trials",
        type=count_arg(0),
        default=20,
        metavar="N",
        help="also check, in the plan's cell, that every search of the first N trials stays "
        "reachable and collision-free where the part really lies (about 0.2 s a trial; "
        "default 20; 0 turns it off)",
    )
    p.add_argument("--json", metavar="FILE", help="also write the report as JSON to FILE")
    p.add_argument("--plots", metavar="DIR", help="also write PNG plots to DIR")
    p.set_defaults(handler=cmd_validate)


def report_json(report: ValidationReport) -> dict[str, Any]:
    """The JSON of a ``ValidationReport``: rows (display units), failures, landings."""

    def num(x: float) -> float | None:
        return float(x) if math.isfinite(x) else None

    return {
        "n_trials": report.n_trials,
        "n_ok": report.n_ok,
        "elapsed_s": report.elapsed_s,
        "rows": [
            {
                "key": r.key,
                "label": r.label,
                "unit": r.unit,
                "level_percent": r.level_percent,
                "procedure": num(r.procedure),
                "procedure_bias": num(r.procedure_bias),
                "best_fit": num(r.best_fit),
                "best_fit_bias": num(r.best_fit_bias),
                "paper": num(r.paper),
            }
            for r in report.rows
        ],
        "failures": report.failures,
        "landings": report.landings,
    }


def cmd_validate(args: argparse.Namespace) -> int:
    """Run the validation with a progress bar and print the report."""
    from planner.validate import check_simulatable, validate_plan

    plan, plan_dir = read_plan(args.plan)
    check_simulatable(plan)  # a clear error before the simulation's heavy imports
    trials = plan.validation.trials if args.trials is None else args.trials
    seed = plan.validation.seed if args.seed is None else args.seed
    with Progress(
        TextColumn("validating"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=stderr(),
        transient=True,
    ) as bar:
        task = bar.add_task("trials", total=trials)
        report = validate_plan(
            plan,
            trials=trials,
            seed=seed,
            workers=args.workers,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
            reach_trials=min(args.reach_trials, trials),
            plan_dir=plan_dir,
        )
    stdout().print(report.to_markdown(), markup=False)
    if args.json:
        data = report_json(report) | {"plan": args.plan, "seed": seed}
        write_text_atomic(args.json, json.dumps(data, indent=2, sort_keys=True) + "\n")
    if args.plots:
        from planner.sim.plots import save_validation_plots

        out_dir = Path(args.plots)
        out_dir.mkdir(parents=True, exist_ok=True)
        written = save_validation_plots(report, out_dir)
        stderr().print(f"plots: {', '.join(str(p) for p in written)}")
    return 0 if report.n_ok == report.n_trials else 1
