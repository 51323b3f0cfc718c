"""The paper's x-offset run (section 3.2, eq. 13-14) in the adaptive A-H URScript program.

After the A-H procedure has calibrated ``wobj``, the side face is measured over every second
tooth at two slot-hole levels (:func:`calib.paper.xoffset.xoffset_probe_points`): each search
runs along -x of ``wobj`` from ``xo_start`` outside the calibrated face (``ah_face[0]``) to
``xo_over`` past it, with D's orientation and speed; the points are kept in the wobj frame
(``px_meas``, m, level by level). ``xoffset_at(y, z)`` is eq. 14: the x on the plane through the
measurements ``PX[k, l]``, ``PX[k, l + 1]``, ``PX[k + 1, l]`` of the levels and teeth bracketing
``(y, z)`` (the end pair outside them: extrapolation), as
:func:`calib.paper.xoffset.xoffset_matrix` and the RAPID ``XOffsetAt``; ``x_offset_run`` fills
the matrix ``mx_w[(layer - 1) * xo_slots + slot - 1]`` (m, wobj) of eq. 13, and
``slot_target(slot, layer, standoff)`` is the paper's target function: the pose at a slot hole
in the wobj frame (its y and z, the matrix's x plus ``standoff`` m along +x, D's orientation;
move there with ``pose_trans(wobj, slot_target(...))``). A search that finds nothing stops the
program naming the point (``PX<level>_<tooth>``, 1-based).
"""

from __future__ import annotations

from calib.frames import rotvec_from_matrix
from calib.paper.settings import XOffsetRun
from calib.paper.xoffset import xoffset_probe_points
from planner.export.job import ExportJob
from planner.export.text import fmt
from planner.export.urscript_probe import MOVEJ, MOVEL, num, nums

#: Two measurements whose (y, z) span less than this area (m^2) give no plane (RAPID's 1E-6 mm^2).
DET_TOL_M2 = 1e-12


def _run(job: ExportJob) -> XOffsetRun | None:
    return None if job.adaptive is None else job.adaptive.settings.xoffset


