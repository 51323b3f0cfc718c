"""The robot controllers a measuring program is made for, and what each language can compute.

A controller's program either runs every search in the nominal work-object frame (the frame is
computed afterwards, by ``wobjcal calibrate``, from the recorded points) or runs the plan's
procedure *adaptively*: it updates its work-object frame from the points measured so far and
commands the later searches in that estimate, as the procedure does step by step. Which
procedures a controller runs adaptively is a fact about its exporter (what its language can
compute and what the writer emits), recorded here once: :data:`CONTROLLERS`. The export
formats (:data:`planner.export.FORMATS`), ``wobjcal validate --format`` and the program's name
all read it from here.
"""

from __future__ import annotations

from dataclasses import dataclass

from calib.errors import InputError


@dataclass(frozen=True)
class Controller:
    """A robot controller and its program language.

    Attributes:
        name: the name on the command line (``--format``), e.g. ``"rapid"``.
        label: the language's name for humans, e.g. ``"RAPID"``.
        vendor: the robot maker, e.g. ``"ABB"``.
        adaptive_methods: the procedures (``procedure.method``) whose frame update the exported
            program computes on the controller; every other procedure runs in the nominal
            frame.
        why_nominal: why the other procedures run in the nominal frame (shown with the
            program's name).
    """

    name: str
    label: str
    vendor: str
    adaptive_methods: frozenset[str] = frozenset()
    why_nominal: str = "the exporter writes no frame update for this procedure"


#: The controllers by name, in the order the UI offers them.
CONTROLLERS: dict[str, Controller] = {
    c.name: c
    for c in (
        Controller(
            "rapid", "RAPID", "ABB", frozenset({"hultman2013", "best_fit", "three_two_one"})
        ),
        Controller("krl", "KRL", "KUKA", frozenset({"hultman2013", "best_fit", "three_two_one"})),
        Controller(
            "urscript",
            "URScript",
            "Universal Robots",
            adaptive_methods=frozenset({"hultman2013", "best_fit", "three_two_one"}),
        ),
        Controller(
            "fanuc",
            "TP",
            "FANUC",
            why_nominal=(
                "the TP writer computes no frame update: writing an updated frame's W, P, R "
                "needs ATAN2 (FANUC's math-function option, not standard TP register "
                "arithmetic) and the update's constants need more registers than a standard "
                "R[] set; the frame comes from wobjcal calibrate"
            ),
        ),
    )
}
#: The controller whose program ``wobjcal validate`` and ``wobjcal check`` judge by default: ABB
#: RAPID, the paper's controller (an IRB 4400), which runs A-H, 3-2-1 and best fit adaptively.
DEFAULT_CONTROLLER = "rapid"


def controller(name: str | None) -> Controller:
    """The controller named ``name`` (``None``: :data:`DEFAULT_CONTROLLER`).

    Raises:
        InputError: no such controller (the message lists the known ones).
    """
    key = DEFAULT_CONTROLLER if name is None else name
    if key not in CONTROLLERS:
        raise InputError(f"format must be one of {list(CONTROLLERS)}, got {key!r}")
    return CONTROLLERS[key]
