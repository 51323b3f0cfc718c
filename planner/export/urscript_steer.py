"""An adaptive best-fit or 3-2-1 program in URScript: the frame update between searches.

The program measures its points in the order of its steps, each search in ``wobj``, and after
the points an update names it moves ``wobj`` by the smallest motion that puts them on their
nominal faces (:mod:`planner.program.steering`, the same iteration as
:mod:`planner.export.rapid_steer`): Gauss-Newton on the residuals ``n . (x - p)`` of the
measured points ``x`` (wobj frame, m), rotations about the layout's centroid ``st_pivot`` (wobj,
m) scaled by its RMS size ``st_scale`` (m), the step restricted to the motions the nominal
points fix (the update's basis, precomputed by :func:`planner.program.steering.update_basis`
and written as constants in ``st_basis``). After the last point the update uses them all:
``wobj`` is then the calibrated work object, the frame ``wobjcal calibrate`` computes from the
same points.

Per iteration ``steer`` builds the Jacobian rows ``-[n, (x - c) x n / L]``, ``B = J V`` and
solves ``(B^T B) y = B^T r`` (``solve_normal``: Gauss-Jordan with partial pivoting, at most
6 x 6); the step is ``-V y`` (translation at the centroid, rotation vector times ``L``),
applied as ``wobj = pose_trans(wobj, p[t - w x c, w])`` (a URScript pose's rotation is a
rotation vector: ``p[.., w]`` is the exact rotation ``exp(w)``). It stops after
:data:`~planner.program.steering.ITERATIONS` iterations or a step below
:data:`~planner.program.steering.STEP_TOL_M`, as
:func:`calib.estimators.runners.min_norm_update` does.
"""

from __future__ import annotations

from planner.export.job import ExportJob
from planner.export.text import comment_text
from planner.export.urscript_layout import SearchCalls, adaptive_program
from planner.export.urscript_probe import num, nums
from planner.program.model import MeasuringProgram, SearchStep, UpdateStep
from planner.program.steering import ITERATIONS, STEP_TOL_M, update_bases

#: A pivot below this in the normal equations: the points fix no frame (as RAPID's).
PIVOT_TOL = 1e-12


