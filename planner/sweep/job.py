"""``wobjcal sweep``: the plan's check over many placements of the robot base and the part.

:func:`run_sweep` draws the placements (:mod:`planner.sweep.space`), skips those already in
``DIR/sweep.csv`` (:mod:`planner.sweep.files`), checks the others
(:func:`planner.sweep.task.check_placement`) on Dask ``distributed`` (a local cluster of worker
processes, or a running scheduler by address) or in this process (``workers=0``), appends each
row as it finishes, and at the end rewrites the CSV in index order and draws ``sweep.png``
(:mod:`planner.sweep.plot`). The same arguments give the same rows whichever way they ran.
"""

from __future__ import annotations

import logging
import os
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from calib.errors import InputError, WobjcalError
from calib.limits import SWEEP_WORKER_MEMORY_BYTES
from calib.plan.file import PlanError, plan_digest, plan_from_json
from calib.plan.json_io import read_text_file
from planner.program.controllers import DEFAULT_CONTROLLER, controller
from planner.sweep.files import (
    COLUMNS,
    CSV_NAME,
    JSON_NAME,
    PNG_NAME,
    SweepMismatch,
    append_row,
    mismatches,
    read_rows,
    read_sidecar,
    row_cells,
    sidecar,
    write_rows,
    write_sidecar,
)
from planner.sweep.plot import plot_sweep
from planner.sweep.space import Placement, SweepSpace, placement
from planner.sweep.task import SweepRow, cached_plan, check_placement

if TYPE_CHECKING:
    from distributed import Client

#: What ``accuracy_mm`` is, written into ``sweep.json``.
ACCURACY_TEXT = (
    "worst point-of-interest half width at the plan's highest confidence level, mm "
    "(check's layout quality)"
)
#: The local cluster's memory policy: nothing to spill (a task's input is a few kilobytes and
#: its row a few hundred bytes), so no spilling and no pause; a worker whose memory reaches
#: 95 % of its limit is restarted by its nanny and its placement runs again (a worker grows by
#: ~45 MB a stator placement: each check's new PyBullet client keeps the part's mesh arrays,
#: docs/sweep.md). A placement may meet a restart a few times before it counts as failed.
WORKER_MEMORY_POLICY: dict[str, object] = {
    "distributed.worker.memory.target": False,
    "distributed.worker.memory.spill": False,
    "distributed.worker.memory.pause": False,
    "distributed.worker.memory.terminate": 0.95,
    "distributed.scheduler.allowed-failures": 10,
}
#: Tasks in flight per worker thread: enough to keep workers busy, few enough that a stop
#: leaves little computed and unwritten.
_IN_FLIGHT_PER_THREAD = 2


class SweepStopped(WobjcalError):
    """The cluster could not finish a placement (its workers died too often, the scheduler
    went away); the rows finished so far are in ``sweep.csv``."""


@dataclass(frozen=True)
class SweepResult:
    """What a sweep did.

    Attributes:
        csv_path: ``DIR/sweep.csv``.
        plot_path: ``DIR/sweep.png``.
        samples: placements in the sweep.
        kept: rows found finished in ``sweep.csv`` and kept (a resume).
        ran: placements checked in this run.
        feasible: placements whose status is ``feasible``, of all ``samples``.
        errors: placements whose check raised (status ``error``).
    """

    csv_path: Path
    plot_path: Path
    samples: int
    kept: int
    ran: int
    feasible: int
    errors: int


def _prepare(out_dir: Path, expected: dict[str, Any]) -> dict[int, list[str]]:
    """The finished rows of ``out_dir``'s sweep (none for a new one), after checking that it was
    written with the same arguments; writes ``sweep.json`` and a clean ``sweep.csv``.

    Raises:
        SweepMismatch: the sweep in ``out_dir`` was written with other arguments.
        InputError: ``out_dir`` is a file, or ``sweep.csv`` is there without ``sweep.json``.
    """
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"-o {out_dir}: exists and is not a folder")
    out_dir.mkdir(parents=True, exist_ok=True)
    csv_path, json_path = out_dir / CSV_NAME, out_dir / JSON_NAME
    rows: dict[int, list[str]] = {}
    if json_path.exists():
        old = read_sidecar(json_path)
        differ = mismatches(old, expected)
        if differ:
            raise SweepMismatch(
                f"{out_dir} holds a sweep written with other arguments: {'; '.join(differ)}; "
                "run with those, or choose another -o DIR"
            )
        if csv_path.exists():
            rows = {i: r for i, r in read_rows(csv_path).items() if i < expected["samples"]}
    elif csv_path.exists():
        raise InputError(
            f"{csv_path} exists without {JSON_NAME}: not resumable (its arguments are unknown); "
            "remove it or choose another -o DIR"
        )
    write_sidecar(json_path, expected)
    write_rows(csv_path, rows)  # drops a torn last line, restores index order
    return rows


@contextmanager
def _restored_level(logger: logging.Logger, level: int) -> Iterator[None]:
    try:
        yield
    finally:
        logger.setLevel(level)


