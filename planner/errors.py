"""Errors raised by ``planner``: subclasses of the ``calib`` errors that name files and fields."""

from __future__ import annotations

from calib.errors import InputError, WobjcalError


class URDFError(InputError):
    """A URDF file is missing, malformed, or lacks what wobjcal needs (named in the message)."""


class MeshError(InputError):
    """A mesh file is missing, unreadable, empty, or has unusable geometry."""


class UnknownFrameError(InputError):
    """A frame, link, joint or TCP name is not known; the message lists the valid names."""


class UnknownBuiltinError(InputError):
    """A ``builtin:`` robot, tool or part name is not known; the message lists the valid ones."""


class ToolMountError(InputError):
    """The tool cannot be mounted on the robot's flange as given; the message names the plan
    field that sets the mount (``cell.tool.T_flange_tool``)."""


class UnreachableError(WobjcalError):
    """A target cannot be reached by the robot; the message says why."""


class PlanRefused(WobjcalError):
    """``wobjcal check`` refuses the plan for the program a job would run, so the job stops
    before it starts (``validate`` without ``--force``).

    Attributes:
        program: the measuring program's name, e.g. ``"RAPID, adaptive best fit"``.
        problems: every problem check names, one line each (``"point T1: ..."``).
    """

    def __init__(self, program: str, problems: tuple[str, ...]) -> None:
        self.program = program
        self.problems = problems
        super().__init__(
            f"check refuses this plan for the program {program}: " + "; ".join(problems)
        )
