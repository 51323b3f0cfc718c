"""Universal Robots URScript export: one program that probes every point and logs the points.

Conventions: metres and rotation vectors, poses ``p[x, y, z, rx, ry, rz]``. The work object is
the pose ``wobj`` (robot base frame); each target is written in the work-object frame and moved
to the base with ``pose_trans(wobj, target)``. Every search starts at the safe start of
:mod:`planner.program.safety` (reached with a joint move, ``movej`` of the pose); an edge point
first approaches its face and runs the edge search from the measured face point. A search runs
``movel`` to the end point in a thread while the main loop polls
``get_standard_digital_in(SENSOR_IN)`` every control cycle (:mod:`planner.export.urscript_probe`).

The program is the controller's :class:`~planner.program.model.MeasuringProgram`
(``job.program("urscript")``):

- **nominal**: every search once, in plan order, with ``wobj`` the nominal work object;
  ``meas_<ID>`` holds ``[code, x, y, z]`` of each point (code 0 measured, x, y, z in the base
  frame, m; 1 no detection on the path; 2 the input already at the searched level at the
  start), each result also written to the log with ``textmsg``; ``wobjcal calibrate``
  computes the frame;
- **adaptive**: the program's steps in its order, ``wobj`` updated between the searches where
  the program updates its estimate, so each search is commanded in the frame estimated so far,
  and at the end ``wobj`` is the calibrated work object: best fit and 3-2-1 by the frame
  update of :mod:`planner.export.urscript_steer`, the paper's A-H procedure (with its x-offset
  run when the plan has one) by :mod:`planner.export.urscript_adaptive`. The results are kept
  in ``measured`` (base frame, m, three per slot) and ``measured_code`` (as the code above, -1
  not run), one slot per point in plan order and then one per retake, and in ``meas_<ID>``
  (``meas2_<ID>``: the retake); a failed search stops the program (``halt``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from planner.export.job import ExportJob, safety_header
from planner.export.paste import PasteLines
from planner.export.text import identifier, literal_text
from planner.export.urscript_layout import preamble
from planner.export.urscript_probe import (
    LOG_MARK,
    SENSOR_IN,
    pose_text,
    probe_args,
    search_routines,
    target_comment,
    via_lines,
)

__all__ = ["SENSOR_IN", "export_urscript", "paste_lines", "pose_text", "urscript_files"]


def export_urscript(job: ExportJob) -> str:
    """The URScript program text of ``job``: the adaptive program when the controller's
    measuring program is adaptive, else the nominal one (module docstring)."""
    from planner.export.urscript_adaptive import export_adaptive
    from planner.export.urscript_steer import export_steered

    program = job.program("urscript")
    if not program.adaptive:  # the A-H specifics are for the controllers that run them
        job = replace(job, adaptive=None)
    if program.steers_itself:
        return export_steered(job, program)
    if program.adaptive and job.adaptive is not None:
        return export_adaptive(job, program)
    return _export_nominal(job)


def _export_nominal(job: ExportJob) -> str:
    """Every search once, in plan order, in the nominal ``wobj``; ``meas_<ID>``."""
    lines = [
        *preamble(
            job, safety_header(job, "urscript", "  # "), "nominal work object in the base frame"
        ),
        *search_routines(),
    ]
    for t in job.targets:
        lines += [
            target_comment(t),
            *via_lines(t, "  "),
            f'  {identifier("meas_" + t.point_id)} = probe("{literal_text(t.point_id)}", '
            f"{probe_args(t)})",
        ]
    lines += [f'  textmsg("{LOG_MARK} end")', "end", ""]
    return "\n".join(lines)


def urscript_files(job: ExportJob) -> dict[str, str]:
    """The URScript program of ``job`` as ``{".script": text}`` (the export registry's writer)."""
    return {".script": export_urscript(job)}


def paste_lines(T_base_wobj: np.ndarray) -> PasteLines:
    """The calibrated work object as a URScript pose in the robot base frame (the export
    registry's paste lines), as the programs hold their ``wobj``: metres and a rotation vector
    in radians; a target ``p`` in the work object is ``pose_trans(wobj_calibrated, p)``."""
    return PasteLines("robot base frame", (f"wobj_calibrated = {pose_text(T_base_wobj)}",))
