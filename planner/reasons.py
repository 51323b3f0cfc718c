"""Why a probe pose, a search or a move fails: a :class:`Reason`, its kind named where it is found.

Every feasibility and search outcome carries a kind beside the English words users read:

==============  ==========================================================================
``reach``       out of reach, too close, no IK solution (:mod:`planner.robot.reach`)
``joint_limit`` a joint at (or, marginal, near) its limit
``singularity`` a singular wrist, or near a singularity
                (:mod:`planner.cell.probe.probe_candidates`)
``collision``   a robot or tool link hits, or comes too near, an obstacle: with its ``pair``
``footprint``   the point is not on a planar face with the sensor footprint on it
                (:mod:`planner.faces.checks`); a simulated search's footprint landed off its
                face or partly over a hole or an edge (:mod:`planner.sim.search_events`)
``move``        the joint move between points, through its vias
                (:mod:`planner.cell.moves.joint_moves`)
``search``      the search cannot reach its face or edge wherever the part may lie, or goes
                wrong too often under the misplacement (:mod:`planner.program.reach`,
                :mod:`planner.sim.landing`); a simulated search finds nothing within its
                length, starts inside the part or already detecting, or its sensor face runs
                into the part (:mod:`planner.sim.proximity`, :mod:`planner.sim.touch`)
==============  ==========================================================================

The code that decides an outcome gives it its kind; everything after it (``wobjcal check
--json``, the heat map's colours, suggest's counts of dropped candidates, the UI's status table,
``wobjcal validate``'s counts of failed searches and trials) reads ``kind`` and ``pair``, never
the words: ``tests/test_import_graph.py`` fails on a module that sorts a reason by searching
its text. A simulated search that the reachability hook refuses keeps the cell's kind and pair
(:func:`planner.sim.search_events.cell_search_hook`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Literal, get_args

ReasonKind = Literal[
    "reach", "joint_limit", "singularity", "collision", "footprint", "move", "search"
]  # fmt: skip
#: Every kind, in the order above.
KINDS: tuple[ReasonKind, ...] = get_args(ReasonKind)

__all__ = ["KINDS", "Reason", "ReasonKind", "joined"]


@dataclass(frozen=True)
class Reason:
    """Why something fails (or is only marginal), with its kind.

    Attributes:
        kind: what fails (a :data:`KINDS` value; see the module docstring).
        text: what users read, e.g. ``"out of reach (2.87 m from the shoulder, reach 1.92
            m)"`` or ``"link_4 hits table (clearance -3.0 mm)"``; not empty.
        pair: ``(robot or tool link, obstacle)`` of a collision (or of a collision along a
            search path or a move), ``None`` otherwise.
        about_part: the reason measures the work object (its distance from the robot or a
            point's from its surface): a part read in the wrong units shows here first, so
            ``wobjcal check`` adds the part's size to it (``note``).
        note: said after the text in parentheses (``"text (note)"``): the part's size and
            units that the check adds; ``""`` for none.
    """

    kind: ReasonKind
    text: str
    pair: tuple[str, str] | None = None
    about_part: bool = False
    note: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"unknown reason kind {self.kind!r}; known: {', '.join(KINDS)}")
        if not self.text:
            raise ValueError(f"a {self.kind} reason needs its words (text is empty)")
        if self.pair is not None and len(self.pair) != 2:
            raise ValueError(f"pair must be (link, obstacle), got {self.pair!r}")

    def __str__(self) -> str:
        """The words users see: the text, and the note in parentheses when there is one."""
        return f"{self.text} ({self.note})" if self.note else self.text

    def worded(self, prefix: str = "", suffix: str = "") -> Reason:
        """The same reason with words around its text (e.g. ``"search path: "``)."""
        return dataclasses.replace(self, text=f"{prefix}{self.text}{suffix}")

    def noted(self, note: str) -> Reason:
        """The same reason with ``note`` said after it."""
        return dataclasses.replace(self, note=note)

    def to_json(self) -> dict[str, Any]:
        """``{"kind", "text"}`` (the text as users see it, note included), and ``"pair"``
        when there is one."""
        out: dict[str, Any] = {"kind": self.kind, "text": str(self)}
        if self.pair is not None:
            out["pair"] = list(self.pair)
        return out


def joined(reasons: Iterable[Reason | None]) -> str:
    """The reasons' words joined with ``"; "`` (``None`` left out; ``""`` for none)."""
    return "; ".join(str(r) for r in reasons if r is not None)
