"""An adaptive best-fit or 3-2-1 program in KUKA KRL: the frame update between searches.

The program measures its points in the order of its steps, each search in ``BASE_DATA[10]``
(``$BASE``), and after the points an update names it moves ``BASE_DATA[10]`` by the smallest
motion that puts them on their nominal faces (:mod:`planner.program.steering`, the same update
as the RAPID ``Steer`` of :mod:`planner.export.rapid_steer`): Gauss-Newton on the residuals
``n . (x - p)`` of the measured points ``x`` (wobj, mm: ``INV_POS(BASE_DATA[10]):xMeas[j]``),
rotations about the layout's centroid ``xPivot`` scaled by its RMS size ``fScale``, the step
restricted to the motions the nominal points fix (the update's basis, precomputed by
:func:`planner.program.steering.update_basis` and written in ``fBasis[u,1..6,1..nRank[u]]``).
After the last point the update uses them all: ``BASE_DATA[10]`` is then the calibrated work
object, the frame ``wobjcal calibrate`` computes from the measured points.

Per iteration ``STEER`` builds the Jacobian rows ``-[n, (x - c) x n / L]``, ``B = J V`` and
solves ``(B^T B) y = B^T r`` (``SOLVE_NORMAL``: Gauss-Jordan with partial pivoting, at most
6 x 6); the step is ``-V y`` (translation at the centroid, rotation vector times ``L``), turned
into a frame ``[R(w), t - w x c]`` (Rodrigues' formula, then its A, B, C by ``ATAN2``) and
applied as ``BASE_DATA[10]=BASE_DATA[10]:xMove``. It stops after 10 iterations or a step below
1E-6 mm, as :func:`calib.estimators.runners.min_norm_update` does. KRL ``REAL`` is single
precision on the controller: expect the update to about 1E-4 mm there (it then runs its 10
iterations), far below the sensor's noise (an estimate: the tests' interpreter computes in
double).
"""

from __future__ import annotations

import math

import numpy as np

from planner.export.job import ExportJob
from planner.export.krl_probe import probe_call
from planner.export.krl_text import WOBJ, array_lines, stop_lines, vector_text
from planner.export.text import fmt
from planner.program.model import MeasuringProgram, SearchStep, UpdateStep
from planner.program.steering import ITERATIONS, STEP_TOL_M, update_bases


def steer_header(program: MeasuringProgram) -> str:
    """What the program computes, for its header."""
    return (
        f"ADAPTIVE: after the points its steps name, {WOBJ} (and $BASE) is moved by the "
        "smallest motion that puts the points measured so far on their faces "
        "(planner.program.steering: best fit: after every point; 3-2-1: after the primary, "
        "the secondary and the tertiary points), so each search runs in the work-object frame "
        f"estimated so far. At the end (nResult 1) {WOBJ} holds the {program.method_label} "
        "frame `wobjcal calibrate` computes from xMeas, NOT YET SCREENED for gross errors: "
        "use it only once `wobjcal calibrate` trusts it."
    )


def steer_data(job: ExportJob, program: MeasuringProgram) -> list[str]:
    """The data-list lines of the layout and the updates (wobj frame, mm)."""
    index = {t.point_id: i for i, t in enumerate(job.targets)}
    order = [index[s.point_id] + 1 for s in program.searches if s.recorded]
    by_id = {rp.point.id: rp.point for rp in program.points}
    normals = np.array([by_id[t.point_id].normal for t in job.targets], dtype=float)
    nominal = np.array([by_id[t.point_id].position_m for t in job.targets], dtype=float) * 1e3
    updates = update_bases(program)
    basis = np.full((len(updates), 6, 6), np.nan)
    for u, (_k, V) in enumerate(updates):
        basis[u, :, : V.shape[1]] = V
    assert program.pivot_m is not None  # checked by update_bases
    n = len(job.targets)
    return [
        f"; {program.name}: the frame update between searches (planner.program.steering)",
        "; the slot of the i-th point measured; each slot's nominal face normal and point (wobj,",
        "; mm); the layout's centroid and RMS size (mm); each update's basis, 6 rows of nRank[u]",
        *array_lines("INT", "nOrder", np.array(order, dtype=float)),
        *array_lines("REAL", "fRowN", normals, 12),
        *array_lines("REAL", "fRowP", nominal, 9),
        f"DECL FRAME xPivot={vector_text(np.asarray(program.pivot_m) * 1e3, 9)}",
        f"DECL REAL fScale={fmt(program.scale_m * 1e3, 9)}",
        *array_lines("INT", "nRank", np.array([V.shape[1] for _k, V in updates], dtype=float)),
        *array_lines("REAL", "fBasis", basis, 12),
        f"DECL REAL fDeg={fmt(180.0 / math.pi, 12)}",
        "; work arrays of STEER and SOLVE_NORMAL",
        f"DECL REAL fJac[{n},6]",
        f"DECL REAL fRes[{n}]",
        f"DECL REAL fB[{n},6]",
        "DECL REAL fH[6,7]",
        "DECL REAL fY[6]",
        "DECL REAL fStep[6]",
    ]


