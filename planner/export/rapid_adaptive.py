"""The paper's A-H procedure (section 3.2) in RAPID: the frame update after every step.

Every search robtarget is a constant in ``wobjCal``; the program rewrites ``wobjCal.uframe``
after each step exactly as :func:`calib.paper.stator_procedure.run_stator_procedure` updates its
estimate, so every later ``SearchL`` is commanded in the work-object frame estimated so far:

1. A, B in the preliminary (nominal) frame; ``EstimateP3`` (eq. 11-12); ``SetRotation`` with
   ``V1 = B - A``, ``V2 = P3 - B`` (eq. 1-9); 2. ``ShiftOrigin`` x from B (eq. 10);
3. C, y from C; 4. D, E, rotation from ``V1 = B - A``, ``V2 = D - E``; 5. x from E;
6. F (edge), G, H (edge); final rotation from H, F, D with V2 inverted (``V1 = F - H``,
``V2 = F - D``); 7. z from H; 8. C retaken, y; 9. D retaken, x.

Measured points are kept in the base frame (``measured{i}``, mm): ``SearchL`` gives ``pMeas``
in ``wobjCal`` and the probe routine converts it with ``PoseVect`` at once, before any update.
``SetRotation`` builds ``X = V1 x V2``, ``Y = V1``, ``Z = X x Y`` (eq. 3-6) and writes the
rotation through the Tait-Bryan angles of eq. 7-9 (``ATan2``, ``OrientZYX``); ``ShiftOrigin``
moves the origin along one axis so that the point gets the face's coordinate (eq. 10). RAPID
angles are degrees. A failed search or a degenerate frame stops the program (``Fail``) after
writing the measurements file.
"""

from __future__ import annotations

import math

from calib.paper.stator_layout import STATOR_POINT_IDS as ROLES
from planner.export.job import AdaptiveSpec, ExportJob
from planner.export.rapid_probe import WOBJ
from planner.export.text import fmt


def _adaptive(job: ExportJob) -> AdaptiveSpec:
    if job.adaptive is None:
        raise ValueError(f"export job {job.name!r} has no A-H procedure (plan method {job.method})")
    return job.adaptive


def adaptive_header() -> list[str]:
    """Header comment lines of an adaptive module."""
    return [
        f"    ! ADAPTIVE: the A-H procedure of Hultman & Leijon (2013); {WOBJ}.uframe is updated",
        "    ! after every step, so each search runs in the work-object frame estimated so far.",
        f"    ! At the end {WOBJ} is the calibrated work object (same as `wobjcal calibrate`).",
    ]


def adaptive_procs(job: ExportJob) -> list[str]:
    """Constants and the routines of the frame update."""
    a = job.adaptive
    assert a is not None
    back = a.settings.edge_start_offset_m if a.settings.edge_start_from_measured else 0.0
    u = f"{WOBJ}.uframe"
    return [
        "    ! A-H procedure settings (mm, degrees)",
        f"    CONST num nTanBeta1:={fmt(math.tan(a.settings.beta1_rad), 12)};",
        f"    CONST num nP3Height:={fmt(a.settings.p3_height_m * 1000.0, 6)};",
        f"    CONST num nEdgeBack:={fmt(back * 1000.0, 6)};",
        f"    CONST num nEdgeEvent:={fmt(a.settings.edge_offset_m * 1000.0, 6)};",
        f"    CONST num nFaceX:={fmt(a.face_coords_wobj[0] * 1000.0, 6)};",
        f"    CONST num nFaceY:={fmt(a.face_coords_wobj[1] * 1000.0, 6)};",
        f"    CONST num nFaceZ:={fmt(a.face_coords_wobj[2] * 1000.0, 6)};",
        "    VAR pos pP3;",
        "    VAR pos pF;",
        "    VAR pos pH;",
        "",
        "    ! Stop the procedure: report, write what was measured, end the program",
        "    PROC Fail(string why)",
        '        TPWrite "wobjcal: A-H stopped: "+why;',
        "        WriteMeasurements;",
        "        EXIT;",
        "    ENDPROC",
        "",
        "    PROC Require(num i)",
        '        IF NOT measuredOk{i} Fail "point "+measuredId{i}+": "+measuredErr{i};',
        "    ENDPROC",
        "",
        "    ! Eq. 11-12: P3, nP3Height above B on the side face assumed inclined by beta1",
        "    FUNC pos EstimateP3(pos a,pos b)",
        "        VAR num alpha1;",
        '        IF Abs(b.x-a.x)+Abs(b.y-a.y)<0.001 Fail "A and B coincide in base xy";',
        "        alpha1:=ATan2(b.x-a.x,b.y-a.y);",
        "        IF alpha1>90 alpha1:=alpha1-180;",
        "        IF alpha1<-90 alpha1:=alpha1+180;",
        "        RETURN b+nP3Height*[nTanBeta1*Cos(alpha1)*Cos(alpha1),"
        "nTanBeta1*Sin(alpha1)*Cos(alpha1),1];",
        "    ENDFUNC",
        "",
        "    ! Eq. 3-9: rotation from V1 (WOCS +y) and V2 (in the yz-plane); origin unchanged",
        "    PROC SetRotation(pos v1,pos v2)",
        "        VAR pos ux;",
        "        VAR pos uy;",
        "        VAR pos uz;",
        "        ux:=CrossProd(v1,v2);",
        '        IF VectMagn(ux)<1E-6*VectMagn(v1)*VectMagn(v2) Fail "degenerate points";',
        "        ux:=(1/VectMagn(ux))*ux;",
        "        uy:=(1/VectMagn(v1))*v1;",
        "        uz:=CrossProd(ux,uy);",
        "        ! eq. 7-9: Tait-Bryan z-y'-x'' angles of R = [ux uy uz]",
        f"        {u}.rot:=NOrient(OrientZYX(ATan2(ux.y,ux.x),"
        "ATan2(-ux.z,Sqrt(ux.x*ux.x+ux.y*ux.y)),ATan2(uy.z,uz.z)));",
        "    ENDPROC",
        "",
        "    ! Eq. 10 for one axis (axis in wobj coordinates): the point p (base) gets coordinate",
        "    ! face along that axis",
        "    PROC ShiftOrigin(pos axis,pos p,num face)",
        "        VAR pos u;",
        f"        u:=PoseVect({u},axis)-{u}.trans;",
        f"        {u}.trans:={u}.trans+(DotProd(u,p-{u}.trans)-face)*u;",
        "    ENDPROC",
        "",
        "    ! An edge point (base) moved back by the start offset along the face normal and by",
        "    ! the sensor's edge-event offset along the search direction (wobj vectors)",
        "    FUNC pos EdgePoint(pos p,pos dir,pos normal)",
        "        VAR pos w;",
        f"        w:=PoseVect(PoseInv({u}),p);",
        "        w:=w-nEdgeBack*normal-nEdgeEvent*dir;",
        f"        RETURN PoseVect({u},w);",
        "    ENDFUNC",
    ]


