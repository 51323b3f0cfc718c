"""``wobjcal validate``: Monte Carlo validation of any plan, simulated beside predicted."""

from __future__ import annotations

import argparse
import json
import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from calib.atomic_io import write_text_atomic
from calib.limits import MAX_PROTOCOL_TRIALS
from calib.plan.models import MAX_SEED, MAX_TRIALS
from planner.cli.common import count_arg, read_plan, stderr, stdout
from planner.errors import PlanRefused
from planner.program.controllers import CONTROLLERS, DEFAULT_CONTROLLER

#: Most worker processes a validation may start.
MAX_WORKERS = 64

if TYPE_CHECKING:
    from planner.reasons import Reason
    from planner.sim.report import FailureCount, ValidationReport


def protocol_arg(text: str) -> tuple[int, int]:
    """``"20x20"`` -> ``(20, 20)``: positions x repeats, each >= 2, at most
    :data:`calib.limits.MAX_PROTOCOL_TRIALS` trials together."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m or min(int(g[:12]) for g in m.groups()) < 2:
        raise argparse.ArgumentTypeError(
            f"must be POSITIONSxREPEATS with both >= 2, e.g. 20x20, got {text!r}"
        )
    big = max(len(g) for g in m.groups()) > 12  # int() of thousands of digits is refused
    positions, repeats = (int(g[:12]) for g in m.groups())
    if big or positions * repeats > MAX_PROTOCOL_TRIALS:
        total = "more than 10^12" if big else f"{positions * repeats:,}"
        raise argparse.ArgumentTypeError(
            f"{text.strip()} is {total} trials, at most "
            f"{MAX_PROTOCOL_TRIALS:,} (as --trials: every trial's result stays in memory until "
            "the report; the paper's protocol is 20x20)"
        )
    return positions, repeats


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``validate`` to the subparsers ``sub``."""
    p = add(
        sub,
        "validate",
        "simulate the calibration many times: confidence intervals, simulated and predicted",
        "Simulate the whole calibration TRIALS times: the measuring program the controller\n"
        "of --format runs for the plan (its searches from the safe starts, in the nominal\n"
        "frame or, where that controller's program updates its frame, adaptively), with the\n"
        "plan's sensor model\n"
        "(proximity or touch probe, against the real mesh where the part really lies), robot\n"
        "error model and part misplacement. Prints every row (origin x/y/z, rotations, the\n"
        "error at the points of interest and over the regions) at the plan's confidence\n"
        "levels: the simulated interval, the interval predicted from the procedure's\n"
        "linearisation with the same noise, and the bias, for the procedure and for the best\n"
        "fit of the same measurements; then how each point's searches went. A plan that\n"
        "cannot work (roles, free degrees of freedom, points off planar faces, searches too\n"
        "short for the misplacement) is refused before the run, naming the point. So is a\n"
        "plan `wobjcal check --format` refuses for the same program (poses, paths, moves,\n"
        "landing risk): every problem is named; --force simulates it anyway.\n\n"
        "exit codes: 0 every trial calibrated, 1 some trials failed (listed) or check refuses\n"
        "the plan, 2 bad input",
        "wobjcal validate assets/plans/stator_section_ah.json --trials 400 --seed 1\n"
        "wobjcal validate plan.json --json report.json --plots plots/\n"
        "wobjcal validate plan.json --format krl   # the program the KUKA export runs\n"
        "wobjcal validate plan.json --protocol 20x20 --sensitivity",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1)")
    p.add_argument(
        "--format",
        choices=list(CONTROLLERS),
        default=DEFAULT_CONTROLLER,
        help="the controller whose exported program is simulated (default: "
        f"{DEFAULT_CONTROLLER}); the report names the program",
    )
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
    p.add_argument(
        "--protocol",
        type=protocol_arg,
        metavar="PxR",
        help="also run the paper's protocol beside the default: P part positions x R repeats, "
        "each position's errors centred on its mean (the paper: 20x20)",
    )
    p.add_argument(
        "--sensitivity",
        action="store_true",
        help="also print the sensitivity table: the rows with each noise term off in turn "
        "(runs the trials once more per term)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="simulate a plan `wobjcal check` refuses (the report names check's problems)",
    )
    p.add_argument(
        "--no-check",
        action="store_true",
        help="skip `wobjcal check` before the run (no verdict; with --reach-trials 0 no cell is "
        "opened), e.g. for a study of a plan known to fail",
    )
    p.add_argument("--json", metavar="FILE", help="also write the report as JSON to FILE")
    p.add_argument(
        "--plots",
        metavar="DIR",
        help="also write PNG plots to DIR: histograms, scatter, and error_map.png, a colour "
        "map of the simulated error over the part",
    )
    p.set_defaults(handler=cmd_validate)


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def check_budget(
    plan: Any, trials: int, protocol: tuple[int, int] | None, fmt: str, sensitivity: bool
) -> None:
    """Refuse a run whose results or ray casts exceed the budget (:mod:`planner.sim.budget`)
    before the check and the simulation start; with ``sensitivity`` its runs too."""
    from planner.sim.budget import check_run_size, run_size, sensitivity_runs

    check_run_size(run_size(plan, trials, protocol, fmt))
    if sensitivity:
        size = run_size(plan, trials, None, fmt, runs=sensitivity_runs(plan))
        check_run_size(size, "--sensitivity")


def _counted(failed: dict[Reason, int]) -> list[dict[str, Any]]:
    """A search's failures, one object each: ``{"kind", "text", "pair"?, "count"}``, by text."""
    rows = [cause.to_json() | {"count": n} for cause, n in failed.items()]
    return sorted(rows, key=lambda r: (r["text"], r["kind"]))


def _failure_json(f: FailureCount) -> dict[str, Any]:
    """One line of the failures: ``{"label", "run", "count", "search", "kind", "text",
    "pair"?}``; ``search`` and ``kind`` ``null`` when no search failed (the measurements
    define no frame: the text is the label)."""
    head: dict[str, Any] = {"label": f.label, "run": f.run, "count": f.count}
    if f.failed is None:
        return head | {"search": None, "kind": None, "text": f.label}
    return head | {"search": f.failed.search} | f.failed.cause.to_json()


def report_json(report: ValidationReport) -> dict[str, Any]:
    """The JSON of a ``ValidationReport``: rows (display units), outcomes, failures, landings.

    Besides the words (``failed`` of each search, ``failures``: text -> count), every failure
    is listed with its kind (``reach``, ``joint_limit``, ``singularity``, ``collision`` with
    its ``pair``, ``search``: :mod:`planner.reasons`): ``failed_reasons`` of each search and
    ``failure_reasons`` of the trials.
    """
    from planner.sim.report import failed_by_words, reach_warning

    return {
        "program": {"name": report.program, "steps": list(report.program_steps)},
        "check_problems": list(report.check_problems),
        "method": report.method,
        "sensor": report.sensor,
        "n_trials": report.n_trials,
        "n_ok": report.n_ok,
        "reach_checked": report.reach_checked,
        "reach_failed": report.reach_failed,
        "reach_warning": reach_warning(report),
        "elapsed_s": report.elapsed_s,
        "protocol": report.protocol,
        "noise_m": {k: _num(v) for k, v in report.noise.items()},
        "rows": [
            {
                "key": r.key,
                "label": r.label,
                "unit": r.unit,
                "level_percent": r.level_percent,
                "procedure": _num(r.procedure),
                "procedure_predicted": _num(r.procedure_predicted),
                "procedure_bias": _num(r.procedure_bias),
                "procedure_protocol": _num(r.procedure_protocol),
                "best_fit": _num(r.best_fit),
                "best_fit_predicted": _num(r.best_fit_predicted),
                "best_fit_bias": _num(r.best_fit_bias),
                "best_fit_protocol": _num(r.best_fit_protocol),
                "paper": _num(r.paper),
            }
            for r in report.rows
        ],
        "outcomes": [
            {
                "search": o.point_id,
                "runs": o.searches,
                "failed": failed_by_words(o.failed),
                "failed_reasons": _counted(o.failed),
                "landed_off": o.landed_off,
                "partly_off": o.partly_off,
                "off_fraction_mean": o.off_fraction_mean,
                "off_fraction_max": o.off_fraction_max,
            }
            for o in report.outcomes
        ],
        "failures": report.failures,
        "failure_reasons": [_failure_json(f) for f in report.failure_counts],
        "landings": report.landings,
    }


def _bar() -> Progress:
    return Progress(
        TextColumn("validating"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=stderr(),
        transient=True,
    )


def cmd_validate(args: argparse.Namespace) -> int:
    """Run the validation with a progress bar and print the report."""
    from planner.validate.job import check_simulatable, sensitivity_plan, validate_plan

    plan, plan_dir = read_plan(args.plan, "validate")
    check_simulatable(plan)  # a clear error before the simulation's heavy imports
    trials = plan.validation.trials if args.trials is None else args.trials
    seed = plan.validation.seed if args.seed is None else args.seed
    check_budget(plan, trials, args.protocol, args.format, args.sensitivity)
    try:
        with _bar() as bar:
            task = bar.add_task("trials", total=trials)
            report = validate_plan(
                plan,
                trials=trials,
                seed=seed,
                workers=args.workers,
                progress=lambda done, total: bar.update(task, completed=done, total=total),
                reach_trials=min(args.reach_trials, trials),
                plan_dir=plan_dir,
                protocol=args.protocol,
                fmt=args.format,
                check="off" if args.no_check else "report" if args.force else "refuse",
            )
    except PlanRefused as exc:
        err = stderr()
        err.print(f"error: check refuses this plan for the program {exc.program}:", markup=False)
        for line in exc.problems:
            err.print(f"error: {line}", markup=False)
        err.print("nothing simulated; fix the plan, or simulate it anyway with --force")
        return 1
    stdout().print(report.to_markdown(), markup=False)
    data = report_json(report) | {"plan": args.plan, "seed": seed}
    if args.sensitivity:
        with _bar() as bar:
            task = bar.add_task("sensitivity", total=trials)
            table = sensitivity_plan(
                plan,
                trials=trials,
                seed=seed,
                workers=args.workers,
                progress=lambda done, total: bar.update(task, completed=done, total=total),
                plan_dir=plan_dir,
                fmt=args.format,
            )
        stdout().print(table.to_markdown(), markup=False)
        data["sensitivity"] = {
            "terms": list(table.terms),
            "rows": [
                {"key": k, "level_percent": lv, "half_widths": [_num(v) for v in vals]}
                for k, _label, _unit, lv, vals in table.rows
            ],
            "dominant": table.dominant,
        }
    if args.json:
        write_text_atomic(args.json, json.dumps(data, indent=2, sort_keys=True) + "\n")
    if args.plots:
        from planner.sim.plots import save_validation_plots

        written = save_validation_plots(report, Path(args.plots))
        stderr().print(f"plots: {', '.join(str(p) for p in written)}")
    return 0 if report.n_ok == report.n_trials else 1
