"""Suggest a probe layout: ``wobjcal suggest``, the web UI's "Suggest" and scripts.

Owns: the job (:mod:`.job`: :func:`suggest_plan`, its result and errors, :func:`moved_plan`),
the designs (:mod:`.steps`: candidates' feasibility, a layout grown to the target, one over
faces; which one a procedure takes is its registry entry's
:class:`~calib.procedures.base.LayoutDesign`),
the measuring order a design lands in (:mod:`.order`), the order that shortens the cycle
(:mod:`.time_order`) and the accuracy-versus-time front (:mod:`.front`).
"""

from typing import TYPE_CHECKING, Any

from calib.procedures import GROWN

#: The procedure suggest designs for unless told: the registry's first whose layout grows (the
#: best fit); the procedures it can design for are :data:`calib.procedures.DESIGNED`.
DEFAULT_PROCEDURE = GROWN[0]

if TYPE_CHECKING:
    from planner.suggest.job import (
        PROCEDURES,
        SuggestError,
        SuggestResult,
        as_procedure,
        grown_procedures,
        moved_plan,
        suggest_plan,
    )

__all__ = [
    "DEFAULT_PROCEDURE",
    "PROCEDURES",
    "SuggestError",
    "SuggestResult",
    "as_procedure",
    "grown_procedures",
    "moved_plan",
    "suggest_plan",
]


def __getattr__(name: str) -> Any:
    """The job's names, imported on first use (``--front``'s argument check and the CLI's help
    do not load the cell and the design)."""
    if name in __all__ and name != "DEFAULT_PROCEDURE":
        from planner.suggest import job

        return getattr(job, name)
    raise AttributeError(f"module 'planner.suggest' has no attribute {name!r}")
