"""``wobjcal sweep``: where to put the robot and the part, over many sampled placements.

This package owns the sweep job: the placements and how they move the cell (:mod:`.space`),
the check of one placement on a worker (:mod:`.task`), the CSV and its sidecar that make a
sweep resumable (:mod:`.files`), the plot (:mod:`.plot`), and the job that runs them on Dask
``distributed`` or in this process (:mod:`.job`, :func:`run_sweep`). ``docs/sweep.md`` says
how to run it on a cluster and what it costs.
"""

from typing import Any

__all__ = ["run_sweep"]


def __getattr__(name: str) -> Any:
    """:func:`run_sweep` on first use: the job imports the check (PyBullet), which
    ``wobjcal --help`` and the flag parsing of ``planner.cli.sweep`` do not need."""
    if name == "run_sweep":
        from planner.sweep.job import run_sweep

        return run_sweep
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
