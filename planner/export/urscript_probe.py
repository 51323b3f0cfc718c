"""The URScript routines that run one search and one probe point, shared by every program.

Frames and units: metres and rotation vectors, poses ``p[x, y, z, rx, ry, rz]``. ``wobj`` is the
work object in the robot base frame, the frame every search is commanded in; each target is
written in the wobj frame and moved to the base with ``pose_trans(wobj, target)``. A nominal
program leaves ``wobj`` nominal; an adaptive one updates it between its searches
(:mod:`planner.export.urscript_steer`, :mod:`planner.export.urscript_adaptive`).

- ``run_search(goal, want, speed)``: one search from the current position to ``goal`` (base):
  ``movel`` in the thread ``search_move`` while the calling thread polls
  ``get_standard_digital_in(SENSOR_IN)`` every control cycle; at the switching event it reads
  ``get_actual_tcp_pose()``, kills the thread and ``stopl``-s. It returns ``[code, x, y, z]``:
  code 0 measured (x, y, z base frame, m), 1 no detection on the path, 2 the input already at
  the searched level at the start.
- ``probe(name, start_wobj, end_wobj, want, speed, safe_wobj, face_wobj)``: a joint move into
  the point's safe start (:mod:`planner.program.safety`); an approach search to the plan's end;
  for an edge point (``want`` False) an approach to its face, then the edge search from the
  measured face point along the plan's direction up to where the plan's search ends; a
  retreat to the safe start; the result logged with ``textmsg``.
- ``probe_from(...)`` (adaptive programs whose procedure starts an edge search from an earlier
  measurement, ``edge_start_from_measured``): a linear move from the safe start to that point
  (base) plus an offset along the face normal, then the edge search from there.
- ``require(i, name, result)`` (adaptive programs): keep a result in slot ``i`` of
  ``measured``/``measured_code``; a failed search stops the program (``halt``), since the
  frame update cannot go on without the point; ``stop_procedure(why)`` likewise for a
  degenerate layout.
"""

from __future__ import annotations

import re

import numpy as np

from calib.frames import rotvec_from_matrix
from planner.export.job import TargetPair
from planner.export.text import comment_text, fmt, literal_text
from planner.program.controllers import URSCRIPT_JOINT_MOVE

#: The standard digital input of the proximity sensor.
SENSOR_IN = 0
#: Joint-move and retreat speeds of every program: (a, v) of ``movej``, of ``movel``.
MOVEJ = (  # from the controller's joint moves, which the cycle time times
    f"a={fmt(URSCRIPT_JOINT_MOVE.acceleration_rad_s2 or 0.0, 3)}, "
    f"v={fmt(URSCRIPT_JOINT_MOVE.velocity_rad_s or 0.0, 3)}"
)
MOVEL = "a=0.5, v=0.1"


def pose_text(T: np.ndarray) -> str:
    """``p[x, y, z, rx, ry, rz]`` of a transform (metres, rotation vector in radians)."""
    vals = [*T[:3, 3], *rotvec_from_matrix(T[:3, :3])]
    return "p[" + ", ".join(fmt(v, 9) for v in vals) + "]"


def num(x: float, decimals: int = 12) -> str:
    """A float literal (always with a decimal point: URScript keeps ints and floats apart)."""
    s = fmt(x, decimals)
    return s if "." in s else s + ".0"


def nums(values: list[float], decimals: int = 12) -> str:
    """A list literal of floats, ``[a, b, ...]``."""
    return "[" + ", ".join(num(v, decimals) for v in values) + "]"


def names_of(ids: list[str]) -> list[str]:
    """Identifier suffixes for point ids (``meas_<s>``, ``measure_<s>``), unique: ids that map
    to the same identifier get ``_2``, ``_3`` ..."""
    out: list[str] = []
    for pid in ids:
        base = re.sub(r"[^A-Za-z0-9_]", "_", pid)
        name, k = base, 2
        while name in out:
            name, k = f"{base}_{k}", k + 1
        out.append(name)
    return out


