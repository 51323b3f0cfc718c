"""The measuring program: the ordered steps a robot controller executes for a plan.

A :class:`MeasuringProgram` is what one controller runs for one plan: for every point the joint
moves into it (through its vias, to its safe start), its searches (an approach; an edge point's
approach to the face it runs along, then the edge search from the measured face point), in the
order the program probes them, with the frame each search is commanded in; the estimate
updates an adaptive program computes between them; and how the frame is computed at the end
(on the controller, or afterwards by ``wobjcal calibrate`` from what the program recorded).

It is built by :func:`planner.program.build.measuring_program` and executed against any probe
(a simulation, or the ideal part of the prediction) by :func:`planner.program.execute.execute`.
The steps here describe the program for people (reports, ``--json``) and give the order the
checks walk; :mod:`planner.program.searches` gives the geometry of each search.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from calib.procedures import RolePoint
from planner.program.controllers import Controller
from planner.program.safety import SafetySpec

#: How a program commands its searches: all in the nominal work-object frame, or each in the
#: frame estimated from the points measured before it.
Steering = Literal["nominal", "adaptive"]

#: How a search step says the frame it is commanded in.
_FRAME = {"nominal": "in the nominal frame", "estimate": "in the frame estimated so far"}

#: Suffix of the key of an edge point's approach to the face its edge search runs along.
FACE_APPROACH = "@face"


@dataclass(frozen=True)
class MoveStep:
    """Joint moves into a point: through its vias, in order, to its safe start (fine points).

    Attributes:
        point_id: the plan's point id.
        n_vias: how many via points the move runs through.
    """

    point_id: str
    n_vias: int = 0

    def describe(self) -> str:
        """One line for people."""
        through = f" through {self.n_vias} via(s)" if self.n_vias else ""
        return f"joint move{through} to the safe start of {self.point_id}"


@dataclass(frozen=True)
class SearchStep:
    """One search of the program.

    Attributes:
        key: the measurement's key (the plan's point id; the procedure's key for a retake,
            e.g. ``"C2"``; ``"<id>@face"`` for an edge point's approach to its face).
        point_id: the plan's point id.
        kind: ``"approach"`` or ``"edge"``.
        frame: ``"nominal"``: commanded in the nominal work object; ``"estimate"``: in the
            frame the program estimated from the points measured before it.
        start: where the search starts: ``"safe start"``, ``"measured face point"`` (an edge
            search after its face approach) or ``"measured point"`` (an edge search that the
            procedure starts from an earlier measurement, e.g. A-H's
            ``edge_start_from_measured``).
        recorded: the program records the result for the frame (a face approach is not).
    """

    key: str
    point_id: str
    kind: str
    frame: Literal["nominal", "estimate"]
    start: str
    recorded: bool = True

    def describe(self) -> str:
        """One line for people."""
        what = "approach to the face" if self.key.endswith(FACE_APPROACH) else f"{self.kind} search"
        rec = ", recorded" if self.recorded else ""
        return f"{self.key}: {what} from the {self.start}, {_FRAME[self.frame]}{rec}"


@dataclass(frozen=True)
class UpdateStep:
    """The program updates its estimate of the work-object frame.

    Attributes:
        after: the keys measured since the previous update.
        uses: the point ids whose last measurements the update fits, in program order, when
            the program computes it itself (:mod:`planner.program.steering`: the smallest
            motion that puts them on their faces); ``()``: the procedure's own update (the
            A-H steps), run by the procedure.
    """

    after: tuple[str, ...]
    uses: tuple[str, ...] = ()

    def describe(self) -> str:
        """One line for people."""
        if self.uses:
            whose = "its face" if len(self.uses) == 1 else "their faces"
            return (
                f"frame estimate updated: the smallest motion that puts "
                f"{', '.join(self.uses)} on {whose}"
            )
        return f"frame estimate updated (after {', '.join(self.after)})"


@dataclass(frozen=True)
class FrameStep:
    """How the final frame is computed.

    Attributes:
        on_controller: the program computes it (an adaptive program's last estimate); else
            ``wobjcal calibrate`` computes it from the recorded points.
        method_label: the procedure, e.g. ``"best fit"``.
    """

    on_controller: bool
    method_label: str

    def describe(self) -> str:
        """One line for people."""
        if self.on_controller:
            return f"the {self.method_label} frame, computed on the controller"
        return (
            f"the {self.method_label} frame, computed from the recorded points by "
            "`wobjcal calibrate`"
        )


Step = MoveStep | SearchStep | UpdateStep | FrameStep


@dataclass(frozen=True)
class MeasuringProgram:
    """The program one controller runs for one plan.

    Attributes:
        controller: the controller (its language and what it computes).
        method: the procedure's registry name (``procedure.method``).
        method_label: its short name for people, e.g. ``"A-H"``.
        steering: ``"adaptive"`` or ``"nominal"`` (see :data:`Steering`).
        steps: the steps, in the order the controller executes them.
        safety: the misplacement tolerance the safe starts are computed for.
        points: the plan's points with their roles (wobj frame): what each search is
            commanded from.
        settings: the procedure's settings struct the program was built with (the frame is
            computed with them).
        note: why a procedure that steers its searches runs nominal on this controller
            (``""`` otherwise).
        pivot_m: ``(3,)`` the centroid of the layout the program's own updates turn about,
            wobj frame, m (``None`` without such updates).
        scale_m: the layout's RMS size those updates scale rotations by, m.
    """

    controller: Controller
    method: str
    method_label: str
    steering: Steering
    steps: tuple[Step, ...]
    safety: SafetySpec
    points: tuple[RolePoint, ...]
    settings: Any
    note: str = ""
    pivot_m: tuple[float, float, float] | None = None
    scale_m: float = 0.0

    @property
    def name(self) -> str:
        """What a user reads, e.g. ``"RAPID, adaptive A-H"``, ``"KRL, nominal best fit"``."""
        return f"{self.controller.label}, {self.steering} {self.method_label}"

    @property
    def adaptive(self) -> bool:
        """True when the program updates its frame between searches."""
        return self.steering == "adaptive"

    @property
    def updates(self) -> tuple[UpdateStep, ...]:
        """The update steps, in order."""
        return tuple(s for s in self.steps if isinstance(s, UpdateStep))

    @property
    def steers_itself(self) -> bool:
        """The program's own frame updates (:mod:`planner.program.steering`) steer its
        searches, rather than the procedure's steps."""
        return any(u.uses for u in self.updates)

    @property
    def xoffset_run(self) -> Any:
        """The paper's x-offset run (:class:`calib.paper.settings.XOffsetRun`) the program runs
        after its frame is computed, or ``None``: only an adaptive program of a procedure whose
        settings hold one runs it (the exporters write it from the calibrated frame)."""
        return getattr(self.settings, "xoffset", None) if self.adaptive else None

    @property
    def searches(self) -> tuple[SearchStep, ...]:
        """The search steps, in order."""
        return tuple(s for s in self.steps if isinstance(s, SearchStep))

    @property
    def probe_order(self) -> tuple[str, ...]:
        """The point ids in the order the program moves to them (a point retaken appears
        again)."""
        return tuple(s.point_id for s in self.steps if isinstance(s, MoveStep))

    def describe(self) -> list[str]:
        """The program for people: its name, then one line per step."""
        head = self.name + (f" ({self.note})" if self.note else "")
        return [head, *(f"{k}. {s.describe()}" for k, s in enumerate(self.steps, start=1))]

    def to_json(self) -> dict[str, object]:
        """The program as the reports' ``--json`` give it."""
        return {
            "name": self.name,
            "controller": self.controller.name,
            "method": self.method,
            "steering": self.steering,
            "note": self.note,
            "steps": [s.describe() for s in self.steps],
        }


