"""Suggest a probe layout: ``wobjcal suggest``, the web UI's "Suggest" and scripts.

Owns: the job (:mod:`.job`: :func:`suggest_plan`, its result and errors, :func:`moved_plan`),
the designs (:mod:`.steps`: candidates' feasibility, best fit grown to the target, 3-2-1),
the measuring order a design lands in (:mod:`.order`), the order that shortens the cycle
(:mod:`.time_order`) and the accuracy-versus-time front (:mod:`.front`).
"""

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from planner.suggest.job import (
        PROCEDURES,
        SuggestError,
        SuggestResult,
        as_best_fit,
        moved_plan,
        suggest_plan,
    )

__all__ = [
    "PROCEDURES",
    "SuggestError",
    "SuggestResult",
    "as_best_fit",
    "moved_plan",
    "suggest_plan",
]


def __getattr__(name: str) -> Any:
    """The job's names, imported on first use (``--front``'s argument check and the CLI's help
    do not load the cell and the design)."""
    if name in __all__:
        from planner.suggest import job

        return getattr(job, name)
    raise AttributeError(f"module 'planner.suggest' has no attribute {name!r}")
