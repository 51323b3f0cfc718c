"""The x-offset run of the adaptive A-H program in KUKA KRL (paper section 3.2, eq. 13-14).

After the A-H steps, with ``BASE_DATA[10]`` the calibrated work object, the program measures
the side face over every second tooth at two slot-hole levels (``PROBE_PX``: from ``fPxStart``
outside the face along ``-x`` of ``BASE_DATA[10]`` to ``fPxOver`` past it, with D's
orientation; ``xPxMeas[level,tooth]``, wobj frame, mm), computes the x-offset matrix of eq.
13-14 (``fMxW[layer,slot]``, mm: the plane interpolation of :func:`calib.paper.xoffset.
xoffset_matrix`, as the RAPID ``XOffsetAt``) and offers ``SLOT_TARGET(slot, layer, standoff)``,
the paper's function returning the robot target at a slot hole (its y and z, the matrix's x
plus the standoff, in ``BASE_DATA[10]``). A search that finds nothing stops the run
(``nResult`` 4, ``nStopAt`` its number ``(level-1)*nPxTeeth+tooth``; the frame stays the
calibrated one); measurements that span no plane stop it with ``nResult`` 3.
"""

from __future__ import annotations

import numpy as np

from calib.paper.settings import XOffsetRun
from calib.paper.xoffset import xoffset_probe_points
from planner.export.job import ExportJob
from planner.export.krl_text import WOBJ, array_lines
from planner.export.text import fmt


def _run(job: ExportJob) -> XOffsetRun | None:
    a = job.adaptive
    return None if a is None else a.settings.xoffset


def has_xoffset(job: ExportJob) -> bool:
    """Whether the job's A-H plan has an x-offset run."""
    return _run(job) is not None


def xoffset_data(job: ExportJob) -> list[str]:
    """The data-list lines of the run: the levels and teeth measured, the slot grid, and the
    measurements and matrix it fills (mm, wobj); ``[]`` without a run."""
    run = _run(job)
    if run is None:
        return []
    grid = run.grid
    rows = xoffset_probe_points(grid, run.layers, run.teeth)
    k_n, l_n = len(rows), len(rows[0])
    ys = np.array([p.position_m[1] for p in rows[0]]) * 1e3
    zs = np.array([row[0].position_m[2] for row in rows]) * 1e3
    return [
        "; x-offset run (section 3.2, eq. 13-14): PX over the teeth (fPxY) at the levels (fPxZ),",
        f"; searched along -x of {WOBJ}; fMxW[layer,slot] is the x-offset of each slot hole",
        "; (mm, wobj)",
        f"DECL INT nPxLevels={k_n}",
        f"DECL INT nPxTeeth={l_n}",
        *array_lines("REAL", "fPxY", ys, 4),
        *array_lines("REAL", "fPxZ", zs, 4),
        f"DECL REAL fPxStart={fmt(run.start_offset_m * 1000.0, 4)}",
        f"DECL REAL fPxOver={fmt(run.overtravel_m * 1000.0, 4)}",
        f"DECL INT nSlots={grid.n_slots}",
        f"DECL INT nLayers={grid.n_layers}",
        *array_lines("REAL", "fSlotY", np.asarray(grid.slot_y_m) * 1e3, 4),
        *array_lines("REAL", "fLayerZ", np.asarray(grid.layer_z_m) * 1e3, 4),
        f"DECL FRAME xPxMeas[{k_n},{l_n}]",
        f"DECL REAL fMxW[{grid.n_layers},{grid.n_slots}]",
    ]