def steer_procs(job: ExportJob, program: MeasuringProgram) -> list[str]:
    """The layout's and the updates' constants, ``solve_normal`` and ``steer``."""
    calls = SearchCalls(job, program)
    order = calls.slots
    by_id = {rp.point.id: rp.point for rp in program.points}
    normals: list[float] = []
    nominal: list[float] = []
    for t in job.targets:
        p = by_id[t.point_id]
        normals += [float(v) for v in p.normal]
        nominal += [float(v) for v in p.position_m]
    basis: list[float] = []
    for _k, V in update_bases(program):
        basis += [float(v) for v in V.ravel()]  # row-major: 6 rows of r
    if program.pivot_m is None:
        raise ValueError(f"{program.name}: a steered program without a pivot")
    n = len(job.targets)
    zeros6n = nums([0.0] * (6 * n))
    return [
        f"  # {comment_text(program.name)}: the frame update between searches "
        "(planner.program.steering), wobj frame, m",
        f"  st_order = [{', '.join(str(i) for i in order)}]  # the slot of the k-th point measured",
        f"  st_normal = {nums(normals)}  # each slot's unit outward face normal",
        f"  st_nominal = {nums(nominal)}  # each slot's nominal point, m",
        f"  st_pivot = {nums([float(v) for v in program.pivot_m])}  # rotations turn about it, m",
        f"  st_scale = {num(program.scale_m)}  # rotations are scaled by it, m",
        "  # each update's basis of the motions its nominal points fix, 6 rows of r (row-major),",
        "  # one update after the other",
        f"  st_basis = {nums(basis)}",
        "  # solve h (r x (r + 1), row-major, the last column the right-hand side) for y:",
        "  # Gauss-Jordan with partial pivoting",
        "  def solve_normal(h, r):",
        "    y = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]",
        "    c = 0",
        "    while c < r:",
        "      piv = c",
        "      big = norm(h[(r + 1) * c + c])",
        "      i = c + 1",
        "      while i < r:",
        "        if norm(h[(r + 1) * i + c]) > big:",
        "          piv = i",
        "          big = norm(h[(r + 1) * i + c])",
        "        end",
        "        i = i + 1",
        "      end",
        f"      if big < {num(PIVOT_TOL, 15)}:",
        '        stop_procedure("frame update: the points measured so far fix no frame")',
        "      end",
        "      m = 0",
        "      while m < r + 1:",
        "        tmp = h[(r + 1) * c + m]",
        "        h[(r + 1) * c + m] = h[(r + 1) * piv + m]",
        "        h[(r + 1) * piv + m] = tmp",
        "        m = m + 1",
        "      end",
        "      i = 0",
        "      while i < r:",
        "        if i != c:",
        "          f = h[(r + 1) * i + c] / h[(r + 1) * c + c]",
        "          m = c",
        "          while m < r + 1:",
        "            h[(r + 1) * i + m] = h[(r + 1) * i + m] - f * h[(r + 1) * c + m]",
        "            m = m + 1",
        "          end",
        "        end",
        "        i = i + 1",
        "      end",
        "      c = c + 1",
        "    end",
        "    c = 0",
        "    while c < r:",
        "      y[c] = h[(r + 1) * c + r] / h[(r + 1) * c + c]",
        "      c = c + 1",
        "    end",
        "    return y",
        "  end",
        "  # move wobj by the smallest motion that puts the first k points of st_order on their",
        f"  # faces: Gauss-Newton, at most {ITERATIONS} iterations, until a step is below "
        f"{num(STEP_TOL_M, 12)} m; the",
        "  # step restricted to the update's basis st_basis[off .. off + 6 r - 1] (6 rows of r)",
        "  def steer(k, off, r):",
        "    global wobj",
        f"    jac = {zeros6n}",
        f"    res = {nums([0.0] * n)}",
        f"    b = {zeros6n}",
        f"    h = {nums([0.0] * 42)}",
        "    it = 0",
        "    done = False",
        f"    while (it < {ITERATIONS}) and (not done):",
        "      # the residuals n . (x - p) and the Jacobian rows -[n, (x - c) x n / L]",
        "      i = 0",
        "      while i < k:",
        "        j = st_order[i]",
        "        x = pose_trans(pose_inv(wobj), p[measured[3 * j], measured[3 * j + 1], "
        "measured[3 * j + 2], 0, 0, 0])",
        "        nx = st_normal[3 * j]",
        "        ny = st_normal[3 * j + 1]",
        "        nz = st_normal[3 * j + 2]",
        "        res[i] = nx * (x[0] - st_nominal[3 * j]) + ny * (x[1] - st_nominal[3 * j + 1]) "
        "+ nz * (x[2] - st_nominal[3 * j + 2])",
        "        dx = x[0] - st_pivot[0]",
        "        dy = x[1] - st_pivot[1]",
        "        dz = x[2] - st_pivot[2]",
        "        jac[6 * i] = -nx",
        "        jac[6 * i + 1] = -ny",
        "        jac[6 * i + 2] = -nz",
        "        jac[6 * i + 3] = -(dy * nz - dz * ny) / st_scale",
        "        jac[6 * i + 4] = -(dz * nx - dx * nz) / st_scale",
        "        jac[6 * i + 5] = -(dx * ny - dy * nx) / st_scale",
        "        i = i + 1",
        "      end",
        "      # B = J V (k x r)",
        "      i = 0",
        "      while i < k:",
        "        c = 0",
        "        while c < r:",
        "          s = 0.0",
        "          m = 0",
        "          while m < 6:",
        "            s = s + jac[6 * i + m] * st_basis[off + r * m + c]",
        "            m = m + 1",
        "          end",
        "          b[r * i + c] = s",
        "          c = c + 1",
        "        end",
        "        i = i + 1",
        "      end",
        "      # the normal equations B^T B y = B^T res, augmented",
        "      a = 0",
        "      while a < r:",
        "        c = 0",
        "        while c < r:",
        "          s = 0.0",
        "          i = 0",
        "          while i < k:",
        "            s = s + b[r * i + a] * b[r * i + c]",
        "            i = i + 1",
        "          end",
        "          h[(r + 1) * a + c] = s",
        "          c = c + 1",
        "        end",
        "        s = 0.0",
        "        i = 0",
        "        while i < k:",
        "          s = s + b[r * i + a] * res[i]",
        "          i = i + 1",
        "        end",
        "        h[(r + 1) * a + r] = s",
        "        a = a + 1",
        "      end",
        "      y = solve_normal(h, r)",
        "      # the step -V y: translation at the pivot, rotation vector times st_scale",
        "      step = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]",
        "      big = 0.0",
        "      m = 0",
        "      while m < 6:",
        "        s = 0.0",
        "        c = 0",
        "        while c < r:",
        "          s = s - st_basis[off + r * m + c] * y[c]",
        "          c = c + 1",
        "        end",
        "        step[m] = s",
        "        if norm(s) > big:",
        "          big = norm(s)",
        "        end",
        "        m = m + 1",
        "      end",
        "      wx = step[3] / st_scale",
        "      wy = step[4] / st_scale",
        "      wz = step[5] / st_scale",
        "      # wobj := wobj [exp(w), t - w x c]: the motion about the pivot in wobj's own axes",
        "      wobj = pose_trans(wobj, p[step[0] - (wy * st_pivot[2] - wz * st_pivot[1]), "
        "step[1] - (wz * st_pivot[0] - wx * st_pivot[2]), "
        "step[2] - (wx * st_pivot[1] - wy * st_pivot[0]), wx, wy, wz])",
        f"      if big < {num(STEP_TOL_M, 12)}:",
        "        done = True",
        "      end",
        "      it = it + 1",
        "    end",
        "  end",
    ]