def search_keys(points: Sequence[RolePoint]) -> dict[str, str]:
    """``{search key: plan id}``: the keys a program may give a point's searches.

    The plan id itself; a role held by exactly one point (the A-H procedure names its
    searches by role); either with ``"2"`` appended (its retakes ``"C2"``, ``"D2"``); and
    either with :data:`FACE_APPROACH` appended (an edge point's approach to its face).

    A plan id always names its own point, and a point's first search its own: the ids are
    taken first, then the roles, then the face approaches, then the retakes (``"T12"`` is
    point T12, never a retake of T1; ``"T12@face"`` is T12's face approach).
    """
    out: dict[str, str] = {}
    roles = [rp.role for rp in points]
    names = [
        (rp.point.id, [rp.point.id] + ([rp.role] if roles.count(rp.role) == 1 else []))
        for rp in points
    ]
    for suffix in ("", FACE_APPROACH, "2", "2" + FACE_APPROACH):  # first takes before retakes
        for k in (0, 1):  # the ids, then the roles
            for pid, own in names:
                if k < len(own):
                    out.setdefault(f"{own[k]}{suffix}", pid)
    return out


def vias_of(points: Mapping[str, int] | None, point_id: str) -> int:
    """How many vias ``point_id`` has in ``points`` (``{id: n}``; 0 when not listed)."""
    return 0 if points is None else int(points.get(point_id, 0))
