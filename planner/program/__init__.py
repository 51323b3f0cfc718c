"""The measuring program: what a robot controller executes for a plan, below every job.

A plan plus a target controller gives exactly one program (``"RAPID, adaptive A-H"``,
``"KRL, nominal best fit"``): the joint moves into each point, its searches from the safe start
(an edge point's approach to its face first), the frame each search is commanded in, the
estimate updates of an adaptive program, and how the frame is computed. Export writes it, check
walks its searches and moves, validate executes it against the simulated sensor, the prediction
linearises that execution, calibrate estimates from what it records.

Owns:
    - :mod:`planner.program.controllers`: :data:`CONTROLLERS`, each language and the procedures
      it runs adaptively, and the default;
    - :mod:`planner.program.model`: :class:`MeasuringProgram` and its steps;
    - :mod:`planner.program.build`: :func:`measuring_program` (plan + controller -> program),
      the safety spec, the A-H specifics of an adaptive program, the probe orders;
    - :mod:`planner.program.execute`: :func:`execute` (a program against a probe) and
      :class:`ProgramProbe` (a procedure's search as the program runs it);
    - :mod:`planner.program.safety`: safe search starts under the plan's misplacement;
    - :mod:`planner.program.searches`: the searches a program runs for one point;
    - :mod:`planner.program.cycle_time`: how long the program takes (joint moves, searches,
      settle, I/O), from joint values and limits given to it.

Imports only :mod:`calib`: no simulator, no cell, no language.
"""

from planner.program.build import measuring_program
from planner.program.controllers import CONTROLLERS, DEFAULT_CONTROLLER, Controller, controller
from planner.program.execute import ProgramProbe, execute
from planner.program.model import MeasuringProgram

__all__ = [
    "CONTROLLERS",
    "DEFAULT_CONTROLLER",
    "Controller",
    "MeasuringProgram",
    "ProgramProbe",
    "controller",
    "execute",
    "measuring_program",
]
