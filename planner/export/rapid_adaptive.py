"""The paper's A-H procedure (section 3.2) in RAPID: the frame update after every step.

Every search robtarget is a constant in ``wobjCal``; the program rewrites ``wobjCal.uframe``
after each step exactly as :func:`calib.paper.stator_procedure.run_stator_procedure` updates its
estimate, so every later ``SearchL`` is commanded in the work-object frame estimated so far:

1. A, B in the preliminary (nominal) frame; ``EstimateP3`` (eq. 11-12); ``SetRotation`` with
   ``V1 = B - A``, ``V2 = P3 - B`` (eq. 1-9); 2. ``ShiftOrigin`` x from B (eq. 10);
3. C, y from C; 4. D, E, rotation from ``V1 = B - A``, ``V2 = D - E``; 5. x from E;
6. F (edge), G, H (edge); final rotation from H, F, D with V2 inverted (``V1 = F - H``,
``V2 = F - D``); 7. z from H; 8. C retaken, y; 9. D retaken, x; 10. with the plan's x-offset
run (:class:`calib.paper.settings.XOffsetRun`), the side face measured over every second tooth at
two slot-hole levels in the calibrated frame (``pxMeas``), the x-offset matrix of eq. 13-14
(``mxW``, the same plane interpolation as :func:`calib.paper.xoffset.xoffset_matrix`) and
``SlotTarget(slot, layer, standoff)``, the paper's function returning the robot target at a slot
hole (its y and z, the matrix's x plus the standoff, in ``wobjCal``).

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

from calib.paper.settings import XOffsetRun
from calib.paper.stator_layout import STATOR_POINT_IDS as ROLES
from calib.paper.xoffset import xoffset_probe_points
from planner.export.job import AdaptiveSpec, ExportJob
from planner.export.rapid_probe import WOBJ, stop_procs
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
        f"    ! At the end {WOBJ} holds the frame `wobjcal calibrate` computes, NOT YET SCREENED",
        "    ! for gross errors: use it once `wobjcal calibrate` on the recorded points trusts it.",
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
        *stop_procs("A-H"),
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
        "    ! face along that axis. The axis is turned by the rotation alone (PoseVect of the",
        "    ! whole uframe minus its origin loses 1E-4 of the unit vector in single precision)",
        "    PROC ShiftOrigin(pos axis,pos p,num face)",
        "        VAR pos u;",
        "        VAR pose r;",
        f"        r.rot:={u}.rot;",
        "        u:=PoseVect(r,axis);",
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
        f'{ind}TPWrite "wobjcal: A-H done, {WOBJ} not screened: run wobjcal calibrate";',
    ]
    if a.settings.xoffset is not None:
        lines += [
            f"{ind}! 10: the x-offset run over every second tooth at two slot-hole levels, in the",
            f"{ind}!     calibrated frame, and the x-offset matrix (eq. 13-14)",
            f"{ind}XOffsetRun;",
        ]
    return lines


def xoffset_procs(job: ExportJob, names: list[str]) -> list[str]:
    """Data and routines of the x-offset run (eq. 13-14) and ``SlotTarget``; ``[]`` without."""
    a = job.adaptive
    if a is None or a.settings.xoffset is None:
        return []
    run: XOffsetRun = a.settings.xoffset
    grid = run.grid
    rows = xoffset_probe_points(grid, run.layers, run.teeth)
    k_n, l_n = len(rows), len(rows[0])
    ys = [p.position_m[1] for p in rows[0]]
    zs = [row[0].position_m[2] for row in rows]
    d = names[a.index["D"]]
    nx = len(grid.slot_y_m) * len(grid.layer_z_m)

    def nums(values: list[float]) -> str:
        return ",".join(fmt(v * 1000.0, 4) for v in values)

    u = f"tSensor\\WObj:={WOBJ}"
    return [
        "",
        "    ! x-offset run (section 3.2, eq. 13-14): PX over the teeth (pxY) at the levels (pxZ),",
        f"    ! searched along -x of {WOBJ} with {d}'s orientation; mxW{{(layer-1)*nSlots+slot}}",
        "    ! is the x-offset of each slot hole (mm, wobjCal)",
        f"    CONST num nPxLevels:={k_n};",
        f"    CONST num nPxTeeth:={l_n};",
        f"    CONST num pxY{{{l_n}}}:=[{nums(ys)}];",
        f"    CONST num pxZ{{{k_n}}}:=[{nums(zs)}];",
        f"    CONST num nPxStart:={fmt(run.start_offset_m * 1000.0, 4)};",
        f"    CONST num nPxOver:={fmt(run.overtravel_m * 1000.0, 4)};",
        f"    CONST num nSlots:={grid.n_slots};",
        f"    CONST num nLayers:={grid.n_layers};",
        f"    CONST num slotY{{{grid.n_slots}}}:=[{nums(list(grid.slot_y_m))}];",
        f"    CONST num layerZ{{{grid.n_layers}}}:=[{nums(list(grid.layer_z_m))}];",
        f"    PERS pos pxMeas{{{k_n * l_n}}}:=[{','.join(['[0,0,0]'] * (k_n * l_n))}];",
        f"    PERS num mxW{{{nx}}}:=[{','.join(['0'] * nx)}];",
        "",
        "    ! One x-offset search: level k, tooth l; the point is kept in wobjCal (mm)",
        "    PROC ProbePX(num k,num l)",
        "        VAR robtarget pS;",
        "        VAR robtarget pE;",
        f"        pS:={d}_start;",
        "        pS.trans:=[nFaceX+nPxStart,pxY{l},pxZ{k}];",
        "        pE:=pS;",
        "        pE.trans.x:=nFaceX-nPxOver;",
        f"        MoveJ pS,vApproach,fine,{u};",
        f"        SearchL\\SStop,diSensor,pMeas,pE,vSearch_{d},{u};",
        "        pxMeas{(k-1)*nPxTeeth+l}:=pMeas.trans;",
        f"        MoveL pS,vApproach,fine,{u};",
        "    ERROR",
        "        IF ERRNO=ERR_WHLSEARCH OR ERRNO=ERR_SIGSUPSEARCH THEN",
        '            Fail "x-offset point PX"+NumToStr(k,0)+"_"+NumToStr(l,0)+" not found";',
        "        ENDIF",
        "        RAISE;",
        "    ENDPROC",
        "",
        "    ! Eq. 14: x at (y, z) on the plane through PX[k,l], PX[k,l+1], PX[k+1,l], the levels",
        "    ! and teeth bracketing (y, z) (the end pair outside them: extrapolation)",
        "    FUNC num XOffsetAt(num y,num z)",
        "        VAR num k:=1;",
        "        VAR num l:=1;",
        "        VAR num sk:=1;",
        "        VAR num sl:=1;",
        "        VAR num det;",
        "        VAR pos p0;",
        "        VAR pos d1;",
        "        VAR pos d2;",
        "        IF pxMeas{nPxTeeth+1}.z<pxMeas{1}.z sk:=-1;",
        "        FOR m FROM 1 TO nPxLevels DO",
        "            IF m>1 AND m<nPxLevels AND sk*pxMeas{(m-1)*nPxTeeth+1}.z<=sk*z k:=m;",
        "        ENDFOR",
        "        IF pxMeas{(k-1)*nPxTeeth+2}.y<pxMeas{(k-1)*nPxTeeth+1}.y sl:=-1;",
        "        FOR m FROM 1 TO nPxTeeth DO",
        "            IF m>1 AND m<nPxTeeth AND sl*pxMeas{(k-1)*nPxTeeth+m}.y<=sl*y l:=m;",
        "        ENDFOR",
        "        p0:=pxMeas{(k-1)*nPxTeeth+l};",
        "        d1:=pxMeas{(k-1)*nPxTeeth+l+1}-p0;",
        "        d2:=pxMeas{k*nPxTeeth+l}-p0;",
        "        det:=d1.y*d2.z-d1.z*d2.y;",
        '        IF Abs(det)<1E-6 Fail "x-offset points span no plane";',
        "        RETURN p0.x+(y-p0.y)*(d1.x*d2.z-d1.z*d2.x)/det"
        "+(z-p0.z)*(d1.y*d2.x-d1.x*d2.y)/det;",
        "    ENDFUNC",
        "",
        "    ! Measure the PX points and fill the x-offset matrix",
        "    PROC XOffsetRun()",
        "        FOR k FROM 1 TO nPxLevels DO",
        "            FOR l FROM 1 TO nPxTeeth DO",
        "                ProbePX k,l;",
        "            ENDFOR",
        "        ENDFOR",
        "        FOR i FROM 1 TO nLayers DO",
        "            FOR j FROM 1 TO nSlots DO",
        "                mxW{(i-1)*nSlots+j}:=XOffsetAt(slotY{j},layerZ{i});",
        "            ENDFOR",
        "        ENDFOR",
        "    ENDPROC",
        "",
        "    ! The robot target at a slot hole (section 3.2): its y and z, the x-offset matrix's x",
        f"    ! plus standoff (mm, along wobjCal +x), with {d}'s orientation, in {WOBJ}",
        "    FUNC robtarget SlotTarget(num slot,num layer,num standoff)",
        "        VAR robtarget t;",
        f"        t:={d}_start;",
        "        t.trans:=[mxW{(layer-1)*nSlots+slot}+standoff,slotY{slot},layerZ{layer}];",
        "        RETURN t;",
        "    ENDFUNC",
    ]