def xoffset_routines(job: ExportJob, names: list[str]) -> list[str]:
    """``PROBE_PX``, ``XOFFSET_AT``, ``XOFFSET_RUN`` and ``SLOT_TARGET``; ``[]`` without a
    run."""
    a = job.adaptive
    if a is None or a.settings.xoffset is None:
        return []
    d = names[a.index["D"]]
    v = fmt(job.targets[a.index["D"]].speed_m_s, 6)
    return [
        "; One x-offset search: level nK, tooth nL, along -x of the work object with D's",
        "; orientation; the point is kept in the wobj (xPxMeas, mm); nResult 4 when not found",
        "DEF PROBE_PX(nK:IN,nL:IN)",
        "  DECL INT nK,nL",
        "  DECL E6POS xPxFrom,xPxTo",
        f"  xPxFrom={d}_start",
        "  xPxFrom.X=fFaceX+fPxStart",
        "  xPxFrom.Y=fPxY[nL]",
        "  xPxFrom.Z=fPxZ[nK]",
        "  xPxTo=xPxFrom",
        "  xPxTo.X=fFaceX-fPxOver",
        "  $VEL.CP=0.1",
        "  PTP xPxFrom",
        "  bHit=FALSE",
        "  IF diSensor==FALSE THEN",
        f"    SEARCH_RISE(xPxTo,{v})",
        "  ENDIF",
        "  IF bHit THEN",
        "    xPxMeas[nK,nL]=xHit",
        "  ELSE",
        "    nResult=4",
        "    nStopAt=(nK-1)*nPxTeeth+nL",
        "  ENDIF",
        "  $VEL.CP=0.1",
        "  LIN xPxFrom",
        "END",
        "",
        "; Eq. 14: x at (fYq, fZq) on the plane through PX[k,l], PX[k,l+1], PX[k+1,l], the levels",
        "; and teeth bracketing (y, z) (the end pair outside them: extrapolation); nResult 3 when",
        "; they span no plane",
        "DEFFCT REAL XOFFSET_AT(fYq:IN,fZq:IN)",
        "  DECL REAL fYq,fZq",
        "  DECL INT nK,nL,nSk,nSl,nM",
        "  DECL REAL fDet,fD1x,fD1y,fD1z,fD2x,fD2y,fD2z,fSy,fSz",
        "  DECL FRAME xP0",
        "  nK=1",
        "  nL=1",
        "  nSk=1",
        "  nSl=1",
        "  IF xPxMeas[2,1].Z<xPxMeas[1,1].Z THEN",
        "    nSk=-1",
        "  ENDIF",
        "  FOR nM=2 TO nPxLevels-1",
        "    IF nSk*xPxMeas[nM,1].Z<=nSk*fZq THEN",
        "      nK=nM",
        "    ENDIF",
        "  ENDFOR",
        "  IF xPxMeas[nK,2].Y<xPxMeas[nK,1].Y THEN",
        "    nSl=-1",
        "  ENDIF",
        "  FOR nM=2 TO nPxTeeth-1",
        "    IF nSl*xPxMeas[nK,nM].Y<=nSl*fYq THEN",
        "      nL=nM",
        "    ENDIF",
        "  ENDFOR",
        "  xP0=xPxMeas[nK,nL]",
        "  fD1x=xPxMeas[nK,nL+1].X-xP0.X",
        "  fD1y=xPxMeas[nK,nL+1].Y-xP0.Y",
        "  fD1z=xPxMeas[nK,nL+1].Z-xP0.Z",
        "  fD2x=xPxMeas[nK+1,nL].X-xP0.X",
        "  fD2y=xPxMeas[nK+1,nL].Y-xP0.Y",
        "  fD2z=xPxMeas[nK+1,nL].Z-xP0.Z",
        "  fDet=fD1y*fD2z-fD1z*fD2y",
        "  IF ABS(fDet)<0.000001 THEN",
        "    nResult=3",
        "    RETURN 0",
        "  ENDIF",
        "  fSy=(fD1x*fD2z-fD1z*fD2x)/fDet ; the slope along y",
        "  fSz=(fD1y*fD2x-fD1x*fD2y)/fDet ; the slope along z",
        "  RETURN xP0.X+(fYq-xP0.Y)*fSy+(fZq-xP0.Z)*fSz",
        "ENDFCT",
        "",
        "; Measure the PX points and fill the x-offset matrix",
        "DEF XOFFSET_RUN()",
        "  DECL INT nK,nL",
        "  FOR nK=1 TO nPxLevels",
        "    FOR nL=1 TO nPxTeeth",
        "      PROBE_PX(nK,nL)",
        "      IF nResult<>0 THEN",
        "        RETURN",
        "      ENDIF",
        "    ENDFOR",
        "  ENDFOR",
        "  FOR nK=1 TO nLayers",
        "    FOR nL=1 TO nSlots",
        "      fMxW[nK,nL]=XOFFSET_AT(fSlotY[nL],fLayerZ[nK])",
        "      IF nResult<>0 THEN",
        "        RETURN",
        "      ENDIF",
        "    ENDFOR",
        "  ENDFOR",
        "END",
        "",
        "; The robot target at a slot hole (section 3.2): its y and z, the x-offset matrix's x",
        f"; plus fStandoff (mm, along +x of the work object), with D's orientation, in {WOBJ}",
        "DEFFCT E6POS SLOT_TARGET(nSlot:IN,nLayer:IN,fStandoff:IN)",
        "  DECL INT nSlot,nLayer",
        "  DECL REAL fStandoff",
        "  DECL E6POS xSlot",
        f"  xSlot={d}_start",
        "  xSlot.X=fMxW[nLayer,nSlot]+fStandoff",
        "  xSlot.Y=fSlotY[nSlot]",
        "  xSlot.Z=fLayerZ[nLayer]",
        "  RETURN xSlot",
        "ENDFCT",
        "",
    ]
