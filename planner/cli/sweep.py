"""``wobjcal sweep``: the plan's check over many placements of the robot base and the part.

Parses the flags (every one checked with one clear error, exit 2) and calls
:func:`planner.sweep.run_sweep` with a progress bar on stderr.
"""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable
from typing import Any

from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from calib.errors import InputError
from calib.limits import (
    MAX_SWEEP_SAMPLES,
    MAX_SWEEP_WORKER_MIB,
    MAX_SWEEP_WORKERS,
    MIN_SWEEP_WORKER_MIB,
    SWEEP_WORKER_MEMORY_BYTES,
)
from planner.cli.common import count_arg, stderr, stdout
from planner.program.controllers import CONTROLLERS, DEFAULT_CONTROLLER
from planner.sweep.space import AXES, DEFAULT_HALF, SweepSpace, flag_of, parse_range

#: ``tcp://host:port``, ``tls://host:port`` or ``host:port``.
_ADDRESS = re.compile(r"^((tcp|tls)://)?[A-Za-z0-9_.\-\[\]:]+:\d{1,5}$")
DEFAULT_WORKERS = 2


def _range_arg(axis: str) -> Callable[[str], tuple[float, float]]:
    def parse(text: str) -> tuple[float, float]:
        try:
            return parse_range(text, axis)
        except InputError as exc:
            raise argparse.ArgumentTypeError(str(exc).split(": ", 1)[1]) from None

    return parse


def _address(text: str) -> str:
    if not _ADDRESS.match(text):
        raise argparse.ArgumentTypeError(
            f"expected a scheduler address such as tcp://host:8786, got {text!r}"
        )
    return text


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``sweep`` to the subparsers ``sub``."""
    p = add(
        sub,
        "sweep",
        "check the plan over many placements of the robot base and the part",
        "Draw --samples placements of the robot base and of the part (the work object with the\n"
        "cell's fixtures) around the plan's own poses and run the plan's check in each:\n"
        "feasibility (points feasible of all, layout status), predicted accuracy (the worst\n"
        "point-of-interest half width at the plan's highest confidence level, mm) and cycle\n"
        "time (s). Writes DIR/sweep.csv (a row per placement, appended as rows finish),\n"
        "DIR/sweep.json (the arguments) and DIR/sweep.png (base x/y coloured by status and\n"
        "accuracy).\n\n"
        "Offsets are from the plan's poses in the world frame, mm and deg: MIN:MAX, or H for\n"
        "-H:H (a negative MIN needs '=': --base-x=-300:100). Placement i is drawn from\n"
        "--seed and i alone, so a restart with the same arguments keeps the finished rows and\n"
        "runs the missing ones; other arguments in the same DIR are refused, named.\n\n"
        "Runs on Dask distributed: a local cluster of --workers processes (one thread,\n"
        f"{SWEEP_WORKER_MEMORY_BYTES >> 20} MiB each), or the workers of a running scheduler\n"
        "(--scheduler tcp://host:8786; wobjcal and the plan's files at the same path on every\n"
        "worker: docs/sweep.md). --workers 0 runs in this process.\n\n"
        "exit codes: 0 the sweep is complete (infeasible placements are results, not failures),\n"
        "2 bad input (plan, flag, a DIR of another sweep, an unreachable scheduler)",
        "wobjcal sweep assets/plans/plate_holes_321.json --samples 200 -o sweep_plate\n"
        "wobjcal sweep plan.json --samples 1000 -o out --base-x=-100:300 --part-yaw 0\n"
        "wobjcal sweep plan.json --samples 20000 -o out --scheduler tcp://10.0.0.5:8786",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1)")
    p.add_argument(
        "--samples",
        metavar="N",
        required=True,
        type=count_arg(1, MAX_SWEEP_SAMPLES),
        help=f"placements to check (1 to {MAX_SWEEP_SAMPLES:,})",
    )
    p.add_argument("-o", "--out", metavar="DIR", required=True, help="the sweep's folder")
    p.add_argument(
        "--workers",
        metavar="W",
        type=count_arg(0, MAX_SWEEP_WORKERS),
        default=None,
        help=f"worker processes of the local cluster (default {DEFAULT_WORKERS}; 0: in this "
        "process, no Dask)",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        type=_address,
        help="a running Dask scheduler (tcp://host:8786) instead of a local cluster",
    )
    p.add_argument(
        "--memory-limit",
        metavar="MIB",
        type=count_arg(MIN_SWEEP_WORKER_MIB, MAX_SWEEP_WORKER_MIB),
        default=None,
        help=f"memory limit of each local worker, MiB (default {SWEEP_WORKER_MEMORY_BYTES >> 20}; "
        "a worker is restarted at 95 %% of it: more memory, fewer restarts, docs/sweep.md)",
    )
    p.add_argument(
        "--seed",
        metavar="S",
        type=count_arg(0, 2**63 - 1),
        default=0,
        help="seed of the placements (default 0)",
    )
    p.add_argument(
        "--format",
        choices=list(CONTROLLERS),
        default=DEFAULT_CONTROLLER,
        help=f"the controller whose program is judged (default: {DEFAULT_CONTROLLER})",
    )
    for axis, unit in AXES:
        half = DEFAULT_HALF[axis]
        who, what = axis.split("_")[:2]
        what = "yaw about world z" if what == "dyaw" else f"{what[1:]} offset"
        p.add_argument(
            flag_of(axis),
            dest=axis,
            metavar="MIN:MAX",
            type=_range_arg(axis),
            default=(-half + 0.0, half),
            help=f"{'robot base' if who == 'base' else 'part'} {what}, {unit} "
            f"(default {-half:g}:{half:g})",
        )
    p.set_defaults(handler=cmd_sweep)


def _bar() -> Progress:
    return Progress(
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=stderr(),
        transient=True,
    )


def cmd_sweep(args: argparse.Namespace) -> int:
    """Run the sweep with a progress bar; print where the files are and a summary."""
    from planner.sweep import run_sweep  # Dask and PyBullet: not for ``wobjcal --help``

    if args.scheduler is not None and args.workers is not None:
        raise InputError(
            "--workers applies to the local cluster; with --scheduler the scheduler's workers "
            "run the sweep (give one of them)"
        )
    if args.scheduler is not None and args.memory_limit is not None:
        raise InputError(
            "--memory-limit applies to the local cluster; with --scheduler each worker's own "
            "--memory-limit holds (dask worker ... --memory-limit)"
        )
    workers = DEFAULT_WORKERS if args.workers is None else args.workers
    memory = SWEEP_WORKER_MEMORY_BYTES if args.memory_limit is None else args.memory_limit << 20
    space = SweepSpace({axis: getattr(args, axis) for axis, _ in AXES})
    with _bar() as bar:
        task = bar.add_task("placements", total=args.samples)
        result = run_sweep(
            args.plan,
            args.out,
            samples=args.samples,
            space=space,
            seed=args.seed,
            fmt=args.format,
            workers=workers,
            scheduler=args.scheduler,
            memory_limit_bytes=memory,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
        )
    stdout().print(
        f"{result.samples} placements ({result.kept} kept from before, {result.ran} checked): "
        f"{result.feasible} feasible, {result.errors} with an error; wrote {result.csv_path} "
        f"and {result.plot_path}",
        markup=False,
    )
    return 0
