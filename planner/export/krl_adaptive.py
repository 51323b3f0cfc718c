"""The paper's A-H procedure (section 3.2) in KUKA KRL: the frame update after every step.

Every search target is an ``E6POS`` in ``BASE_DATA[10]`` (``$BASE``); the program rewrites
``BASE_DATA[10]`` after each step exactly as :func:`calib.paper.stator_procedure.
run_stator_procedure` updates its estimate (and as the RAPID module of
:mod:`planner.export.rapid_adaptive` does), so every later search is commanded in the
work-object frame estimated so far:

1. A, B in the preliminary (nominal) frame; ``EST_P3`` (eq. 11-12); ``SET_ROTATION`` with
   ``V1 = B - A``, ``V2 = P3 - B`` (eq. 1-9); 2. ``SHIFT_ORIGIN`` x from B (eq. 10);
3. C, y from C; 4. D, E, rotation from ``V1 = B - A``, ``V2 = D - E``; 5. x from E;
6. F (edge), G, H (edge); ``EDGE_POINT`` removes the edge-start offset (``fEdgeBack``) and the
sensor's edge-event offset (``fEdgeEvent``) from F and H; final rotation from H, F, D with V2
inverted (``V1 = F - H``, ``V2 = F - D``); 7. z from H; 8. C retaken, y; 9. D retaken, x;
10. with the plan's x-offset run, :mod:`planner.export.krl_xoffset`.

The updates are written where the measuring program's steps put them (``program.steps``: each
:class:`~planner.program.model.UpdateStep` runs the procedure's steps its searches complete,
the :class:`~planner.program.model.FrameStep` the rest); a program whose updates do not follow
the procedure is refused.

Measured points are kept in the robot base (``xMeas[i]``, mm): the search gives ``xHit`` in
``$BASE`` and the probe routine converts it with ``BASE_DATA[10]:xHit`` at once, before any
update. ``SET_ROTATION`` builds ``X = V1 x V2``, ``Y = V1``, ``Z = X x Y`` (eq. 3-6) and writes
the rotation as the Tait-Bryan angles of eq. 7-9 (``ATAN2``: KUKA's A, B, C, degrees);
``SHIFT_ORIGIN`` moves the origin along one axis so that the point gets the face's coordinate
(eq. 10). A point not measured stops the program (``nResult`` 2), and so do points that define
no frame (``nResult`` 3); ``nResult`` 1: ``BASE_DATA[10]`` is the calibrated work object.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

from calib.paper.settings import Hultman2013
from calib.paper.stator_layout import STATOR_POINT_IDS as ROLES
from calib.procedures import procedure_kind
from planner.export.job import AdaptiveSpec, ExportJob
from planner.export.krl_probe import probe_call
from planner.export.krl_text import WOBJ, stop_lines, vector_text
from planner.export.text import fmt
from planner.program.model import FrameStep, MeasuringProgram, SearchStep, UpdateStep


def spec_of(job: ExportJob) -> AdaptiveSpec:
    """The job's A-H specifics (:func:`with_spec` gives a job them).

    Raises:
        ValueError: the job has none.
    """
    if job.adaptive is None:
        raise ValueError(f"export job {job.name!r} has no A-H procedure (plan method {job.method})")
    return job.adaptive


def with_spec(job: ExportJob, program: MeasuringProgram) -> ExportJob:
    """``job`` with the A-H specifics of its adaptive A-H ``program``: the job's own, or, for a
    job built without them, the program's (its points are the plan's, in plan order, and its
    settings the resolved ones: what :func:`planner.program.build.adaptive_spec` computes).

    Raises:
        ValueError: the program is no A-H program of the job's points.
    """
    if job.adaptive is not None:
        return job
    layout = procedure_kind(program.method).adaptive_layout(program.points)
    if (
        layout is None
        or not isinstance(program.settings, Hultman2013)
        or len(program.points) != len(job.targets)
    ):
        raise ValueError(
            f"{program.name}: not an A-H program of the job's {len(job.targets)} points"
        )
    face = layout.face_coords_wobj
    spec = AdaptiveSpec(
        index={rp.role: i for i, rp in enumerate(program.points)},
        settings=program.settings,
        face_coords_wobj=(float(face[0]), float(face[1]), float(face[2])),
    )
    return replace(job, adaptive=spec)


def krl_job(job: ExportJob) -> tuple[ExportJob, MeasuringProgram]:
    """``job`` as the KRL writer uses it, and its KRL program: the A-H specifics kept (or
    taken from the program) for an adaptive A-H program, dropped for any other (the data list
    and the slots of ``xMeas`` follow from it)."""
    program = job.program("krl")
    if not program.adaptive or program.steers_itself:
        return replace(job, adaptive=None), program
    return with_spec(job, program), program


def measured_slots(job: ExportJob) -> list[tuple[str, bool]]:
    """``(point id, is a retake)`` of each slot of ``xMeas``/``nFail``, in order: the points
    in plan order, then (adaptive A-H with retakes) C and D retaken."""
    slots = [(t.point_id, False) for t in job.targets]
    a = job.adaptive
    if a is not None and a.settings.retake_c_d:
        slots += [(job.targets[a.index[r]].point_id, True) for r in ("C", "D")]
    return slots


def ah_header() -> str:
    """What the program computes, for its header."""
    return (
        "ADAPTIVE: the A-H procedure of Hultman & Leijon (2013); "
        f"{WOBJ} (and $BASE) is updated after every step, so each search runs in the "
        f"work-object frame estimated so far. At the end (nResult 1) {WOBJ} holds the frame "
        "`wobjcal calibrate` computes from xMeas, NOT YET SCREENED for gross errors: use it "
        "only once `wobjcal calibrate` trusts it."
    )


def ah_data(job: ExportJob, names: list[str]) -> list[str]:
    """The data-list lines of the procedure: its settings, the frames it builds, and the
    search direction and face normal of F and H (wobj)."""
    a = spec_of(job)
    s = a.settings
    back = s.edge_start_offset_m if s.edge_start_from_measured else 0.0
    face = a.face_coords_wobj
    lines = [
        "; A-H procedure settings (mm, degrees)",
        f"DECL REAL fTanBeta1={fmt(math.tan(s.beta1_rad), 12)}",
        f"DECL REAL fP3Height={fmt(s.p3_height_m * 1000.0, 6)}",
        f"DECL REAL fEdgeBack={fmt(back * 1000.0, 6)}",
        f"DECL REAL fEdgeEvent={fmt(s.edge_offset_m * 1000.0, 6)}",
        f"DECL REAL fFaceX={fmt(face[0] * 1000.0, 6)}",
        f"DECL REAL fFaceY={fmt(face[1] * 1000.0, 6)}",
        f"DECL REAL fFaceZ={fmt(face[2] * 1000.0, 6)}",
        "; P3 (eq. 12) and the edge points F, H without their offsets (robot base, mm)",
        "DECL FRAME xP3",
        "DECL FRAME xEdgeF",
        "DECL FRAME xEdgeH",
    ]
    for role in ("F", "H"):
        t, name = job.targets[a.index[role]], names[a.index[role]]
        lines += [
            f"; {role}: search direction and face normal (wobj)",
            f"DECL FRAME {name}_dir={vector_text(t.edge_direction_wobj)}",
            f"DECL FRAME {name}_nrm={vector_text(t.normal_wobj)}",
        ]
    return lines


def ah_routines() -> list[str]:
    """``EST_P3``, ``SET_ROTATION``, ``SHIFT_ORIGIN`` and ``EDGE_POINT``."""
    u = WOBJ
    return [
        "; Eq. 11-12: xP3, fP3Height above B on the side face assumed inclined by beta1 (base,",
        "; mm); nResult 3 when A and B coincide in the base xy-plane",
        "DEF EST_P3(xPa:IN,xPb:IN)",
        "  DECL FRAME xPa,xPb",
        "  DECL REAL fAl",
        "  IF ABS(xPb.X-xPa.X)+ABS(xPb.Y-xPa.Y)<0.001 THEN",
        "    nResult=3",
        "    RETURN",
        "  ENDIF",
        "  fAl=ATAN2(xPb.X-xPa.X,xPb.Y-xPa.Y)",
        "  IF fAl>90 THEN",
        "    fAl=fAl-180",
        "  ENDIF",
        "  IF fAl<-90 THEN",
        "    fAl=fAl+180",
        "  ENDIF",
        "  xP3=$NULLFRAME",
        "  xP3.X=xPb.X+fP3Height*fTanBeta1*COS(fAl)*COS(fAl)",
        "  xP3.Y=xPb.Y+fP3Height*fTanBeta1*SIN(fAl)*COS(fAl)",
        "  xP3.Z=xPb.Z+fP3Height",
        "END",
        "",
        f"; Eq. 3-9: the rotation of {u} from V1 = xV1b - xV1a (WOCS +y) and",
        "; V2 = xV2b - xV2a (in the WOCS yz-plane), its origin unchanged: X = V1 x V2, Y = V1,",
        "; Z = X x Y (eq. 3-6), then the Tait-Bryan z-y'-x'' angles A, B, C (eq. 7-9);",
        "; nResult 3 when V1 and V2 span no plane",
        "DEF SET_ROTATION(xV1a:IN,xV1b:IN,xV2a:IN,xV2b:IN)",
        "  DECL FRAME xV1a,xV1b,xV2a,xV2b",
        "  DECL REAL fAx,fAy,fAz,fBx,fBy,fBz,fNa,fNb,fNx",
        "  DECL REAL fXx,fXy,fXz,fYx,fYy,fYz,fZz",
        "  fAx=xV1b.X-xV1a.X",
        "  fAy=xV1b.Y-xV1a.Y",
        "  fAz=xV1b.Z-xV1a.Z",
        "  fBx=xV2b.X-xV2a.X",
        "  fBy=xV2b.Y-xV2a.Y",
        "  fBz=xV2b.Z-xV2a.Z",
        "  fXx=fAy*fBz-fAz*fBy",
        "  fXy=fAz*fBx-fAx*fBz",
        "  fXz=fAx*fBy-fAy*fBx",
        "  fNa=SQRT(fAx*fAx+fAy*fAy+fAz*fAz)",
        "  fNb=SQRT(fBx*fBx+fBy*fBy+fBz*fBz)",
        "  fNx=SQRT(fXx*fXx+fXy*fXy+fXz*fXz)",
        "  IF fNx<=0.000001*fNa*fNb THEN",
        "    nResult=3",
        "    RETURN",
        "  ENDIF",
        "  fXx=fXx/fNx",
        "  fXy=fXy/fNx",
        "  fXz=fXz/fNx",
        "  fYx=fAx/fNa",
        "  fYy=fAy/fNa",
        "  fYz=fAz/fNa",
        "  fZz=fXx*fYy-fXy*fYx",
        "  ; eq. 7-9: the angles of R = [X Y Z] (A about z, B about y', C about x'')",
        f"  {u}.A=ATAN2(fXy,fXx)",
        f"  {u}.B=ATAN2(-fXz,SQRT(fXx*fXx+fXy*fXy))",
        f"  {u}.C=ATAN2(fYz,fZz)",
        f"  $BASE={u}",
        "END",
        "",
        "; Eq. 10 for one axis (nAxis 1, 2, 3: x, y, z of the WOCS): move the origin along it so",
        "; that the point xPt (base, mm) gets the coordinate fFace (mm)",
        "DEF SHIFT_ORIGIN(nAxis:IN,xPt:IN,fFace:IN)",
        "  DECL INT nAxis",
        "  DECL FRAME xPt",
        "  DECL REAL fFace",
        "  DECL FRAME xRot,xAxis",
        "  DECL REAL fS",
        "  xAxis=$NULLFRAME",
        "  IF nAxis==1 THEN",
        "    xAxis.X=1",
        "  ENDIF",
        "  IF nAxis==2 THEN",
        "    xAxis.Y=1",
        "  ENDIF",
        "  IF nAxis==3 THEN",
        "    xAxis.Z=1",
        "  ENDIF",
        "  ; the axis in the base: turned by the rotation of the estimate",
        f"  xRot={u}",
        "  xRot.X=0",
        "  xRot.Y=0",
        "  xRot.Z=0",
        "  xAxis=xRot:xAxis",
        f"  fS=xAxis.X*(xPt.X-{u}.X)+xAxis.Y*(xPt.Y-{u}.Y)+xAxis.Z*(xPt.Z-{u}.Z)-fFace",
        f"  {u}.X={u}.X+fS*xAxis.X",
        f"  {u}.Y={u}.Y+fS*xAxis.Y",
        f"  {u}.Z={u}.Z+fS*xAxis.Z",
        f"  $BASE={u}",
        "END",
        "",
        "; An edge point (base, mm) moved back by fEdgeBack along the face normal xNrm and by the",
        "; sensor's edge-event offset fEdgeEvent along the search direction xDir (wobj vectors)",
        "DEFFCT FRAME EDGE_POINT(xPt:IN,xDir:IN,xNrm:IN)",
        "  DECL FRAME xPt,xDir,xNrm",
        "  DECL FRAME xW",
        f"  xW=INV_POS({u}):xPt",
        "  xW.X=xW.X-fEdgeBack*xNrm.X-fEdgeEvent*xDir.X",
        "  xW.Y=xW.Y-fEdgeBack*xNrm.Y-fEdgeEvent*xDir.Y",
        "  xW.Z=xW.Z-fEdgeBack*xNrm.Z-fEdgeEvent*xDir.Z",
        f"  RETURN {u}:xW",
        "ENDFCT",
        "",
    ]


def _key_role(key: str) -> tuple[str, bool]:
    """``(role, is a retake)`` of an A-H search key (``"C"``, ``"C2"``)."""
    if key in ROLES:
        return key, False
    if key[:-1] in ("C", "D") and key.endswith("2"):
        return key[:-1], True
    raise ValueError(f"search {key!r} is not a search of the A-H procedure")


def ah_body(job: ExportJob, program: MeasuringProgram, names: list[str]) -> list[str]:
    """The measuring routine's body: the program's searches in its order and, at each of its
    updates, the procedure's steps those searches complete.

    Raises:
        ValueError: the program's searches or updates are not those of the A-H procedure.
    """
    a = spec_of(job)
    n = len(job.targets)
    slot = {r: a.index[r] + 1 for r in ROLES} | {"C2": n + 1, "D2": n + 2}
    retake = a.settings.retake_c_d
    c2, d2 = ("C2", "D2") if retake else ("C", "D")
    name = {r: names[a.index[r]] for r in ROLES}
    pad = "  "

    def m(key: str) -> str:
        return f"xMeas[{slot[key]}]"

    def rotation(*points: str) -> list[str]:
        return [f"{pad}SET_ROTATION({','.join(points)})", *stop_lines(pad)]

    steps: list[tuple[set[str], Callable[[], list[str]]]] = [
        (
            {"A", "B"},
            lambda: [
                f"{pad}; 1: alpha1, P3 (eq. 11-12); rotation from V1 = B - A, V2 = P3 - B",
                f"{pad}EST_P3({m('A')},{m('B')})",
                *stop_lines(pad),
                *rotation(m("A"), m("B"), m("B"), "xP3"),
                f"{pad}; 2: x origin from B (eq. 10)",
                f"{pad}SHIFT_ORIGIN(1,{m('B')},fFaceX)",
            ],
        ),
        ({"C"}, lambda: [f"{pad}; 3: y origin from C", f"{pad}SHIFT_ORIGIN(2,{m('C')},fFaceY)"]),
        (
            {"D", "E"},
            lambda: [
                f"{pad}; 4: rotation from V1 = B - A, V2 = D - E (eq. 2-9)",
                *rotation(m("A"), m("B"), m("E"), m("D")),
                f"{pad}; 5: x origin from E",
                f"{pad}SHIFT_ORIGIN(1,{m('E')},fFaceX)",
            ],
        ),
        (
            {"F", "G", "H"},
            lambda: [
                f"{pad}; 6: F, H without their offsets; rotation from V1 = F - H, V2 = F - D",
                f"{pad}xEdgeF=EDGE_POINT({m('F')},{name['F']}_dir,{name['F']}_nrm)",
                f"{pad}xEdgeH=EDGE_POINT({m('H')},{name['H']}_dir,{name['H']}_nrm)",
                *rotation("xEdgeH", "xEdgeF", m("D"), "xEdgeF"),
                f"{pad}; 7: z origin from H",
                f"{pad}SHIFT_ORIGIN(3,xEdgeH,fFaceZ)",
            ],
        ),
        (
            {c2},
            lambda: [f"{pad}; 8: y origin from {c2}", f"{pad}SHIFT_ORIGIN(2,{m(c2)},fFaceY)"],
        ),
        (
            {d2},
            lambda: [f"{pad}; 9: x origin from {d2}", f"{pad}SHIFT_ORIGIN(1,{m(d2)},fFaceX)"],
        ),
    ]
    measured: set[str] = set()
    done = 0
    lines: list[str] = []

    def ready() -> list[str]:
        nonlocal done
        out: list[str] = []
        while done < len(steps) and steps[done][0] <= measured:
            out += steps[done][1]()
            done += 1
        return out

    for step in program.steps:
        if isinstance(step, SearchStep) and step.recorded:
            role, _ = _key_role(step.key)
            start = None
            if step.start == "measured point":
                start = {"F": m("E"), "H": m("G")}.get(role)
                if start is None:
                    raise ValueError(f"search {step.key} starts at a measured point: not A-H's")
            lines += probe_call(name[role], slot[step.key], pad, start)
            measured.add(step.key)
        elif isinstance(step, UpdateStep):
            update = ready()
            if not update:
                raise ValueError(f"update after {step.after} is no step of the A-H procedure")
            lines += update
        elif isinstance(step, FrameStep):
            lines += ready()
            if done < len(steps):
                raise ValueError(f"the A-H program ends {len(steps) - done} update(s) early")
    return lines
