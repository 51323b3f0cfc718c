"""An adaptive best-fit or 3-2-1 program in RAPID: the frame update between searches.

The program measures its points in the order of its steps, each ``SearchL`` in ``wobjCal``, and
after the points an update names it moves ``wobjCal.uframe`` by the smallest motion that puts
them on their nominal faces (:mod:`planner.program.steering`): Gauss-Newton on the residuals
``n . (x - p)`` of the measured points ``x`` (wobj), rotations about the layout's centroid
``nPivot`` scaled by its RMS size ``nScale``, the step restricted to the motions the nominal
points fix (the update's basis, precomputed and written as constants in ``nBasis``). After the
last point the update uses them all: ``wobjCal`` is then the calibrated work object, the frame
``wobjcal calibrate`` computes from the measurements file.

Per iteration ``Steer`` builds the Jacobian rows ``-[n, (x - c) x n / L]``, ``B = J V`` and
solves ``(B^T B) y = B^T r`` (Gauss-Jordan with partial pivoting, at most 6 x 6); the step is
``-V y`` (translation at the centroid, rotation vector times ``L``), applied as
``PoseMult(uframe, [t - w x c, q(w)])``. It stops after 10 iterations or a step below 1E-6 mm,
as :func:`calib.estimators.runners.min_norm_update` does. RAPID ``num`` is single precision on
the controller: the update is good to about 1E-4 mm there.
"""

from __future__ import annotations

import math

from calib.procedures.base import RolePoint
from planner.export.job import ExportJob
from planner.export.rapid_probe import WOBJ, stop_procs
from planner.export.text import fmt
from planner.program.model import MeasuringProgram, SearchStep, UpdateStep
from planner.program.steering import ITERATIONS, STEP_TOL_M, update_bases


def _nums(values: list[float], decimals: int) -> str:
    return "[" + ",".join(fmt(v, decimals) for v in values) + "]"


