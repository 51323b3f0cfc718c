"""Export a plan as robot programs: the checked export job the command line and the UI share.

Owns the job (:mod:`.job`: :func:`export_program`: check the plan, build the export job with the
checked targets and arm poses, format it with the writer of :mod:`planner.export`).
"""

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from planner.export_plan.job import export_program

__all__ = ["export_program"]


def __getattr__(name: str) -> Any:
    """The job's names, imported on first use."""
    if name in __all__:
        from planner.export_plan import job

        return getattr(job, name)
    raise AttributeError(f"module 'planner.export_plan' has no attribute {name!r}")
