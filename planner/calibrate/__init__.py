"""Calibrate a work object from measured points, with gross-error screening.

Owns the job (:mod:`.job`: :func:`calibrate_plan` and the screens a result passes before anyone
pastes it into a robot). Pure numpy and :mod:`calib`: no simulator, no cell.
"""

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from planner.calibrate.job import calibrate_plan

__all__ = ["calibrate_plan"]


def __getattr__(name: str) -> Any:
    """The job's names, imported on first use."""
    if name in __all__:
        from planner.calibrate import job

        return getattr(job, name)
    raise AttributeError(f"module 'planner.calibrate' has no attribute {name!r}")