def steer_procs(job: ExportJob, program: MeasuringProgram) -> list[str]:
    """The constants of the layout and the updates, and ``PROC Steer``."""
    index = {t.point_id: i for i, t in enumerate(job.targets)}
    order = [index[s.point_id] + 1 for s in program.searches if s.recorded]
    by_id: dict[str, RolePoint] = {rp.point.id: rp for rp in program.points}
    normals: list[float] = []
    nominal: list[float] = []
    for t in job.targets:
        p = by_id[t.point_id].point
        normals += [float(v) for v in p.normal]
        nominal += [float(v) * 1000.0 for v in p.position_m]
    basis: list[float] = []
    for _k, V in update_bases(program):
        basis += [float(v) for v in V.ravel()]  # row-major: 6 rows of r
    assert program.pivot_m is not None
    n = len(job.targets)
    u = f"{WOBJ}.uframe"
    return [
        *stop_procs(program.method_label),
        f"    ! {program.name}: the frame update between searches (planner.program.steering)",
        f"    CONST num nOrder{{{n}}}:={_nums([float(i) for i in order], 0)};",
        f"    CONST num nRowN{{{3 * n}}}:={_nums(normals, 12)};",
        f"    CONST num nRowP{{{3 * n}}}:={_nums(nominal, 9)};",
        f"    CONST pos nPivot:={_nums([v * 1000.0 for v in program.pivot_m], 9)};",
        f"    CONST num nScale:={fmt(program.scale_m * 1000.0, 9)};",
        f"    CONST num nBasis{{{len(basis)}}}:={_nums(basis, 12)};",
        f"    CONST num nDeg:={fmt(180.0 / math.pi, 12)};",
        f"    VAR num nJac{{{6 * n}}};",
        f"    VAR num nRes{{{n}}};",
        f"    VAR num nB{{{6 * n}}};",
        "    VAR num nH{42};",
        "    VAR num nY{6};",
        "    VAR num nStep{6};",
        "",
        "    ! Solve nH (r x r, augmented by the column r+1 = B^T res) for nY: Gauss-Jordan with",
        "    ! partial pivoting",
        "    PROC SolveNormal(num r)",
        "        VAR num piv;",
        "        VAR num big;",
        "        VAR num f;",
        "        VAR num tmp;",
        "        FOR c FROM 1 TO r DO",
        "            piv:=c;",
        "            big:=Abs(nH{(r+1)*(c-1)+c});",
        "            FOR i FROM c+1 TO r DO",
        "                IF Abs(nH{(r+1)*(i-1)+c})>big THEN",
        "                    piv:=i;",
        "                    big:=Abs(nH{(r+1)*(i-1)+c});",
        "                ENDIF",
        "            ENDFOR",
        '            IF big<1E-12 Fail "frame update: the points measured so far fix no frame";',
        "            FOR m FROM 1 TO r+1 DO",
        "                tmp:=nH{(r+1)*(c-1)+m};",
        "                nH{(r+1)*(c-1)+m}:=nH{(r+1)*(piv-1)+m};",
        "                nH{(r+1)*(piv-1)+m}:=tmp;",
        "            ENDFOR",
        "            FOR i FROM 1 TO r DO",
        "                IF i<>c THEN",
        "                    f:=nH{(r+1)*(i-1)+c}/nH{(r+1)*(c-1)+c};",
        "                    FOR m FROM c TO r+1 DO",
        "                        nH{(r+1)*(i-1)+m}:=nH{(r+1)*(i-1)+m}-f*nH{(r+1)*(c-1)+m};",
        "                    ENDFOR",
        "                ENDIF",
        "            ENDFOR",
        "        ENDFOR",
        "        FOR c FROM 1 TO r DO",
        "            nY{c}:=nH{(r+1)*(c-1)+r+1}/nH{(r+1)*(c-1)+c};",
        "        ENDFOR",
        "    ENDPROC",
        "",
        "    ! Move wobjCal by the smallest motion that puts the first k points of nOrder on",
        "    ! their faces; the update's basis is nBasis{off+1..off+6*r} (6 rows of r)",
        "    PROC Steer(num k,num off,num r)",
        "        VAR num j;",
        "        VAR num s;",
        "        VAR num th;",
        "        VAR num big;",
        "        VAR pos x;",
        "        VAR pos nrm;",
        "        VAR pos cr;",
        "        VAR pos w;",
        "        VAR pose mv;",
        "        VAR orient q;",
        "        VAR bool bDone:=FALSE;",
        f"        FOR it FROM 1 TO {ITERATIONS} DO",
        "            IF NOT bDone THEN",
        "                FOR i FROM 1 TO k DO",
        "                    j:=nOrder{i};",
        f"                    x:=PoseVect(PoseInv({u}),measured{{j}});",
        "                    nrm:=[nRowN{3*j-2},nRowN{3*j-1},nRowN{3*j}];",
        "                    nRes{i}:=DotProd(nrm,x-[nRowP{3*j-2},nRowP{3*j-1},nRowP{3*j}]);",
        "                    cr:=CrossProd(x-nPivot,nrm);",
        "                    nJac{6*i-5}:=-nrm.x;",
        "                    nJac{6*i-4}:=-nrm.y;",
        "                    nJac{6*i-3}:=-nrm.z;",
        "                    nJac{6*i-2}:=-cr.x/nScale;",
        "                    nJac{6*i-1}:=-cr.y/nScale;",
        "                    nJac{6*i}:=-cr.z/nScale;",
        "                ENDFOR",
        "                ! B = J V (k x r)",
        "                FOR i FROM 1 TO k DO",
        "                    FOR c FROM 1 TO r DO",
        "                        s:=0;",
        "                        FOR m FROM 1 TO 6 DO",
        "                            s:=s+nJac{6*(i-1)+m}*nBasis{off+r*(m-1)+c};",
        "                        ENDFOR",
        "                        nB{r*(i-1)+c}:=s;",
        "                    ENDFOR",
        "                ENDFOR",
        "                ! the normal equations B^T B y = B^T res, augmented",
        "                FOR a FROM 1 TO r DO",
        "                    FOR c FROM 1 TO r DO",
        "                        s:=0;",
        "                        FOR i FROM 1 TO k DO",
        "                            s:=s+nB{r*(i-1)+a}*nB{r*(i-1)+c};",
        "                        ENDFOR",
        "                        nH{(r+1)*(a-1)+c}:=s;",
        "                    ENDFOR",
        "                    s:=0;",
        "                    FOR i FROM 1 TO k DO",
        "                        s:=s+nB{r*(i-1)+a}*nRes{i};",
        "                    ENDFOR",
        "                    nH{(r+1)*(a-1)+r+1}:=s;",
        "                ENDFOR",
        "                SolveNormal r;",
        "                ! the step -V y: translation at the pivot, rotation vector times nScale",
        "                big:=0;",
        "                FOR m FROM 1 TO 6 DO",
        "                    s:=0;",
        "                    FOR c FROM 1 TO r DO",
        "                        s:=s-nBasis{off+r*(m-1)+c}*nY{c};",
        "                    ENDFOR",
        "                    nStep{m}:=s;",
        "                    IF Abs(s)>big big:=Abs(s);",
        "                ENDFOR",
        "                w:=[nStep{4}/nScale,nStep{5}/nScale,nStep{6}/nScale];",
        "                mv.trans:=[nStep{1},nStep{2},nStep{3}]-CrossProd(w,nPivot);",
        "                th:=VectMagn(w);",
        "                s:=0.5;",
        "                q.q1:=1;",
        "                IF th>=1E-12 THEN",
        "                    s:=Sin(0.5*th*nDeg)/th;",
        "                    q.q1:=Cos(0.5*th*nDeg);",
        "                ENDIF",
        "                q.q2:=s*w.x;",
        "                q.q3:=s*w.y;",
        "                q.q4:=s*w.z;",
        "                mv.rot:=NOrient(q);",
        f"                {u}:=PoseMult({u},mv);",
        f"                IF big<{fmt(STEP_TOL_M * 1000.0, 9)} bDone:=TRUE;",
        "            ENDIF",
        "        ENDFOR",
        "    ENDPROC",
    ]


def steer_main(job: ExportJob, program: MeasuringProgram, names: list[str]) -> list[str]:
    """The body of ``main``: each point's probe in the program's order, a failed search stops
    the program (nothing to steer by), and the updates between."""
    index = {t.point_id: i for i, t in enumerate(job.targets)}
    updates = iter(update_bases(program))
    ind = "        "
    off = 0
    lines = [f"{ind}! {program.name}: each search in wobjCal, the frame estimated so far"]
    for step in program.steps:
        if isinstance(step, SearchStep) and step.recorded:
            i = index[step.point_id]
            lines += [f"{ind}Probe_{names[i]} {i + 1};", f"{ind}Require {i + 1};"]
        elif isinstance(step, UpdateStep) and step.uses:
            k, V = next(updates)
            r = V.shape[1]
            lines.append(f"{ind}Steer {k},{off},{r};")
            off += 6 * r
    lines.append(f'{ind}TPWrite "wobjcal: done, {WOBJ} not screened: run wobjcal calibrate";')
    return lines