@contextmanager
def _client(workers: int, scheduler: str | None, memory_limit_bytes: int) -> Iterator[Client]:
    """A Dask client: of a running scheduler at ``scheduler``, else of a local cluster of
    ``workers`` processes with one thread and ``memory_limit_bytes`` each."""
    import dask
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise InputError(f"--scheduler {scheduler}: cannot connect: {exc}") from None
        with client:
            yield client
        return
    quiet = logging.getLogger("distributed")
    level = quiet.level
    if not logging.getLogger().isEnabledFor(logging.DEBUG):  # wobjcal --debug shows them
        quiet.setLevel(logging.ERROR)  # a cluster's start and stop are not the user's news
    with (
        _restored_level(quiet, level),
        dask.config.set(WORKER_MEMORY_POLICY),
        LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            memory_limit=memory_limit_bytes,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",  # its HTTP server starts anyway: local, any port
            silence_logs=logging.ERROR,
        ) as cluster,
        Client(cluster) as client,
    ):
        yield client


def _run_distributed(
    client: Client,
    plan_text: str,
    plan_dir: str,
    fmt: str,
    todo: list[Placement],
    done: Callable[[SweepRow], None],
) -> None:
    """Check ``todo`` on ``client``'s workers, a bounded number in flight; ``done`` gets each
    row as it finishes (in any order)."""
    from distributed import as_completed
    from distributed.client import FutureCancelledError
    from distributed.scheduler import KilledWorker

    threads = max(1, sum(client.nthreads().values()))
    pending = iter(todo)
    run = uuid.uuid4().hex[:12]  # keys of this run: a shared scheduler may hold others'

    def submit(where: Placement) -> Any:
        key = f"wobjcal-sweep-{run}-{where.index}"
        # the text itself, not scattered: a worker restarted for its memory would take the
        # only copy of scattered data with it
        return client.submit(check_placement, plan_text, plan_dir, fmt, where, key=key)

    first = [submit(w) for _, w in zip(range(threads * _IN_FLIGHT_PER_THREAD), pending)]
    running = as_completed(first)
    for future in running:
        try:
            row: SweepRow = future.result()
        except (FutureCancelledError, KilledWorker) as exc:
            raise SweepStopped(
                f"the cluster lost placement {future.key.rsplit('-', 1)[1]} ({exc}); the "
                "finished rows are kept: run the same command again to resume"
            ) from None
        done(row)
        nxt = next(pending, None)
        if nxt is not None:
            running.add(submit(nxt))


def run_sweep(
    plan_path: str | Path,
    out_dir: str | Path,
    *,
    samples: int,
    space: SweepSpace | None = None,
    seed: int = 0,
    fmt: str | None = None,
    workers: int = 2,
    scheduler: str | None = None,
    memory_limit_bytes: int = SWEEP_WORKER_MEMORY_BYTES,
    progress: Callable[[int, int], None] | None = None,
) -> SweepResult:
    """Check the plan at ``plan_path`` in ``samples`` placements; write ``out_dir/sweep.csv``,
    ``sweep.json`` and ``sweep.png`` (see the module docstring).

    Args:
        plan_path: the plan file; its folder must be readable at the same path on every worker.
        out_dir: the sweep's folder (created; a sweep already there is resumed).
        samples: how many placements (indices ``0 .. samples - 1``).
        space: the ranges of the offsets (default :meth:`SweepSpace.default`), mm and deg.
        seed: the seed the placements derive from (with their index).
        fmt: the controller whose program is judged (``None``: the default, RAPID).
        workers: processes of the local cluster; ``0`` runs in this process without Dask.
            Ignored with ``scheduler``.
        scheduler: address of a running Dask scheduler (``tcp://host:8786``).
        memory_limit_bytes: memory limit of each local worker, bytes (restarted at 95 %).
        progress: called with ``(done, samples)`` as rows finish (kept rows count as done).

    Raises:
        PlanError: the plan is invalid or its files are missing.
        SweepMismatch: ``out_dir`` holds a sweep written with other arguments.
        InputError: a bad argument, or the scheduler cannot be reached.
    """
    fmt = fmt or DEFAULT_CONTROLLER
    controller(fmt)
    space = space or SweepSpace.default()
    plan_file = Path(plan_path)
    plan_text = read_text_file(plan_file, PlanError, "plan file")
    plan_dir = str(plan_file.resolve().parent)
    cached_plan(plan_text, plan_dir)  # a bad plan: one clear error before any worker starts
    digest = plan_digest(plan_from_json(plan_text, source=str(plan_file)))
    out = Path(out_dir)
    expected = sidecar(str(plan_path), digest, seed, fmt, space.to_json(), samples, ACCURACY_TEXT)
    rows = _prepare(out, expected)
    kept = len(rows)
    todo = [placement(space, seed, i) for i in range(samples) if i not in rows]
    csv_path = out / CSV_NAME
    if progress is not None:
        progress(kept, samples)
    fd = os.open(csv_path, os.O_WRONLY | os.O_APPEND)
    try:

        def done(row: SweepRow) -> None:
            cells = row_cells(row)
            append_row(fd, cells)
            rows[row.placement.index] = cells
            if progress is not None:
                progress(len(rows), samples)

        if not todo:
            pass
        elif workers == 0 and scheduler is None:
            for where in todo:
                done(check_placement(plan_text, plan_dir, fmt, where))
        else:
            with _client(workers, scheduler, memory_limit_bytes) as client:
                _run_distributed(client, plan_text, plan_dir, fmt, todo, done)
    finally:
        os.close(fd)
    write_rows(csv_path, rows)
    plot_path = plot_sweep([rows[i] for i in sorted(rows)], out / PNG_NAME, str(plan_path))
    status = [r[COLUMNS.index("status")] for r in rows.values()]
    return SweepResult(
        csv_path,
        plot_path,
        samples,
        kept,
        len(todo),
        status.count("feasible"),
        status.count("error"),
    )