def adaptive_main(job: ExportJob, names: list[str]) -> list[str]:
    """The body of ``main``: the nine steps of the procedure."""
    a = job.adaptive
    assert a is not None
    idx = {r: a.index[r] + 1 for r in ROLES}
    name = {r: names[a.index[r]] for r in ROLES}
    n = len(job.targets)
    m = {r: f"measured{{{idx[r]}}}" for r in ROLES}
    ind = "        "

    def probe(role: str, i: int, start_from: str | None = None) -> list[str]:
        arg = f",{start_from}" if start_from else ""
        return [f"{ind}Probe_{name[role]} {i}{arg};", f"{ind}Require {i};"]

    from_e = m["E"] if a.settings.edge_start_from_measured else None
    from_g = m["G"] if a.settings.edge_start_from_measured else None
    c2, d2 = (n + 1, n + 2) if a.settings.retake_c_d else (idx["C"], idx["D"])
    lines = [
        f"{ind}! 1: A, B in the preliminary frame; alpha1, P3 (eq. 11-12); rotation (eq. 1-9)",
        *probe("A", idx["A"]),
        *probe("B", idx["B"]),
        f"{ind}pP3:=EstimateP3({m['A']},{m['B']});",
        f"{ind}SetRotation {m['B']}-{m['A']},pP3-{m['B']};",
        f"{ind}! 2: x origin from B (eq. 10)",
        f"{ind}ShiftOrigin [1,0,0],{m['B']},nFaceX;",
        f"{ind}! 3: C, y origin",
        *probe("C", idx["C"]),
        f"{ind}ShiftOrigin [0,1,0],{m['C']},nFaceY;",
        f"{ind}! 4: D, E; rotation from V1 = B - A, V2 = D - E (eq. 2-9)",
        *probe("D", idx["D"]),
        *probe("E", idx["E"]),
        f"{ind}SetRotation {m['B']}-{m['A']},{m['D']}-{m['E']};",
        f"{ind}! 5: x origin from E",
        f"{ind}ShiftOrigin [1,0,0],{m['E']},nFaceX;",
        f"{ind}! 6: F (edge), G, H (edge); rotation from H, F, D with V2 inverted (eq. 1-9)",
        *probe("F", idx["F"], from_e),
        f"{ind}pF:=EdgePoint({m['F']},{name['F']}_dir,{name['F']}_normal);",
        *probe("G", idx["G"]),
        *probe("H", idx["H"], from_g),
        f"{ind}pH:=EdgePoint({m['H']},{name['H']}_dir,{name['H']}_normal);",
        f"{ind}SetRotation pF-pH,pF-{m['D']};",
        f"{ind}! 7: z origin from H",
        f"{ind}ShiftOrigin [0,0,1],pH,nFaceZ;",
        f"{ind}! 8: C{' retaken' if a.settings.retake_c_d else ''}, y origin",
        *(probe("C", c2) if a.settings.retake_c_d else []),
        f"{ind}ShiftOrigin [0,1,0],measured{{{c2}}},nFaceY;",
        f"{ind}! 9: D{' retaken' if a.settings.retake_c_d else ''}, x origin",
        *(probe("D", d2) if a.settings.retake_c_d else []),
        f"{ind}ShiftOrigin [1,0,0],measured{{{d2}}},nFaceX;",
        f'{ind}TPWrite "wobjcal: A-H done, {WOBJ} is the calibrated work object";',
    ]
    return lines
