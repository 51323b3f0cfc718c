"""Probe-pose feasibility checks per second on a ~100,000-triangle work object.

The built-in IRB 4400 with the cable-feeder tool faces a 0.8 x 0.6 x 0.4 m box subdivided into
114,688 triangles (a concave static PyBullet mesh). ``--n`` probe points are sampled uniformly by
area on its surface (seeded), with their face normals, and checked two ways in the same run:

1. wobjcal: ``cell.check_probes(points, normals)``: one batched analytic IK call for all points
   x 24 rotations about the sensor axis (every branch and 2*pi variant), limit and singularity
   filters, then batched ``getClosestPoints`` per body pair, best candidates first, with the
   allowed-collision list and the sensor standoff rule.
2. A plain loop, as one would write it with PyBullet alone: for each point and each of the same
   24 rotations, ``calculateInverseKinematics`` (tuned: ``jointDamping=[1e-3]*n``, 100
   iterations) from the home pose, reset the joints, accept when the flange lands within 1 mm /
   0.01 rad and the joints are within limits, then ``getClosestPoints`` of robot and tool
   against the work object (threshold = the 5 mm margin, sensor exempt down to contact); stop
   at the first rotation that passes. No self-collision check (it would only slow it down).

Reported: checks (points) per second of each, their ratio on the same points, how many points
each finds feasible, and the points where the two disagree (with our reason).

3. The worst case (:func:`run_worst_case`): in the demo cell (stator section on a table)
   ``--worst-n`` stator samples; the points whose every candidate collides are checked one
   per call (a UI click), staged and with one whole clearance query per candidate
   (``staged=False``: the check as it was), and by the plain loop; likewise the feasible
   points; then the heat map per sample. Ratios, and whether the answers are the same.

Run: ``python -m bench.bench_feasibility [--n 300] [--pybullet-n 100] [--seed 0] [--worst-n 40]``;
writes
``bench/results/feasibility.json``.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np
import pybullet as pb
import trimesh
from rich.console import Console
from rich.table import Table

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from calib.atomic_io import write_text_atomic
from calib.frames import invert_transform, make_transform
from planner.cell.bodies import pb_pose
from planner.cell.cell import Cell
from planner.cell.collision import DEFAULT_MARGIN_M
from planner.cell.feasibility import tcp_frames
from planner.cell.reachability_map import sample_surface

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench/results/feasibility.json"
T_WORLD_WOBJ = make_transform(p=[1.5, 0.0, 0.4])


def work_object() -> trimesh.Trimesh:
    """A 0.8 x 0.6 x 0.4 m box subdivided to 114,688 triangles."""
    return trimesh.creation.box([0.8, 0.6, 0.4]).subdivide_to_size(0.012)


def run_ours(cell: Cell, pts: np.ndarray, nrm: np.ndarray) -> dict[str, object]:
    cell.check_probes(pts[:2], nrm[:2])  # warm-up
    t0 = time.perf_counter()
    res = cell.check_probes(pts, nrm)
    dt = time.perf_counter() - t0
    status = [r.status for r in res]
    return {
        "per_point": [r.status != "infeasible" for r in res],
        "reasons": [r.reason for r in res],
        "n": len(res),
        "seconds": dt,
        "checks_per_s": len(res) / dt,
        "feasible": sum(s != "infeasible" for s in status),
        "status_counts": {s: status.count(s) for s in ("feasible", "marginal", "infeasible")},
    }


def run_plain_loop(cell: Cell, pts: np.ndarray, nrm: np.ndarray) -> dict[str, object]:
    c, robot, tool = cell.client, cell.robot.body_id, cell.tool_body
    wobj = cell.checker.wobj_body
    joints, flange = cell.joint_indices, cell.flange_index
    n = len(joints)
    sensor = {i for i, name in tool.names.items() if name in cell.tool.sensor_links}
    angles = np.radians(np.arange(0, 360, 15))
    T_world = (
        cell.T_world_wobj
        @ tcp_frames(pts, nrm, angles)
        @ invert_transform(cell.T_flange_tcp("sensor"))
    )
    lo, hi = cell.chain.lower, cell.chain.upper
    feasible = 0
    per_point = [False] * len(pts)
    t0 = time.perf_counter()
    for i in range(len(pts)):
        for r in range(angles.size):
            for j, v in zip(joints, cell.home_q):
                pb.resetJointState(robot, j, float(v), physicsClientId=c)
            pos, quat = pb_pose(T_world[i, r])
            q = np.array(
                pb.calculateInverseKinematics(
                    robot,
                    flange,
                    pos,
                    quat,
                    jointDamping=[1e-3] * n,
                    maxNumIterations=100,
                    residualThreshold=1e-10,
                    physicsClientId=c,
                )[:n]
            )
            if np.any(q < lo) or np.any(q > hi):
                continue
            for j, v in zip(joints, q):
                pb.resetJointState(robot, j, float(v), physicsClientId=c)
            state = pb.getLinkState(robot, flange, computeForwardKinematics=True, physicsClientId=c)
            if np.linalg.norm(np.subtract(state[4], pos)) > 1e-3:
                continue
            q_err = np.abs(np.subtract(state[5], quat)).max()
            q_err2 = np.abs(np.add(state[5], quat)).max()
            if min(q_err, q_err2) > 5e-3:
                continue
            tp, tq = state[4], state[5]
            off_p, off_q = pb.getDynamicsInfo(tool.body_id, -1, physicsClientId=c)[3:5]
            bp, bq = pb.multiplyTransforms(tp, tq, off_p, off_q)
            pb.resetBasePositionAndOrientation(tool.body_id, bp, bq, physicsClientId=c)
            hits = [
                p for p in pb.getClosestPoints(robot, wobj, DEFAULT_MARGIN_M, physicsClientId=c)
            ] + [
                p
                for p in pb.getClosestPoints(
                    tool.body_id, wobj, DEFAULT_MARGIN_M, physicsClientId=c
                )
                if not (p[3] in sensor and p[8] >= 0.0)
            ]
            if not hits:
                feasible += 1
                per_point[i] = True
                break
    dt = time.perf_counter() - t0
    return {
        "n": len(pts),
        "seconds": dt,
        "checks_per_s": len(pts) / dt,
        "feasible": feasible,
        "per_point": per_point,
    }


def _timed_points(cell: Cell, pts: np.ndarray, nrm: np.ndarray, staged: bool) -> dict:
    """Each point checked alone (one UI click each): per-point seconds and the answers."""
    seconds, answers = [], []
    for i in range(len(pts)):
        t0 = time.perf_counter()
        (r,) = cell.check_probes(pts[i : i + 1], nrm[i : i + 1], staged=staged)
        seconds.append(time.perf_counter() - t0)
        answers.append((r.status, r.reason))
    return {"seconds": seconds, "answers": answers}


def _summary(seconds: list[float]) -> dict[str, float]:
    s = np.asarray(seconds) * 1e3
    return {"median_ms": float(np.median(s)), "max_ms": float(s.max()), "mean_ms": float(s.mean())}


def run_worst_case(n_samples: int, seed: int, with_loop: bool) -> dict[str, object]:
    """The demo cell (stator on a table): points that collide in every candidate pose.

    ``n_samples`` points are sampled on the stator; those whose answer is a collision (every
    candidate collides: the slow case of a UI click) are the worst-case set, the feasible ones
    the typical set. Each point is checked alone, staged and with one whole query per
    candidate (``staged=False``, the check as it was), and by the plain PyBullet loop (which
    tries all 24 rotations before it gives up); then all samples as one heat-map batch.
    """
    from planner.cell.reachability_map import reachability_map
    from planner.demo import make_demo_cell

    with make_demo_cell() as cell:
        pts, nrm, _ = sample_surface(cell.work_object.mesh, n_samples, np.random.default_rng(seed))
        cell.check_probes(pts[:2], nrm[:2])  # warm-up
        first = _timed_points(cell, pts, nrm, staged=True)
        worst = [i for i, (_, why) in enumerate(first["answers"]) if " hits " in why]
        typical = [i for i, (st, _) in enumerate(first["answers"]) if st == "feasible"]
        out: dict[str, object] = {"samples": n_samples, "worst_points": len(worst)}
        for name, idx in (("worst", worst), ("typical", typical)):
            staged = _timed_points(cell, pts[idx], nrm[idx], staged=True)
            whole = _timed_points(cell, pts[idx], nrm[idx], staged=False)
            row = {"staged": _summary(staged["seconds"]), "whole_query": _summary(whole["seconds"])}
            row["same_answers"] = staged["answers"] == whole["answers"]
            row["ratio_median"] = row["whole_query"]["median_ms"] / row["staged"]["median_ms"]
            row["ratio_max"] = row["whole_query"]["max_ms"] / row["staged"]["max_ms"]
            if with_loop and idx:
                loop = run_plain_loop(cell, pts[idx], nrm[idx])
                row["pybullet_loop_ms_per_point"] = 1e3 * loop["seconds"] / len(idx)
            out[name] = row
        heat = {}
        for staged_flag in (True, False):
            t0 = time.perf_counter()
            reachability_map(cell, n_samples, np.random.default_rng(seed), staged=staged_flag)
            heat["staged" if staged_flag else "whole_query"] = (
                1e3 * (time.perf_counter() - t0) / n_samples
            )
        heat["ratio"] = heat["whole_query"] / heat["staged"]
        out["heat_map_ms_per_sample"] = heat
    return out


def _print_worst(w: dict) -> None:
    table = Table(title=f"demo cell, one point per call ({w['samples']} stator samples)")
    for col in ("points", "n", "staged median/max ms", "whole-query median/max ms", "ratio"):
        table.add_column(col)
    for name in ("worst", "typical"):
        r = w[name]
        table.add_row(
            name,
            str(w["worst_points"]) if name == "worst" else "",
            f"{r['staged']['median_ms']:.1f} / {r['staged']['max_ms']:.0f}",
            f"{r['whole_query']['median_ms']:.1f} / {r['whole_query']['max_ms']:.0f}",
            f"{r['ratio_median']:.1f}x (max {r['ratio_max']:.1f}x)",
        )
    Console().print(table)
    h = w["heat_map_ms_per_sample"]
    Console().print(
        f"heat map: {h['staged']:.1f} ms/sample staged, {h['whole_query']:.1f} whole-query "
        f"({h['ratio']:.1f}x); same answers: {w['worst']['same_answers']}, "
        f"{w['typical']['same_answers']}"
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=300, help="probe points for wobjcal")
    ap.add_argument("--pybullet-n", type=int, default=100, help="points for the plain loop")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=RESULTS)
    ap.add_argument("--worst-n", type=int, default=40, help="demo samples for the worst case")
    ap.add_argument("--worst-no-loop", action="store_true", help="skip the loop on those")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    mesh = work_object()
    pts, nrm, _ = sample_surface(mesh, args.n, rng)
    with Cell() as cell:
        t0 = time.perf_counter()
        cell.set_work_object(mesh, "m", T_WORLD_WOBJ, name="box_114k")
        load_s = time.perf_counter() - t0
        ours = run_ours(cell, pts, nrm)
        k = min(args.pybullet_n, args.n)
        ours_same = run_ours(cell, pts[:k], nrm[:k])
        loop = run_plain_loop(cell, pts[:k], nrm[:k])
    ours_pp, loop_pp = ours_same.pop("per_point"), loop.pop("per_point")
    reasons = ours_same.pop("reasons")
    ours.pop("per_point")
    ours.pop("reasons")
    result = {
        "bench": "feasibility",
        "only_loop_feasible_our_reasons": [
            reasons[i] for i in range(k) if loop_pp[i] and not ours_pp[i]
        ],
        "only_ours_feasible": int(sum(o and not lp for o, lp in zip(ours_pp, loop_pp))),
        "triangles": len(mesh.faces),
        "work_object_load_s": load_s,
        "seed": args.seed,
        "ours": ours,
        "ours_on_loop_points": ours_same,
        "pybullet_plain_loop": loop,
        "ratio_checks_per_s": ours_same["checks_per_s"] / loop["checks_per_s"],
        "worst_case_demo": run_worst_case(args.worst_n, args.seed, not args.worst_no_loop),
        "machine": {"python": platform.python_version(), "cpu": platform.processor()},
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(args.out, json.dumps(result, indent=2, sort_keys=True) + "\n")
    table = Table(title=f"probe feasibility on {len(mesh.faces):,} triangles")
    for col in ("method", "points", "checks/s", "feasible"):
        table.add_column(col)
    table.add_row(
        "wobjcal check_probes",
        str(ours["n"]),
        f"{ours['checks_per_s']:.0f}",
        f"{ours['feasible']}/{ours['n']}",
    )
    table.add_row(
        "wobjcal (loop's points)",
        str(ours_same["n"]),
        f"{ours_same['checks_per_s']:.0f}",
        f"{ours_same['feasible']}/{k}",
    )
    table.add_row(
        "PyBullet IK + getClosestPoints loop",
        str(k),
        f"{loop['checks_per_s']:.0f}",
        f"{loop['feasible']}/{k}",
    )
    Console().print(table)
    _print_worst(result["worst_case_demo"])
    Console().print(
        f"ratio: {result['ratio_checks_per_s']:.1f}x; only the loop finds feasible (our "
        f"reasons): {result['only_loop_feasible_our_reasons']}; only we find feasible: "
        f"{result['only_ours_feasible']}; written {args.out}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
