"""Throughput of probe feasibility, both units, both sides in one run.

Two units, as issue 11 words them:

- **poses/s**: a probe *pose* is a TCP target with its sensor rotation fixed (here the rotation
  0 of :func:`planner.cell.probe.feasibility.tcp_frames`: ``rotation_step_deg=360``), decided for IK
  (every branch), limits, singularity and collision with 5 mm clearance against the part and
  the table, and self-collision: the first passing branch in the product's order, else the
  least-bad one, with a reason.
- **points/s**: a probe *point* with the search over 24 sensor rotations (15 deg) and all their
  branches: what ``wobjcal check``, the UI's click and the reachability map do.

References, on the same points in the same run:

- *the plain loop, same decisions*: one ``check_probes(..., staged=False)`` call per pose or
  point: the IK of that one target, then one whole Bullet clearance query per candidate
  (``getClosestPoints`` of every robot and tool link against part and table, and of every
  self pair not in the allowed-collision list), in the product's order, first passing one
  wins. Its answers are compared with ours (any difference is counted).
- *the PyBullet-IK loop* (points only, :func:`bench.feasibility_cell.run_plain_loop`): the
  reference of the issue's first figures: PyBullet's numeric IK from home, one branch, no
  self-collision, no reasons. It does less work and different decisions: shown for continuity.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from bench.feasibility_cell import run_plain_loop
from planner.cell.cell import Cell

#: ``rotation_step_deg`` that leaves one rotation: a pose.
POSE_STEP_DEG = 360.0


def timed_best(
    cell: Cell, pts: np.ndarray, nrm: np.ndarray, repeat: int, **kw: Any
) -> tuple[list, float]:
    """``check_probes`` on the batch ``repeat`` times: the answers and the fastest seconds."""
    res, best, _ = timed_best_cpu(cell, pts, nrm, repeat, **kw)
    return res, best


def timed_best_cpu(
    cell: Cell, pts: np.ndarray, nrm: np.ndarray, repeat: int, **kw: Any
) -> tuple[list, float, float]:
    """:func:`timed_best` and the least CPU seconds of this process over the runs (the work is
    single-threaded: on an idle machine the two agree; other jobs inflate the wall time more)."""
    best, cpu, res = np.inf, np.inf, []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        res = cell.check_probes(pts, nrm, **kw)
        best = min(best, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    return res, best, cpu


def one_per_call(
    cell: Cell, pts: np.ndarray, nrm: np.ndarray, repeat: int, **kw: Any
) -> tuple[list, float]:
    """The plain loop: one exact ``check_probes(staged=False)`` call per target; the answers
    and the fastest of ``repeat`` runs, seconds (timed like ours, so that load changes on
    this shared machine touch both sides alike)."""
    best, res = np.inf, []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = [cell.check_probes(pts[i : i + 1], nrm[i : i + 1], staged=False, **kw)[0]
               for i in range(len(pts))]  # fmt: skip
        best = min(best, time.perf_counter() - t0)
    return res, best


def answer_key(r: Any) -> tuple:
    """What must agree: status, reason, branch, rotation, pair, clearance (1e-6 m)."""
    rot = None if np.isnan(r.rotation_rad) else round(float(r.rotation_rad), 9)
    cl = None if np.isnan(r.clearance_m) else round(float(r.clearance_m) * 1e6)
    return (r.status, r.reason, r.branch, rot, r.clearance_pair, cl)


def disagreements(ours: list, exact: list) -> list[int]:
    """Indices where the answers differ (see :func:`answer_key`; clearance within 1e-6 m)."""
    out = []
    for i, (a, b) in enumerate(zip(ours, exact)):
        same = answer_key(a)[:5] == answer_key(b)[:5]
        ca, cb = a.clearance_m, b.clearance_m
        same = same and ((np.isnan(ca) and np.isnan(cb)) or abs(ca - cb) <= 1e-6)
        if not same:
            out.append(i)
    return out


def _side(
    cell: Cell, pts: np.ndarray, nrm: np.ndarray, k: int, repeat: int, **kw: Any
) -> dict[str, object]:
    """Ours on all targets and on the first ``k``; the plain loop on those ``k``."""
    n = len(pts)
    ours, dt, cpu = timed_best_cpu(cell, pts, nrm, repeat, **kw)
    ours_k, dt_k = timed_best(cell, pts[:k], nrm[:k], repeat, **kw)
    loop, dt_loop = one_per_call(cell, pts[:k], nrm[:k], repeat, **kw)
    status = [r.status for r in ours]
    return {
        "n": n,
        "ours_per_s": n / dt,
        "ours_per_cpu_s": n / cpu,
        "status_counts": {s: status.count(s) for s in ("feasible", "marginal", "infeasible")},
        "loop_n": k,
        "ours_on_loop_targets_per_s": k / dt_k,
        "plain_loop_per_s": k / dt_loop,
        "ratio": dt_loop / dt_k,
        "loop_disagreements": len(disagreements(ours_k, loop)),
    }


def run_rates(
    cell: Cell, pts: np.ndarray, nrm: np.ndarray, loop_n: int, repeat: int
) -> dict[str, object]:
    """Poses/s and points/s, ours and the plain loops, on the same targets (module docstring)."""
    k = min(loop_n, len(pts))
    poses = _side(cell, pts, nrm, k, repeat, rotation_step_deg=POSE_STEP_DEG)
    points = _side(cell, pts, nrm, max(k // 2, 1), repeat)
    kp = int(points["loop_n"])  # type: ignore[call-overload]
    dt_pyb = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        pyb = run_plain_loop(cell, pts[:kp], nrm[:kp])
        dt_pyb = min(dt_pyb, time.perf_counter() - t0)
    points["pybullet_ik_loop_per_s"] = kp / dt_pyb
    points["pybullet_ik_loop_feasible"] = pyb["feasible"]
    points["ratio_vs_pybullet_ik_loop"] = dt_pyb / (kp / points["ours_on_loop_targets_per_s"])  # type: ignore[operator]
    return {"poses": poses, "points": points}
