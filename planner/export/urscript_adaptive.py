"""The paper's A-H procedure (section 3.2) in URScript: the frame update after every step.

Every search target is written in the wobj frame; the program rewrites ``wobj`` after each step
exactly as :func:`calib.paper.stator_procedure.run_stator_procedure` updates its estimate (and
as the RAPID module, :mod:`planner.export.rapid_adaptive`, does), so every later search is
commanded in the work-object frame estimated so far:

1. A, B in the preliminary (nominal) frame; ``estimate_p3`` (eq. 11-12); ``set_rotation`` with
   ``V1 = B - A``, ``V2 = P3 - B`` (eq. 1-9); 2. ``shift_origin`` x from B (eq. 10);
3. C, y from C; 4. D, E, rotation from ``V1 = B - A``, ``V2 = D - E``; 5. x from E;
6. F (edge), G, H (edge); final rotation from H, F, D with V2 inverted (``V1 = F - H``,
``V2 = F - D``); 7. z from H; 8. C retaken, y; 9. D retaken, x; 10. with the plan's x-offset
run, :mod:`planner.export.urscript_xoffset`.

The main body follows the measuring program's steps (``job.program("urscript").steps``): each
recorded search where the program measures it, and the procedure's updates where the program
updates its frame (checked: searches in another order than the procedure's, a search the program
commands before an update the procedure makes, or an update with nothing to update, is an error
of the writer, not a program).

Measured points are kept in the base frame (``measured``, m). ``set_rotation`` builds
``X = V1 x V2``, ``Y = V1``, ``Z = X x Y`` (eq. 3-6) and writes the rotation through the
Tait-Bryan angles of eq. 7-9 (``atan2``, then ``rpy2rotvec([gamma, beta, alpha])``: URScript's
RPY vector is ``Rz(yaw) Ry(pitch) Rx(roll)``, the z-y'-x'' angles); ``shift_origin`` moves the
origin along one axis of ``wobj`` so that the point gets the face's coordinate (eq. 10);
``edge_point`` moves an edge point back by the start offset along the face normal and by the
sensor's edge-event offset along the search direction (wobj vectors). URScript angles are
radians, and ``atan2(x, y)`` is the arc tangent of ``x / y``. A failed search or a degenerate
frame stops the program (``halt``) with what was measured kept.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from calib.paper.hultman import COINCIDENT_TOL_M, COLLINEAR_SIN_TOL
from calib.paper.stator_layout import STATOR_POINT_IDS as ROLES
from planner.export.job import AdaptiveSpec, ExportJob
from planner.export.text import comment_text
from planner.export.urscript_layout import SearchCalls, adaptive_program
from planner.export.urscript_probe import num, nums
from planner.export.urscript_xoffset import xoffset_main, xoffset_procs
from planner.program.model import FrameStep, MeasuringProgram, SearchStep, UpdateStep


def _spec(job: ExportJob) -> AdaptiveSpec:
    if job.adaptive is None:
        raise ValueError(f"export job {job.name!r} has no A-H procedure (plan method {job.method})")
    return job.adaptive


def adaptive_procs(job: ExportJob) -> list[str]:
    """The A-H constants and the routines of the frame update."""
    a = _spec(job)
    s = a.settings
    back = s.edge_start_offset_m if s.edge_start_from_measured else 0.0
    return [
        "  # A-H procedure settings (m, rad) and the faces' coordinates (wobj, m)",
        f"  ah_tan_beta1 = {num(math.tan(s.beta1_rad))}",
        f"  ah_p3_height = {num(s.p3_height_m)}",
        f"  ah_edge_back = {num(back)}  # edge start offset along the face normal",
        f"  ah_edge_event = {num(s.edge_offset_m)}  # edge-event offset along the search",
        f"  ah_face = {nums(list(a.face_coords_wobj))}  # x of the side, y of the short side, "
        "z of the top",
        "  ah_p3 = [0.0, 0.0, 0.0]",
        "  ah_pf = [0.0, 0.0, 0.0]",
        "  ah_ph = [0.0, 0.0, 0.0]",
        "  def vsub(u, v):",
        "    return [u[0] - v[0], u[1] - v[1], u[2] - v[2]]",
        "  end",
        "  def vcross(u, v):",
        "    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], "
        "u[0] * v[1] - u[1] * v[0]]",
        "  end",
        "  # eq. 11-12: P3, ah_p3_height above B on the side face assumed inclined by beta1",
        "  # (base frame, m)",
        "  def estimate_p3(a, b):",
        "    dx = b[0] - a[0]",
        "    dy = b[1] - a[1]",
        f"    if sqrt(dx * dx + dy * dy) < {num(COINCIDENT_TOL_M, 15)}:",
        '      stop_procedure("A and B coincide in the base xy-plane (eq. 11)")',
        "    end",
        "    alpha1 = atan2(dx, dy)",
        "    if alpha1 > pi / 2.0:",
        "      alpha1 = alpha1 - pi",
        "    elif alpha1 < -pi / 2.0:",
        "      alpha1 = alpha1 + pi",
        "    end",
        "    ca = cos(alpha1)",
        "    sa = sin(alpha1)",
        "    return [b[0] + ah_p3_height * ah_tan_beta1 * ca * ca, "
        "b[1] + ah_p3_height * ah_tan_beta1 * sa * ca, b[2] + ah_p3_height]",
        "  end",
        "  # eq. 3-9: the rotation of wobj from V1 (its +y) and V2 (in its yz-plane), base",
        "  # frame; the origin unchanged",
        "  def set_rotation(v1, v2):",
        "    global wobj",
        "    n1 = norm(v1)",
        "    n2 = norm(v2)",
        f"    if (n1 < {num(COINCIDENT_TOL_M, 15)}) or (n2 < {num(COINCIDENT_TOL_M, 15)}):",
        '      stop_procedure("a vector of the rotation has zero length (eq. 1-2)")',
        "    end",
        "    ux = vcross(v1, v2)",
        "    nx = norm(ux)",
        f"    if nx < {num(COLLINEAR_SIN_TOL, 15)} * n1 * n2:",
        '      stop_procedure("the points of the rotation are collinear (eq. 3)")',
        "    end",
        "    ux = [ux[0] / nx, ux[1] / nx, ux[2] / nx]",
        "    uy = [v1[0] / n1, v1[1] / n1, v1[2] / n1]",
        "    uz = vcross(ux, uy)",
        "    # eq. 7-9: the Tait-Bryan z-y'-x'' angles of R = [ux uy uz]",
        "    alpha = atan2(ux[1], ux[0])",
        "    beta = atan2(-ux[2], sqrt(ux[0] * ux[0] + ux[1] * ux[1]))",
        "    gamma = atan2(uy[2], uz[2])",
        "    rv = rpy2rotvec([gamma, beta, alpha])",
        "    wobj = p[wobj[0], wobj[1], wobj[2], rv[0], rv[1], rv[2]]",
        "  end",
        "  # eq. 10 for one axis of wobj (0 x, 1 y, 2 z): the point q (base, m) gets the",
        "  # coordinate face (m) along it",
        "  def shift_origin(axis, q, face):",
        "    global wobj",
        "    w = pose_trans(pose_inv(wobj), p[q[0], q[1], q[2], 0, 0, 0])",
        "    e = [0.0, 0.0, 0.0]",
        "    e[axis] = w[axis] - face",
        "    wobj = pose_trans(wobj, p[e[0], e[1], e[2], 0, 0, 0])",
        "  end",
        "  # an edge point q (base, m) moved back by the start offset along the face normal nrm",
        "  # and by the sensor's edge-event offset along the search direction d (wobj vectors)",
        "  def edge_point(q, d, nrm):",
        "    w = pose_trans(pose_inv(wobj), p[q[0], q[1], q[2], 0, 0, 0])",
        "    g = pose_trans(wobj, p[w[0] - ah_edge_back * nrm[0] - ah_edge_event * d[0], "
        "w[1] - ah_edge_back * nrm[1] - ah_edge_event * d[1], "
        "w[2] - ah_edge_back * nrm[2] - ah_edge_event * d[2], 0, 0, 0])",
        "    return [g[0], g[1], g[2]]",
        "  end",
    ]


@dataclass
class _Stage:
    """One update of the procedure: the measurements it needs, ``(role, take)``, and its
    lines."""

    needs: tuple[tuple[str, int], ...]
    lines: list[str]
    done: bool = field(default=False)


def _stages(job: ExportJob, calls: SearchCalls) -> list[_Stage]:
    """The procedure's updates after its searches, in its order (module docstring); each
    is due when its measurements are in and the updates before it are done."""
    a = _spec(job)
    pid = {r: job.targets[a.index[r]].point_id for r in ROLES}
    take2 = 2 if a.settings.retake_c_d else 1

    def at(role: str, take: int = 1) -> str:
        return f"point_of({calls.slot_of(pid[role], take)})"

    return [
        _Stage(
            (("A", 1), ("B", 1)),
            [
                "  # 1: alpha1, P3 (eq. 11-12); rotation from A, B, P3 (eq. 1-9)",
                f"  ah_p3 = estimate_p3({at('A')}, {at('B')})",
                f"  set_rotation(vsub({at('B')}, {at('A')}), vsub(ah_p3, {at('B')}))",
                "  # 2: x origin from B (eq. 10)",
                f"  shift_origin(0, {at('B')}, ah_face[0])",
            ],
        ),
        _Stage(
            (("C", 1),), ["  # 3: y origin from C", f"  shift_origin(1, {at('C')}, ah_face[1])"]
        ),
        _Stage(
            (("D", 1), ("E", 1)),
            [
                "  # 4: rotation from V1 = B - A, V2 = D - E (eq. 2-9)",
                f"  set_rotation(vsub({at('B')}, {at('A')}), vsub({at('D')}, {at('E')}))",
                "  # 5: x origin from E",
                f"  shift_origin(0, {at('E')}, ah_face[0])",
            ],
        ),
        _Stage(
            (("F", 1), ("G", 1), ("H", 1)),
            [
                "  # 6: rotation from H, F, D with V2 inverted (eq. 1-9)",
                f"  set_rotation(vsub(ah_pf, ah_ph), vsub(ah_pf, {at('D')}))",
                "  # 7: z origin from H",
                "  shift_origin(2, ah_ph, ah_face[2])",
            ],
        ),
        _Stage(
            (("C", take2),),
            [
                f"  # 8: y origin from C{' retaken' if take2 == 2 else ''}",
                f"  shift_origin(1, {at('C', take2)}, ah_face[1])",
            ],
        ),
        _Stage(
            (("D", take2),),
            [
                f"  # 9: x origin from D{' retaken' if take2 == 2 else ''}",
                f"  shift_origin(0, {at('D', take2)}, ah_face[0])",
            ],
        ),
    ]


def adaptive_main(job: ExportJob, program: MeasuringProgram) -> list[str]:
    """The main body: the program's steps, each update the procedure's (module docstring).

    Raises:
        ValueError: the program's steps and the procedure's updates disagree.
    """
    a = _spec(job)
    role_of = {t.point_id: t.role for t in job.targets}
    order = [role_of[s.point_id] for s in program.searches if s.recorded]
    want = [*ROLES, *(("C", "D") if a.settings.retake_c_d else ())]
    if order != want:
        raise ValueError(f"{program.name}: searches {order}, the A-H procedure {want}")
    calls = SearchCalls(job, program)
    stages = _stages(job, calls)
    pid = {r: job.targets[a.index[r]].point_id for r in ROLES}
    from_measured = {"F": "E", "H": "G"} if a.settings.edge_start_from_measured else {}
    measured: set[tuple[str, int]] = set()
    takes: dict[str, int] = {}
    lines = [f"  # {comment_text(program.name)}: each search in wobj, the frame estimated so far"]

    def ready() -> list[_Stage]:
        out = []
        for st in stages:
            if st.done:
                continue
            if not set(st.needs) <= measured:
                break
            out.append(st)
        return out

    for step in program.steps:
        if isinstance(step, SearchStep) and step.recorded:
            if ready():
                raise ValueError(
                    f"{program.name}: {step.key} searched before the procedure's update"
                )
            role = role_of[step.point_id]
            takes[role] = takes.get(role, 0) + 1
            start = None
            if step.start == "measured point":
                if role not in from_measured:
                    raise ValueError(f"{program.name}: {step.key} starts at a measured point")
                start = f"point_of({calls.slot_of(pid[from_measured[role]])})"
            elif role in from_measured and takes[role] == 1:
                raise ValueError(f"{program.name}: {step.key} does not start at the measured point")
            lines += calls.next(step, start)
            if role in ("F", "H") and takes[role] == 1:
                t = job.targets[a.index[role]]
                lines.append(
                    f"  ah_p{role.lower()} = edge_point(point_of({calls.slot_of(t.point_id)}), "
                    f"{nums([float(v) for v in t.edge_direction_wobj])}, "
                    f"{nums([float(v) for v in t.normal_wobj])})"
                )
            measured.add((role, takes[role]))
        elif isinstance(step, UpdateStep | FrameStep):
            due = ready()
            if isinstance(step, UpdateStep) and not due:
                raise ValueError(f"{program.name}: no update of the procedure after {step.after}")
            for st in due:
                lines += st.lines
                st.done = True
    if not all(st.done for st in stages):
        raise ValueError(f"{program.name}: the program ends before the procedure's last update")
    lines.append('  textmsg("wobjcal: A-H done, wobj (not screened, see calibrate): ", wobj)')
    lines += xoffset_main(job)
    return lines


def export_adaptive(job: ExportJob, program: MeasuringProgram) -> str:
    """The adaptive A-H program of ``job`` (module docstring)."""
    a = _spec(job)
    s = a.settings
    computes = (
        "the A-H procedure of Hultman & Leijon (2013), on the controller: after every step "
        "wobj is updated (rotation from A, B and P3, eq. 1-9 and 11-12; x origin from B, eq. "
        "10; y from C; rotation from A, B, D, E; x from E; rotation from H, F, D; z from H; "
        + ("y from C and x from D retaken" if s.retake_c_d else "y from C and x from D")
        + f"; edge-event offset {s.edge_offset_m * 1000.0:g} mm removed from F and H), so each "
        "search is commanded in the work-object frame estimated so far. At the end wobj "
        "holds the frame `wobjcal calibrate` computes from the same points, NOT YET SCREENED "
        "for gross errors: use it only once `wobjcal calibrate` trusts it."
        + (
            " Then the x-offset run (eq. 13-14) in the calibrated frame fills mx_w; "
            "slot_target(slot, layer, standoff) gives the target at a slot hole."
            if s.xoffset is not None
            else ""
        )
        + " A failed search stops the program (halt); the points measured before it stay in "
        "measured and meas_<ID>."
    )
    starts: dict[str, float] = {}
    if s.edge_start_from_measured:
        starts = {job.targets[a.index[r]].point_id: s.edge_start_offset_m for r in ("F", "H")}
    procs = adaptive_procs(job) + xoffset_procs(job)
    return adaptive_program(job, program, computes, procs, adaptive_main(job, program), starts)