def steer_routines() -> list[str]:
    """``SOLVE_NORMAL`` and ``STEER``."""
    return [
        "; Solve fH (r x r, augmented by the column r+1 = B^T res) for fY: Gauss-Jordan with",
        "; partial pivoting; nResult 3 when the points measured so far fix no frame",
        "DEF SOLVE_NORMAL(nR:IN)",
        "  DECL INT nR",
        "  DECL INT nC,nI,nM,nPiv",
        "  DECL REAL fBig,fF,fT",
        "  FOR nC=1 TO nR",
        "    nPiv=nC",
        "    fBig=ABS(fH[nC,nC])",
        "    FOR nI=nC+1 TO nR",
        "      IF ABS(fH[nI,nC])>fBig THEN",
        "        nPiv=nI",
        "        fBig=ABS(fH[nI,nC])",
        "      ENDIF",
        "    ENDFOR",
        "    IF fBig<0.000000000001 THEN",
        "      nResult=3",
        "      RETURN",
        "    ENDIF",
        "    FOR nM=1 TO nR+1",
        "      fT=fH[nC,nM]",
        "      fH[nC,nM]=fH[nPiv,nM]",
        "      fH[nPiv,nM]=fT",
        "    ENDFOR",
        "    FOR nI=1 TO nR",
        "      IF nI<>nC THEN",
        "        fF=fH[nI,nC]/fH[nC,nC]",
        "        FOR nM=nC TO nR+1",
        "          fH[nI,nM]=fH[nI,nM]-fF*fH[nC,nM]",
        "        ENDFOR",
        "      ENDIF",
        "    ENDFOR",
        "  ENDFOR",
        "  FOR nC=1 TO nR",
        "    fY[nC]=fH[nC,nR+1]/fH[nC,nC]",
        "  ENDFOR",
        "END",
        "",
        f"; Move {WOBJ} by the smallest motion that puts the first nK points of nOrder on",
        "; their faces, in the motions of update nU (its basis fBasis[nU,,])",
        "DEF STEER(nK:IN,nU:IN)",
        "  DECL INT nK,nU",
        "  DECL INT nIt,nI,nJ,nC,nM,nA,nR",
        "  DECL REAL fS,fBig,fTh,fSn,fCs,fWx,fWy,fWz,fR11,fR21,fR31,fR32,fR33",
        "  DECL FRAME xW,xMove",
        "  DECL BOOL bDone",
        "  nR=nRank[nU]",
        "  bDone=FALSE",
        f"  FOR nIt=1 TO {ITERATIONS}",
        "    IF NOT bDone THEN",
        "      ; residuals n.(x - p) in the estimate; Jacobian rows -[n, (x - c) x n / L]",
        "      FOR nI=1 TO nK",
        "        nJ=nOrder[nI]",
        f"        xW=INV_POS({WOBJ}):xMeas[nJ]",
        "        fS=fRowN[nJ,1]*(xW.X-fRowP[nJ,1])+fRowN[nJ,2]*(xW.Y-fRowP[nJ,2])",
        "        fRes[nI]=fS+fRowN[nJ,3]*(xW.Z-fRowP[nJ,3])",
        "        fJac[nI,1]=-fRowN[nJ,1]",
        "        fJac[nI,2]=-fRowN[nJ,2]",
        "        fJac[nI,3]=-fRowN[nJ,3]",
        "        fJac[nI,4]=((xW.Z-xPivot.Z)*fRowN[nJ,2]-(xW.Y-xPivot.Y)*fRowN[nJ,3])/fScale",
        "        fJac[nI,5]=((xW.X-xPivot.X)*fRowN[nJ,3]-(xW.Z-xPivot.Z)*fRowN[nJ,1])/fScale",
        "        fJac[nI,6]=((xW.Y-xPivot.Y)*fRowN[nJ,1]-(xW.X-xPivot.X)*fRowN[nJ,2])/fScale",
        "      ENDFOR",
        "      ; B = J V (nK x nR)",
        "      FOR nI=1 TO nK",
        "        FOR nC=1 TO nR",
        "          fS=0",
        "          FOR nM=1 TO 6",
        "            fS=fS+fJac[nI,nM]*fBasis[nU,nM,nC]",
        "          ENDFOR",
        "          fB[nI,nC]=fS",
        "        ENDFOR",
        "      ENDFOR",
        "      ; the normal equations B^T B y = B^T res, augmented",
        "      FOR nA=1 TO nR",
        "        FOR nC=1 TO nR",
        "          fS=0",
        "          FOR nI=1 TO nK",
        "            fS=fS+fB[nI,nA]*fB[nI,nC]",
        "          ENDFOR",
        "          fH[nA,nC]=fS",
        "        ENDFOR",
        "        fS=0",
        "        FOR nI=1 TO nK",
        "          fS=fS+fB[nI,nA]*fRes[nI]",
        "        ENDFOR",
        "        fH[nA,nR+1]=fS",
        "      ENDFOR",
        "      SOLVE_NORMAL(nR)",
        "      IF nResult<>0 THEN",
        "        RETURN",
        "      ENDIF",
        "      ; the step -V y: translation at the pivot, rotation vector times fScale",
        "      fBig=0",
        "      FOR nM=1 TO 6",
        "        fS=0",
        "        FOR nC=1 TO nR",
        "          fS=fS-fBasis[nU,nM,nC]*fY[nC]",
        "        ENDFOR",
        "        fStep[nM]=fS",
        "        IF ABS(fS)>fBig THEN",
        "          fBig=ABS(fS)",
        "        ENDIF",
        "      ENDFOR",
        "      fWx=fStep[4]/fScale",
        "      fWy=fStep[5]/fScale",
        "      fWz=fStep[6]/fScale",
        "      ; the motion [R(w), t - w x c] as a frame: Rodrigues' formula, then A, B, C",
        "      xMove=$NULLFRAME",
        "      xMove.X=fStep[1]-(fWy*xPivot.Z-fWz*xPivot.Y)",
        "      xMove.Y=fStep[2]-(fWz*xPivot.X-fWx*xPivot.Z)",
        "      xMove.Z=fStep[3]-(fWx*xPivot.Y-fWy*xPivot.X)",
        "      fTh=SQRT(fWx*fWx+fWy*fWy+fWz*fWz)",
        "      IF fTh<0.00000001 THEN",
        "        fSn=1-fTh*fTh/6",
        "        fCs=0.5-fTh*fTh/24",
        "      ELSE",
        "        fSn=SIN(fTh*fDeg)/fTh",
        "        fCs=(1-COS(fTh*fDeg))/(fTh*fTh)",
        "      ENDIF",
        "      fR11=1+fCs*(fWx*fWx-fTh*fTh)",
        "      fR21=fSn*fWz+fCs*fWx*fWy",
        "      fR31=fCs*fWx*fWz-fSn*fWy",
        "      fR32=fSn*fWx+fCs*fWy*fWz",
        "      fR33=1+fCs*(fWz*fWz-fTh*fTh)",
        "      xMove.A=ATAN2(fR21,fR11)",
        "      xMove.B=ATAN2(-fR31,SQRT(fR11*fR11+fR21*fR21))",
        "      xMove.C=ATAN2(fR32,fR33)",
        f"      {WOBJ}={WOBJ}:xMove",
        f"      IF fBig<{fmt(STEP_TOL_M * 1000.0, 9)} THEN",
        "        bDone=TRUE",
        "      ENDIF",
        "    ENDIF",
        "  ENDFOR",
        f"  $BASE={WOBJ}",
        "END",
        "",
    ]


def steer_body(job: ExportJob, program: MeasuringProgram, names: list[str]) -> list[str]:
    """The measuring routine's body: each point's probe in the program's order, a point not
    measured stops the program (nothing to steer by), and the updates between."""
    index = {t.point_id: i for i, t in enumerate(job.targets)}
    updates = iter(update_bases(program))
    pad = "  "
    lines: list[str] = []
    n_update = 0
    for step in program.steps:
        if isinstance(step, SearchStep) and step.recorded:
            i = index[step.point_id]
            lines += probe_call(names[i], i + 1, pad)
        elif isinstance(step, UpdateStep) and step.uses:
            k, _V = next(updates)
            n_update += 1
            lines += [f"{pad}STEER({k},{n_update})", *stop_lines(pad)]
    return lines
