"""Validate a plan: thousands of simulated calibrations of its measuring program.

Owns the job (:mod:`.job`: :func:`validate_plan`, :func:`sensitivity_plan`), which checks the
plan first (:mod:`planner.check`) and simulates with :mod:`planner.sim`.
"""

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from planner.validate.job import sensitivity_plan, validate_plan

__all__ = ["sensitivity_plan", "validate_plan"]


def __getattr__(name: str) -> Any:
    """The job's names, imported on first use."""
    if name in __all__:
        from planner.validate import job

        return getattr(job, name)
    raise AttributeError(f"module 'planner.validate' has no attribute {name!r}")