def xoffset_procs(job: ExportJob) -> list[str]:
    """The x-offset run's data and functions (module docstring); ``[]`` without one."""
    run = _run(job)
    if run is None or job.adaptive is None:
        return []
    grid = run.grid
    rows = xoffset_probe_points(grid, run.layers, run.teeth)
    k_n, l_n = len(rows), len(rows[0])
    ys = [float(p.position_m[1]) for p in rows[0]]
    zs = [float(row[0].position_m[2]) for row in rows]
    d = job.targets[job.adaptive.index["D"]]
    rv = ", ".join(num(float(v), 9) for v in rotvec_from_matrix(d.T_wobj_start[:3, :3]))
    nx = grid.n_slots * grid.n_layers
    return [
        "  # x-offset run (section 3.2, eq. 13-14): PX over the teeth (px_y) at the levels",
        "  # (px_z), searched along -x of wobj with D's orientation (wobj, m)",
        f"  xo_levels = {k_n}",
        f"  xo_teeth = {l_n}",
        f"  px_y = {nums(ys)}",
        f"  px_z = {nums(zs)}",
        f"  xo_start = {num(run.start_offset_m)}",
        f"  xo_over = {num(run.overtravel_m)}",
        f"  xo_slots = {grid.n_slots}",
        f"  xo_layers = {grid.n_layers}",
        f"  slot_y = {nums([float(v) for v in grid.slot_y_m])}",
        f"  layer_z = {nums([float(v) for v in grid.layer_z_m])}",
        f"  px_meas = {nums([0.0] * (3 * k_n * l_n))}",
        "  # mx_w[(layer - 1) * xo_slots + slot - 1]: the x-offset of each slot hole (m, wobj)",
        f"  mx_w = {nums([0.0] * nx)}",
        "  # one x-offset search: level k, tooth l (0-based); the point kept in px_meas (wobj)",
        "  def probe_px(k, l):",
        "    global px_meas",
        f"    s = p[ah_face[0] + xo_start, px_y[l], px_z[k], {rv}]",
        f"    e = p[ah_face[0] - xo_over, px_y[l], px_z[k], {rv}]",
        f"    movej(pose_trans(wobj, s), {MOVEJ})",
        f"    result = run_search(pose_trans(wobj, e), True, {fmt(d.speed_m_s, 6)})",
        "    if result[0] != 0.0:",
        f"      movel(pose_trans(wobj, s), {MOVEL})",
        '      stop_procedure(str_cat(str_cat("x-offset point PX", to_str(k + 1)), '
        'str_cat(str_cat("_", to_str(l + 1)), " not found")))',
        "    end",
        "    w = pose_trans(pose_inv(wobj), p[result[1], result[2], result[3], 0, 0, 0])",
        "    px_meas[3 * (k * xo_teeth + l)] = w[0]",
        "    px_meas[3 * (k * xo_teeth + l) + 1] = w[1]",
        "    px_meas[3 * (k * xo_teeth + l) + 2] = w[2]",
        f"    movel(pose_trans(wobj, s), {MOVEL})",
        "  end",
        "  # eq. 14: x at (y, z) on the plane through PX[k, l], PX[k, l + 1], PX[k + 1, l], the",
        "  # levels and teeth bracketing (y, z) (the end pair outside them: extrapolation)",
        "  def xoffset_at(y, z):",
        "    k = 0",
        "    l = 0",
        "    sk = 1.0",
        "    sl = 1.0",
        "    if px_meas[3 * xo_teeth + 2] < px_meas[2]:",
        "      sk = -1.0",
        "    end",
        "    m = 1",
        "    while m < xo_levels - 1:",
        "      if sk * px_meas[3 * m * xo_teeth + 2] <= sk * z:",
        "        k = m",
        "      end",
        "      m = m + 1",
        "    end",
        "    if px_meas[3 * (k * xo_teeth + 1) + 1] < px_meas[3 * k * xo_teeth + 1]:",
        "      sl = -1.0",
        "    end",
        "    m = 1",
        "    while m < xo_teeth - 1:",
        "      if sl * px_meas[3 * (k * xo_teeth + m) + 1] <= sl * y:",
        "        l = m",
        "      end",
        "      m = m + 1",
        "    end",
        "    i0 = 3 * (k * xo_teeth + l)",
        "    i1 = 3 * (k * xo_teeth + l + 1)",
        "    i2 = 3 * ((k + 1) * xo_teeth + l)",
        "    d1 = [px_meas[i1] - px_meas[i0], px_meas[i1 + 1] - px_meas[i0 + 1], "
        "px_meas[i1 + 2] - px_meas[i0 + 2]]",
        "    d2 = [px_meas[i2] - px_meas[i0], px_meas[i2 + 1] - px_meas[i0 + 1], "
        "px_meas[i2 + 2] - px_meas[i0 + 2]]",
        "    det = d1[1] * d2[2] - d1[2] * d2[1]",
        f"    if norm(det) < {num(DET_TOL_M2, 15)}:",
        '      stop_procedure("x-offset points span no plane")',
        "    end",
        "    return px_meas[i0] + (y - px_meas[i0 + 1]) * (d1[0] * d2[2] - d1[2] * d2[0]) / det "
        "+ (z - px_meas[i0 + 2]) * (d1[1] * d2[0] - d1[0] * d2[1]) / det",
        "  end",
        "  # measure the PX points and fill the x-offset matrix",
        "  def x_offset_run():",
        "    global mx_w",
        "    k = 0",
        "    while k < xo_levels:",
        "      l = 0",
        "      while l < xo_teeth:",
        "        probe_px(k, l)",
        "        l = l + 1",
        "      end",
        "      k = k + 1",
        "    end",
        "    i = 0",
        "    while i < xo_layers:",
        "      j = 0",
        "      while j < xo_slots:",
        "        mx_w[i * xo_slots + j] = xoffset_at(slot_y[j], layer_z[i])",
        "        j = j + 1",
        "      end",
        "      i = i + 1",
        "    end",
        "  end",
        "  # the pose at a slot hole (slot, layer 1-based; standoff m along +x), wobj frame",
        "  def slot_target(slot, layer, standoff):",
        "    return p[mx_w[(layer - 1) * xo_slots + slot - 1] + standoff, slot_y[slot - 1], "
        f"layer_z[layer - 1], {rv}]",
        "  end",
    ]


def xoffset_main(job: ExportJob) -> list[str]:
    """The main-body lines of the x-offset run (``[]`` without one)."""
    if _run(job) is None:
        return []
    return [
        "  # 10: the x-offset run over every second tooth at two slot-hole levels, in the",
        "  #     calibrated frame, and the x-offset matrix (eq. 13-14)",
        "  x_offset_run()",
        '  textmsg("wobjcal: x-offset run done: mx_w holds the x-offset of every slot hole")',
    ]
