"""Statuses of probe points without their exact poses: the reachability heat map's question.

A heat map asks of each sample "can it be probed, and if not, why?", not "with which pose
and how near". :func:`probe_statuses` answers that with the same statuses as
:func:`planner.cell.probe.check_probes` (same arguments, same candidates and rule), but
stops early where the rule's exact answer is not needed:

- a point with a passing candidate is decided as by :func:`check_probes`: the first passing
  candidate in the rule's order (least joint motion), already the first one found;
- a point without one is ``marginal`` when its least-bad candidate does not collide, else
  ``infeasible``; instead of finding that candidate (the largest exact slack, which for a
  pose deep in a mesh takes several full Bullet queries), the candidates are tried highest
  upper bound first until one shows a slack at least the tie above 0 (``marginal``), or all
  are shown to collide (``infeasible``), each stopping at its first part shown below 0
  (:meth:`planner.cell.probe.probe_choice.ProbeSearch._status`).

Pruning applies here and not in :func:`check_probes`: the rule there picks the least joint
motion over every rotation and the least-bad pose by its exact slack, and a click, ``wobjcal
check`` and the recorded outputs report that pose and its clearance.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planner.cell.probe.feasibility import Status, feasibility_of, prepare_candidates
from planner.cell.probe.probe_choice import ProbeSearch
from planner.cell.probe.probe_rule import Verdict
from planner.reasons import Reason

if TYPE_CHECKING:
    from planner.cell.scene import CellScene

#: The reason of a point whose every candidate collides, found without its least-bad pose
#: (so without the pair that limits it): a ``collision``.
EVERY_POSE_HITS = "every checked pose hits an obstacle or is too near one"
#: The reason of a marginal point found without its least-bad pose; its kind is what kept the
#: candidate that settled it from passing (:attr:`planner.cell.probe.probe_rule.Verdict.kind`).
NO_POSE_WITH_MARGIN = "no pose keeps the full clearance and joint margin; one does not collide"


@dataclass(frozen=True)
class ProbeStatuses:
    """Statuses of ``N`` probe points.

    Attributes:
        statuses: per point ``"feasible"``, ``"marginal"`` or ``"infeasible"``, those of
            :func:`planner.cell.probe.check_probes` with the same arguments.
        causes: per point, :func:`check_probes`'s cause where its pose was found (feasible
            points, points without any IK candidate within limits, and the rest where the
            shortcut could not decide); else :data:`EVERY_POSE_HITS` or
            :data:`NO_POSE_WITH_MARGIN`; ``None`` for a feasible point.
        exact: ``(N,)`` True where ``causes[i]`` is :func:`check_probes`'s own.
    """

    statuses: tuple[Status, ...]
    causes: tuple[Reason | None, ...]
    exact: NDArray[np.bool_]

    @property
    def reasons(self) -> tuple[str, ...]:
        """The words of :attr:`causes` (``""`` for none)."""
        return tuple("" if c is None else str(c) for c in self.causes)


def probe_statuses(
    cell: CellScene,
    points_wobj: ArrayLike,
    normals_wobj: ArrayLike,
    tcp: str = "sensor",
    rotation_step_deg: float = 15.0,
    margin_m: float | None = None,
    q_ref: ArrayLike | None = None,
    max_checks: int = 48,
) -> ProbeStatuses:
    """The statuses of ``N`` probe points (see the module docstring).

    Args: as :func:`planner.cell.probe.check_probes` (without ``staged``).

    Raises:
        As :func:`planner.cell.probe.check_probes`.
    """
    prep = prepare_candidates(
        cell, points_wobj, normals_wobj, tcp, rotation_step_deg, margin_m, q_ref, max_checks
    )
    if prep is None:
        return ProbeStatuses((), (), np.zeros(0, dtype=bool))
    cands, margin, max_checks = prep
    with cell.saved_state():
        decisions = ProbeSearch(cell, margin, max_checks, statuses_only=True).run(cands)
    statuses: list[Status] = []
    causes: list[Reason | None] = []
    exact = np.ones(len(decisions), dtype=bool)
    for i, (d, why) in enumerate(zip(decisions, cands.reasons)):
        if d is None:
            statuses.append("infeasible")
            causes.append(why)
        elif isinstance(d, Verdict):
            statuses.append(d.status)
            text = EVERY_POSE_HITS if d.status == "infeasible" else NO_POSE_WITH_MARGIN
            causes.append(Reason(d.kind, text))
            exact[i] = False
        else:
            res = feasibility_of(cell.chain, cands, i, d, margin)
            statuses.append(res.status)
            causes.append(res.cause)
    return ProbeStatuses(tuple(statuses), tuple(causes), exact)