def steer_main(job: ExportJob, program: MeasuringProgram) -> list[str]:
    """The main body: each point's searches in the program's order (a failed search stops
    the program: nothing to steer by), and the updates between."""
    calls = SearchCalls(job, program)
    steps = iter(update_bases(program))
    off = 0
    lines = [f"  # {comment_text(program.name)}: each search in wobj, the frame estimated so far"]
    for step in program.steps:
        if isinstance(step, SearchStep) and step.recorded:
            lines += calls.next(step)
        elif isinstance(step, UpdateStep) and step.uses:
            k, V = next(steps)
            r = V.shape[1]
            lines.append(f"  steer({k}, {off}, {r})")
            off += 6 * r
    lines.append('  textmsg("wobjcal: done, wobj (not screened: run wobjcal calibrate): ", wobj)')
    return lines


def export_steered(job: ExportJob, program: MeasuringProgram) -> str:
    """The adaptive best-fit or 3-2-1 program of ``job`` (module docstring)."""
    computes = (
        f"the {program.method_label} frame, on the controller: after the points each update "
        "names, wobj is moved by the smallest motion that puts the points measured so far on "
        f"their nominal faces (Gauss-Newton, at most {ITERATIONS} iterations, until a step is "
        f"below {STEP_TOL_M * 1000.0:g} mm; rotations about the layout's centroid st_pivot "
        "scaled by its RMS size st_scale; the step restricted to the motions the nominal "
        "points fix, st_basis), so each search is commanded in the frame estimated so far. "
        "After the last point wobj holds the frame `wobjcal calibrate` computes from the same "
        "points, NOT YET SCREENED for gross errors: use it only once `wobjcal calibrate` "
        "trusts it. A failed search stops the program (halt); "
        "the points measured before it stay in measured and meas_<ID>."
    )
    return adaptive_program(
        job, program, computes, steer_procs(job, program), steer_main(job, program)
    )