def search_routines() -> list[str]:
    """The search thread, ``run_search`` and ``probe`` (module docstring)."""
    return [
        "  search_end = p[0, 0, 0, 0, 0, 0]",
        "  search_speed = 0.01",
        "  move_done = False",
        "  thread search_move():",
        "    global move_done",
        "    movel(search_end, a=0.2, v=search_speed)",
        "    move_done = True",
        "  end",
        "  # one search from the current position to `goal` (base): [code, x, y, z] (floats),",
        "  # code 0 measured (x, y, z base frame, m), 1 no detection,",
        "  # 2 input already at the searched level at the start",
        "  def run_search(goal, want, speed):",
        "    global search_end",
        "    global search_speed",
        "    global move_done",
        "    if get_standard_digital_in(SENSOR_IN) == want:",
        "      return [2.0, 0.0, 0.0, 0.0]",
        "    end",
        "    search_end = goal",
        "    search_speed = speed",
        "    move_done = False",
        "    mover = run search_move()",
        "    while (get_standard_digital_in(SENSOR_IN) != want) and (not move_done):",
        "      sync()",
        "    end",
        "    hit = get_actual_tcp_pose()",
        "    kill mover",
        "    stopl(1.0)",
        "    if get_standard_digital_in(SENSOR_IN) == want:",
        "      return [0.0, hit[0], hit[1], hit[2]]",
        "    end",
        "    return [1.0, 0.0, 0.0, 0.0]",
        "  end",
        *log_routine(),
        "  # probe one point (poses in the wobj frame): approach search from safe_wobj; for an",
        "  # edge point (want False) first approach the face (safe_wobj -> face_wobj), then run",
        "  # along the plan's direction from the measured face point up to the plan's end",
        "  def probe(name, start_wobj, end_wobj, want, speed, safe_wobj, face_wobj):",
        "    safe = pose_trans(wobj, safe_wobj)",
        "    # a joint move into the safe start (IK nearest the current joints), as the vias and",
        "    # the other formats, and as wobjcal check walks it; the searches are linear",
        f"    movej(safe, {MOVEJ})",
        "    if want:",
        "      result = run_search(pose_trans(wobj, end_wobj), True, speed)",
        "    else:",
        "      result = run_search(pose_trans(wobj, face_wobj), True, speed)",
        "      if result[0] == 0.0:",
        "        f = pose_trans(pose_inv(wobj), p[result[1], result[2], result[3], 0, 0, 0])",
        "        s = p[f[0], f[1], f[2], start_wobj[3], start_wobj[4], start_wobj[5]]",
        f"        movel(pose_trans(wobj, s), {MOVEL})",
        "        d = [end_wobj[0] - start_wobj[0], end_wobj[1] - start_wobj[1], "
        "end_wobj[2] - start_wobj[2]]",
        "        k = ((end_wobj[0] - s[0]) * d[0] + (end_wobj[1] - s[1]) * d[1] + "
        "(end_wobj[2] - s[2]) * d[2]) / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])",
        "        if k <= 0.0:",
        "          # the face point lies past where the plan's search ends: searching on would",
        "          # run backwards and could find another edge; no detection on the path",
        "          result = [1.0, 0.0, 0.0, 0.0]",
        "        else:",
        "          e = p[s[0] + k * d[0], s[1] + k * d[1], s[2] + k * d[2], end_wobj[3], "
        "end_wobj[4], end_wobj[5]]",
        "          result = run_search(pose_trans(wobj, e), False, speed)",
        "        end",
        "      end",
        "    end",
        *_log_and_retreat("    "),
        "    return result",
        "  end",
    ]


def _log_and_retreat(ind: str) -> list[str]:
    return [f"{ind}log_result(name, result)", f"{ind}movel(safe, {MOVEL})"]


#: What begins every results line in the log (:mod:`planner.results.urscript_log`).
LOG_MARK = "wobjcal/1"


def log_routine() -> list[str]:
    """``log_result(name, result)``: the results line of a search in the controller's log,
    ``wobjcal/1 point <id> <code> <x> <y> <z>`` (base frame, integer nanometres: an integer
    prints exactly; :mod:`planner.results.urscript_log` reads it)."""
    nm = "1000000000.0"
    return [
        "  # the result of a search as one log line, read by `wobjcal calibrate`:",
        "  # wobjcal/1 point <id> <code> <x> <y> <z>, code 0 measured, 1 no detection, 2 input",
        "  # already at the searched level; x y z the point, base frame, integer nanometres",
        "  def log_result(name, result):",
        f'    line = str_cat(str_cat("{LOG_MARK} point ", name), '
        'str_cat(" ", to_str(floor(result[0] + 0.5))))',
        *(
            f'    line = str_cat(line, str_cat(" ", to_str(floor(result[{k}] * {nm} + 0.5))))'
            for k in (1, 2, 3)
        ),
        "    textmsg(line)",
        "  end",
    ]


