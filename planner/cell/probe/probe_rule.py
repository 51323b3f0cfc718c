"""The rule that picks a probe point's pose from its candidates, given their clearances.

The rule, shared by the exact check (:func:`planner.cell.probe.check_probes` with
``staged=False``: one whole clearance query per candidate, :func:`select`) and the fast path
(:mod:`planner.cell.probe.probe_choice`):

1. the candidates are taken in order (:class:`planner.cell.probe.probe_candidates.ProbeCandidates`),
   at most ``max_checks``; the first whose clearance passes (no collision, slack at least
   ``margin_m``) and whose joints are not near a limit is chosen: ``feasible``;
2. else the least-bad candidate: the largest slack, where slacks within
   :data:`CLEARANCE_TIE_M` of the largest are a tie won by the earliest candidate. It is
   ``marginal`` when it does not collide, else ``infeasible``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from planner.cell.scene import Clearance
from planner.reasons import ReasonKind

BoolArray = NDArray[np.bool_]

#: Clearances closer than this are a tie (Bullet's GJK answers vary by micrometres with the
#: scene's pose); among ties the earlier candidate (less joint motion) wins, m.
CLEARANCE_TIE_M = 1e-4


@dataclass(frozen=True)
class Decision:
    """The chosen (or least-bad) candidate of a point and its exact clearance.

    Attributes:
        candidate: index into the point's candidates.
        clearance: its clearance query's answer.
        chosen: True when it passed (``feasible``) or is the least-bad one without a
            collision (``marginal``); False: every candidate collides (``infeasible``).
    """

    candidate: int
    clearance: Clearance
    chosen: bool


@dataclass(frozen=True)
class Verdict:
    """The status of a point that the rule leaves to its least-bad candidate, found without
    finding that candidate (:class:`planner.cell.probe.probe_choice.ProbeSearch` with
    ``statuses_only``: the heat map's question is "can this point be probed, and if not,
    why", not "which pose and how near").

    Attributes:
        status: ``"marginal"`` (the least-bad candidate does not collide) or
            ``"infeasible"`` (every candidate collides).
        kind: what kept the candidate that settled it from passing: ``"collision"`` (it
            collides, or comes nearer than the margin) or ``"joint_limit"`` (a joint near its
            limit).
    """

    status: Literal["marginal", "infeasible"]
    kind: ReasonKind


def select(
    order: NDArray[np.int_],
    near_limit: BoolArray,
    margin_m: float,
    clearance: Callable[[int], Clearance],
) -> Decision:
    """The rule of the module docstring with exact clearances of every candidate (the plain
    reference: ``clearance(c)`` is one whole query per candidate)."""
    seen: list[tuple[int, Clearance]] = []
    for c in order.tolist():
        cl = clearance(c)
        if passes(cl, margin_m) and not near_limit[c]:
            return Decision(c, cl, True)
        seen.append((c, cl))
    return least_bad(seen)


def passes(cl: Clearance, margin_m: float) -> bool:
    """No collision and slack at least the margin."""
    return cl.ok and cl.slack_m >= margin_m


def least_bad(seen: list[tuple[int, Clearance]]) -> Decision:
    """The least-bad of exactly known candidates ``(candidate, clearance)`` in order."""
    top = max(cl.slack_m for _, cl in seen)
    c, cl = next((c, cl) for c, cl in seen if cl.slack_m >= top - CLEARANCE_TIE_M)
    return Decision(c, cl, cl.ok)
