"""Suggest a probe layout: ``wobjcal suggest``, the web UI's "Suggest" and scripts.

Owns: the job (:mod:`.job`: :func:`suggest_plan`, its result and errors, :func:`moved_plan`),
the designs (:mod:`.steps`: candidates' feasibility, best fit grown to the target, 3-2-1),
the measuring order a design lands in (:mod:`.order`), the order that shortens the cycle
(:mod:`.time_order`) and the accuracy-versus-time front (:mod:`.front`).
"""

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
