"""Check a plan: the one verdict on what a plan's measuring program does in its cell.

``wobjcal check``, the web UI, and every other job that must judge the program the robot will
run (validate first, suggest for every plan it writes, export for its targets, the sweep for
each placement) call it, so it sits below them.

Owns: the job (:mod:`.job`: :func:`check_plan`, :func:`check_points`, the layout and quality
verdicts), what it returns (:mod:`.results`), the program's search paths walked in the cell
(:mod:`.paths`), the cycle time of the checked program (:mod:`.cycle`), via points for colliding
moves (:mod:`.vias`), and what the prediction shares with the validation: whether a plan can be
simulated (:mod:`.simulatable`) and its simulation setups (:mod:`.simulation_setup`). The
procedure's dry run on the nominal part uses the one ideal probe, :mod:`calib.plane_probe`.
"""

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from planner.check.job import check_plan, check_points, layout_problem, plan_quality
    from planner.check.results import PlanCheck, PointCheck

__all__ = [
    "PlanCheck",
    "PointCheck",
    "check_plan",
    "check_points",
    "layout_problem",
    "plan_quality",
]


def __getattr__(name: str) -> Any:
    """The job's names, imported on first use (the package's modules load only what they need)."""
    if name in ("PlanCheck", "PointCheck"):
        from planner.check import results

        return getattr(results, name)
    if name in __all__:
        from planner.check import job

        return getattr(job, name)
    raise AttributeError(f"module 'planner.check' has no attribute {name!r}")