def probe_from_routine() -> list[str]:
    """``probe_from``: an edge search that starts at a measured point (base, m) moved ``off``
    (m) along the face normal ``nrm`` (wobj), instead of approaching the face first."""
    return [
        "  # an edge search from a measured point start_base (base, m) moved off (m) along the",
        "  # face normal nrm (wobj): a linear move there from the safe start, then the search",
        "  # along the plan's direction up to where the plan's search ends",
        "  def probe_from(name, start_base, off, nrm, start_wobj, end_wobj, speed, safe_wobj):",
        "    safe = pose_trans(wobj, safe_wobj)",
        f"    movej(safe, {MOVEJ})",
        "    q = pose_trans(pose_inv(wobj), p[start_base[0], start_base[1], start_base[2], 0, 0, "
        "0])",
        "    s = p[q[0] + off * nrm[0], q[1] + off * nrm[1], q[2] + off * nrm[2], start_wobj[3], "
        "start_wobj[4], start_wobj[5]]",
        "    d = [end_wobj[0] - start_wobj[0], end_wobj[1] - start_wobj[1], "
        "end_wobj[2] - start_wobj[2]]",
        "    k = ((end_wobj[0] - s[0]) * d[0] + (end_wobj[1] - s[1]) * d[1] + "
        "(end_wobj[2] - s[2]) * d[2]) / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])",
        "    if k <= 0.0:",
        "      # the measured start lies past the end of the search: no detection on the path",
        "      log_result(name, [1.0, 0.0, 0.0, 0.0])",
        "      return [1.0, 0.0, 0.0, 0.0]",
        "    end",
        f"    movel(pose_trans(wobj, s), {MOVEL})",
        "    e = p[s[0] + k * d[0], s[1] + k * d[1], s[2] + k * d[2], end_wobj[3], "
        "end_wobj[4], end_wobj[5]]",
        "    result = run_search(pose_trans(wobj, e), False, speed)",
        *_log_and_retreat("    "),
        "    return result",
        "  end",
    ]


def keep_routines(label: str) -> list[str]:
    """``stop_procedure(why)`` and ``require(i, name, result)`` of an adaptive program (module
    docstring); ``label`` names the procedure in the messages, e.g. ``"A-H"``."""
    lab = re.sub(r"[^A-Za-z0-9_. -]", "_", label)  # a string literal: no quote, no line break
    return [
        "  # stop the procedure: say why; what was measured stays in measured, measured_code",
        "  # and meas_<ID> (and in the log)",
        "  def stop_procedure(why):",
        f'    textmsg("{LOG_MARK} stop {lab}: ", why)',
        "    halt",
        "  end",
        "  # keep the result of slot i (base frame, m); a failed search stops the program: the",
        "  # frame update cannot go on without the point",
        "  def require(i, name, result):",
        "    global measured",
        "    global measured_code",
        "    measured_code[i] = result[0]",
        "    if result[0] != 0.0:",
        '      stop_procedure(str_cat(str_cat("point ", name), '
        'str_cat(": code (1 no detection, 2 at level at start) ", to_str(result[0]))))',
        "    end",
        "    measured[3 * i] = result[1]",
        "    measured[3 * i + 1] = result[2]",
        "    measured[3 * i + 2] = result[3]",
        "  end",
        "  # the point kept in slot i, [x, y, z] (base, m)",
        "  def point_of(i):",
        "    return [measured[3 * i], measured[3 * i + 1], measured[3 * i + 2]]",
        "  end",
    ]


def target_comment(t: TargetPair) -> str:
    """The comment line above a point's search."""
    return (
        f"  # {comment_text(t.point_id)}: {comment_text(t.kind)} search, role "
        f"{comment_text(t.role)}, "
        f"{fmt(t.length_m * 1000.0, 1)} mm at {fmt(t.speed_m_s * 1000.0, 1)} mm/s"
    )


def via_lines(t: TargetPair, ind: str) -> list[str]:
    """The joint moves through the point's vias (rad), before its safe start."""
    t.vias_deg("URScript")  # six joint values each, or a clear error
    return [
        f"{ind}movej([{', '.join(fmt(v, 6) for v in q)}], {MOVEJ})  # via {k} (rad)"
        for k, q in enumerate(t.vias_q_rad, start=1)
    ]


def probe_args(t: TargetPair) -> str:
    """The arguments of ``probe`` for ``t`` after its name."""
    want = "False" if t.kind == "edge" else "True"
    return (
        f"{pose_text(t.T_wobj_start)}, {pose_text(t.T_wobj_end)}, {want}, "
        f"{fmt(t.speed_m_s, 6)}, {pose_text(t.safe_start)}, {pose_text(t.face_end)}"
    )


def point_function(t: TargetPair, name: str, from_measured: float | None) -> list[str]:
    """``def measure_<name>()`` of an adaptive program: the vias, then the point's searches in
    the current ``wobj``; the result ``[code, x, y, z]``.

    Args:
        t: the target.
        name: its identifier suffix.
        from_measured: for an edge search the procedure starts at a measured point
            (``edge_start_from_measured``): the offset of the start along the face normal, m;
            the function then takes ``start_base`` (base, m). ``None``: approach the face
            first.
    """
    pid = literal_text(t.point_id)
    if from_measured is None:
        head = f"  def measure_{name}():"
        call = f'    result = probe("{pid}", {probe_args(t)})'
    else:
        n = [float(v) for v in t.normal_wobj]
        head = f"  def measure_{name}(start_base):"
        call = (
            f'    result = probe_from("{pid}", start_base, {num(from_measured)}, {nums(n)}, '
            f"{pose_text(t.T_wobj_start)}, {pose_text(t.T_wobj_end)}, {fmt(t.speed_m_s, 6)}, "
            f"{pose_text(t.safe_start)})"
        )
    return [target_comment(t), head, *via_lines(t, "    "), call, "    return result", "  end"]
