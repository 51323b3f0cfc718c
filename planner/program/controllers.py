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

import math
from dataclasses import dataclass

from calib.registry import lookup


@dataclass(frozen=True)
class JointMoveSpeed:
    """How fast a controller's program commands its joint moves (to the safe starts and
    through the vias): the one place the exporters write them from and the cycle-time model
    (:mod:`planner.program.cycle_time`) times them with.

    Attributes:
        velocity_fraction: of each joint's velocity limit (FANUC ``J ... 20%``: 0.2).
        velocity_rad_s: a cap on every joint's velocity, rad/s (URScript ``movej`` ``v``:
            the leading axis), ``None``: none.
        acceleration_rad_s2: every joint's acceleration, rad/s^2 (URScript ``movej`` ``a``),
            ``None``: the plan's ``validation.cycle.joint_acceleration_rad_s2``.
        tcp_speed_m_s: a cap on the TCP's speed along its path, m/s (RAPID ``MoveJ`` with
            ``vApproach``: its ``v_tcp``), ``None``: none.
        tool_speed_rad_s: a cap on the tool's reorientation speed, rad/s (RAPID's ``v_ori``),
            ``None``: none.
        how: the command, for program headers and the docs.
    """

    velocity_fraction: float = 1.0
    velocity_rad_s: float | None = None
    acceleration_rad_s2: float | None = None
    tcp_speed_m_s: float | None = None
    tool_speed_rad_s: float | None = None
    how: str = ""


#: RAPID ``MoveJ``/``MoveAbsJ`` with ``vApproach := [100, 50, 5000, 1000]``: TCP 100 mm/s, tool
#: 50 deg/s (``v_tcp``, ``v_ori``; the joints at their limits otherwise).
RAPID_JOINT_MOVE = JointMoveSpeed(
    tcp_speed_m_s=0.1,
    tool_speed_rad_s=math.radians(50.0),
    how="MoveJ vApproach: TCP 100 mm/s, tool 50 deg/s",
)
#: KRL ``PTP`` after ``BAS(#INITMOV,0)``: ``$VEL_AXIS`` and ``$ACC_AXIS`` at KSS's default 100 %.
KRL_JOINT_MOVE = JointMoveSpeed(how="PTP at $VEL_AXIS 100 % (BAS #INITMOV)")
#: URScript ``movej(q, a=1.4, v=1.05)``: leading axis 1.05 rad/s, 1.4 rad/s^2.
URSCRIPT_JOINT_MOVE = JointMoveSpeed(
    velocity_rad_s=1.05, acceleration_rad_s2=1.4, how="movej a=1.4 rad/s^2, v=1.05 rad/s"
)
#: FANUC ``J P[n] 20% FINE``: 20 % of each joint's speed.
FANUC_JOINT_MOVE = JointMoveSpeed(velocity_fraction=0.2, how="J 20% FINE")


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
        joint_move: how fast its program commands the joint moves.
    """

    name: str
    label: str
    vendor: str
    adaptive_methods: frozenset[str] = frozenset()
    why_nominal: str = "the exporter writes no frame update for this procedure"
    joint_move: JointMoveSpeed = JointMoveSpeed()


#: The controllers by name, in the order the UI offers them.
CONTROLLERS: dict[str, Controller] = {
    c.name: c
    for c in (
        Controller(
            "rapid",
            "RAPID",
            "ABB",
            frozenset({"hultman2013", "best_fit", "three_two_one"}),
            joint_move=RAPID_JOINT_MOVE,
        ),
        Controller(
            "krl",
            "KRL",
            "KUKA",
            frozenset({"hultman2013", "best_fit", "three_two_one"}),
            joint_move=KRL_JOINT_MOVE,
        ),
        Controller(
            "urscript",
            "URScript",
            "Universal Robots",
            adaptive_methods=frozenset({"hultman2013", "best_fit", "three_two_one"}),
            joint_move=URSCRIPT_JOINT_MOVE,
        ),
        Controller(
            "fanuc",
            "TP",
            "FANUC",
            joint_move=FANUC_JOINT_MOVE,
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
    return lookup(CONTROLLERS, key, "controller (--format)")
