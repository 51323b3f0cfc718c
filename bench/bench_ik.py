"""Inverse kinematics: wobjcal's solver against ``pybullet.calculateInverseKinematics``.

The same ``--n`` random reachable flange poses of a robot (FK of random joint values within the
limits) go to (1) our solver (``make_ik_solver``: analytic OPW with all branches, 2*pi variants
and limits for the built-in IRB 4400; numeric otherwise), and to PyBullet's IK (2) at its
defaults, (3) tuned: ``jointDamping=[1e-3]*n``, ``maxNumIterations=100``,
``residualThreshold=1e-12`` (ignores joint limits), and (4) tuned with lower/upper limits, ranges
and rest poses (PyBullet's null-space IK). PyBullet starts every pose from the rest pose (all
zeros); only the ``calculateInverseKinematics`` calls are timed.

Timing is interleaved so that both sides see the same machine load: the poses given to PyBullet
are cut into ``--chunk`` consecutive poses; for every chunk and mode, our solver solves all
``--n`` poses (3 timed runs, their median) right before PyBullet solves the chunk. Each such
round gives a paired ratio of throughputs (poses per second); the reported ratio is the median
over the rounds (their range is in the JSON), the reported rates are the medians of each side.
A pose counts as solved when some solution is within the joint limits and reproduces the pose
(measured with our FK) within 1e-6 m and 1e-4 rad (also reported at 1e-3 m).

Run: ``python -m bench.bench_ik [--n 10000] [--seed 0] [--pybullet-n N] [--chunk 1000]
[--robot URDF]``; writes ``bench/results/ik.json`` and prints a table.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pybullet as pb
from rich.console import Console
from rich.table import Table
from scipy.spatial.transform import Rotation

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from calib.atomic_io import write_text_atomic
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.solver import make_ik_solver

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_ROBOT = ROOT / "assets/robots/irb4400/irb4400.urdf"
RESULTS = ROOT / "bench/results/ik.json"


def pose_errors(chain: KinematicChain, q: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, ...]:
    """Position (m) and rotation (rad) errors of ``fk(q)`` against ``T``; inf for NaN rows."""
    bad = np.isnan(q).any(axis=-1)
    T_q = chain.fk(np.where(bad[:, None], 0.0, q))
    pos = np.linalg.norm(T_q[:, :3, 3] - T[:, :3, 3], axis=1)
    R_err = np.swapaxes(T_q[:, :3, :3], 1, 2) @ T[:, :3, :3]
    rot = np.linalg.norm(Rotation.from_matrix(R_err).as_rotvec(), axis=1)
    return np.where(bad, np.inf, pos), np.where(bad, np.inf, rot)


def time_ours(solve: Callable[[np.ndarray], object], T: np.ndarray, runs: int = 3) -> float:
    """Median wall time (s) of ``runs`` calls ``solve(T)``."""
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        solve(T)
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def check_ours(chain: KinematicChain, T: np.ndarray) -> dict[str, object]:
    """Solve ``T`` once and measure what our solver finds (no timing)."""
    solver = make_ik_solver(chain)
    sol = solver.solve(T)
    N, K, n = sol.q.shape
    q = sol.q.reshape(N * K, n)
    pos, rot = pose_errors(chain, q, np.repeat(T, K, axis=0))
    inside = chain.within_limits(np.nan_to_num(q, nan=np.inf), tol=1e-9)
    pos, rot = pos.reshape(N, K), rot.reshape(N, K)
    inside = inside.reshape(N, K)
    ok6 = ((pos <= 1e-6) & (rot <= 1e-4) & inside).any(axis=1)
    ok3 = ((pos <= 1e-3) & (rot <= 1e-4) & inside).any(axis=1)
    valid_pos = pos[sol.valid]
    return {
        "solver": solver.kind,
        "why_not_opw": solver.why_not_opw,
        "solutions_per_pose_mean": float(sol.valid.sum(axis=1).mean()),
        "K": K,
        "solved_1e-6m": float(ok6.mean()),
        "solved_1e-3m": float(ok3.mean()),
        "valid_flag_fraction": float(sol.found.mean()),
        "max_pos_err_m_valid": float(valid_pos.max()) if valid_pos.size else None,
        "max_rot_err_rad_valid": float(rot[sol.valid].max()) if valid_pos.size else None,
        "_q_first": sol.nearest(np.zeros(n))[0],
    }


class PyBulletIK:
    """PyBullet's IK from the rest pose; ``mode`` is ``default``, ``tuned`` or ``tuned_limits``."""

    def __init__(self, chain: KinematicChain, path: Path, mode: str) -> None:
        self.cid = pb.connect(pb.DIRECT)
        cid = self.cid
        self.body = pb.loadURDF(str(path), useFixedBase=True, physicsClientId=cid)
        info = [
            pb.getJointInfo(self.body, i, physicsClientId=cid)
            for i in range(pb.getNumJoints(self.body, physicsClientId=cid))
        ]
        jidx = {i[1].decode(): i[0] for i in info}
        self.tip = next(i[0] for i in info if i[12].decode() == chain.tip_link)
        self.movable = [i[0] for i in info if i[2] != pb.JOINT_FIXED]
        self.order = [self.movable.index(jidx[name]) for name in chain.joint_names]
        self.n = chain.n_joints
        lo = np.where(np.isfinite(chain.lower), chain.lower, -2 * np.pi)
        hi = np.where(np.isfinite(chain.upper), chain.upper, 2 * np.pi)
        self.kwargs: dict[str, object] = {}
        if mode != "default":
            self.kwargs = dict(
                jointDamping=[1e-3] * len(self.movable),
                maxNumIterations=100,
                residualThreshold=1e-12,
            )
        if mode == "tuned_limits":  # PyBullet's null-space IK
            self.kwargs.update(
                lowerLimits=list(lo),
                upperLimits=list(hi),
                jointRanges=list(hi - lo),
                restPoses=[0.0] * len(self.movable),
            )

    def solve(self, T: np.ndarray) -> tuple[np.ndarray, float]:
        """Joint values ``(N, n)`` for poses ``T`` and the seconds spent in the IK calls."""
        cid = self.cid
        quat = Rotation.from_matrix(T[:, :3, :3]).as_quat()  # xyzw
        q = np.empty((len(T), self.n))
        spent = 0.0
        for k in range(len(T)):
            for j in self.movable:
                pb.resetJointState(self.body, j, 0.0, physicsClientId=cid)
            pos, orn = T[k, :3, 3].tolist(), quat[k].tolist()
            t0 = time.perf_counter()
            sol = pb.calculateInverseKinematics(
                self.body, self.tip, pos, orn, physicsClientId=cid, **self.kwargs
            )
            spent += time.perf_counter() - t0
            q[k] = np.asarray(sol)[self.order]
        return q, spent

    def close(self) -> None:
        pb.disconnect(self.cid)


def run_mode(
    chain: KinematicChain, path: Path, T: np.ndarray, n_pb: int, chunk: int, mode: str
) -> dict[str, Any]:
    """Interleaved rounds: ours on all poses, then PyBullet on the next chunk of its poses."""
    solver = make_ik_solver(chain)
    solver.solve(T[:10])  # warm-up
    pyb = PyBulletIK(chain, path, mode)
    q = np.empty((n_pb, chain.n_joints))
    ours_rate, pb_rate, ratio = [], [], []
    pb_seconds = 0.0
    try:
        for s in range(0, n_pb, chunk):
            t_ours = time_ours(solver.solve, T)
            q[s : s + chunk], t_pb = pyb.solve(T[s : s + chunk])
            m = min(chunk, n_pb - s)
            pb_seconds += t_pb
            ours_rate.append(len(T) / t_ours)
            pb_rate.append(m / t_pb)
            ratio.append(ours_rate[-1] / pb_rate[-1])
    finally:
        pyb.close()
    pos, rot = pose_errors(chain, q, T[:n_pb])
    inside = chain.within_limits(q, tol=1e-9)
    return {
        "rounds": len(ratio),
        "poses_per_s": float(np.median(pb_rate)),
        "poses_per_s_best_chunk": float(max(pb_rate)),
        "poses_per_s_overall": n_pb / pb_seconds,
        "ours_poses_per_s": float(np.median(ours_rate)),
        "ours_poses_per_s_best": float(max(ours_rate)),
        "ratio_median": float(np.median(ratio)),
        "ratio_min": float(min(ratio)),
        "ratio_max": float(max(ratio)),
        "seconds": pb_seconds,
        "solved_1e-6m": float(((pos <= 1e-6) & (rot <= 1e-4) & inside).mean()),
        "solved_1e-3m": float(((pos <= 1e-3) & (rot <= 1e-4) & inside).mean()),
        "median_pos_err_m": float(np.median(pos)),
        "median_rot_err_rad": float(np.median(rot)),
        "within_limits": float(inside.mean()),
    }


def pybullet_fk_agreement(chain: KinematicChain, path: Path, q: np.ndarray, T: np.ndarray) -> float:
    """Largest position difference (m) between PyBullet's FK of our solutions and the targets."""
    cid = pb.connect(pb.DIRECT)
    worst = 0.0
    try:
        body = pb.loadURDF(str(path), useFixedBase=True, physicsClientId=cid)
        info = [
            pb.getJointInfo(body, i, physicsClientId=cid)
            for i in range(pb.getNumJoints(body, physicsClientId=cid))
        ]
        jidx = {i[1].decode(): i[0] for i in info}
        tip = next(i[0] for i in info if i[12].decode() == chain.tip_link)
        for k in np.flatnonzero(~np.isnan(q).any(axis=1)):
            for name, v in zip(chain.joint_names, q[k]):
                pb.resetJointState(body, jidx[name], float(v), physicsClientId=cid)
            st = pb.getLinkState(body, tip, computeForwardKinematics=True, physicsClientId=cid)
            worst = max(worst, float(np.abs(np.array(st[4]) - T[k, :3, 3]).max()))
    finally:
        pb.disconnect(cid)
    return worst


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10000, help="number of random reachable poses")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--pybullet-n", type=int, default=None, help="poses given to PyBullet")
    ap.add_argument("--chunk", type=int, default=1000, help="PyBullet poses per timed round")
    ap.add_argument("--robot", type=Path, default=DEFAULT_ROBOT, help="URDF (tip: tool0)")
    ap.add_argument("--out", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    console = Console()
    chain = KinematicChain.from_urdf(args.robot)
    rng = np.random.default_rng(args.seed)
    lo = np.where(np.isfinite(chain.lower), chain.lower, -np.pi)
    hi = np.where(np.isfinite(chain.upper), chain.upper, np.pi)
    T = chain.fk(rng.uniform(lo, hi, (args.n, chain.n_joints)))
    n_pb = min(args.pybullet_n or args.n, args.n)
    ours = check_ours(chain, T)
    runs = {}
    for mode in ("default", "tuned", "tuned_limits"):
        with console.status(f"interleaved rounds: ours and PyBullet IK, {mode} ..."):
            runs[mode] = run_mode(chain, args.robot, T, n_pb, args.chunk, mode)
    all_rates = [r["ours_poses_per_s"] for r in runs.values()]
    ours["poses_per_s"] = float(np.median(all_rates))
    ours["seconds"] = args.n / ours["poses_per_s"]
    q_first = ours.pop("_q_first")
    n_fk = min(1000, args.n)
    agree = pybullet_fk_agreement(chain, args.robot, q_first[:n_fk], T[:n_fk])  # type: ignore[index]
    result = {
        "benchmark": "ik",
        "timing": (
            "interleaved rounds: ours solves all n_poses (median of 3 runs), then PyBullet solves "
            "the next chunk of its poses (sum of its IK calls); ratio = median over rounds of "
            "the paired throughput ratios; rates = medians"
        ),
        "chunk": args.chunk,
        "robot": str(
            args.robot.relative_to(ROOT) if args.robot.is_relative_to(ROOT) else args.robot
        ),
        "n_poses": args.n,
        "n_poses_pybullet": n_pb,
        "seed": args.seed,
        "ours": ours,
        **{f"pybullet_{mode}": r for mode, r in runs.items()},
        **{f"throughput_ratio_vs_pybullet_{mode}": r["ratio_median"] for mode, r in runs.items()},
        "pybullet_fk_agreement_max_m": agree,
        "pybullet_fk_agreement_n": n_fk,
        "machine": {
            "python": platform.python_version(),
            "cpu": platform.processor() or platform.machine(),
            "load_average_1_5_15": list(os.getloadavg()),
        },
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(args.out, json.dumps(result, indent=2, sort_keys=True) + "\n")
    table = Table(title=f"IK on {args.n} random reachable poses of {chain.name} ({ours['solver']})")
    for col in ("solver", "poses/s", "ratio (range)", "solved 1e-6 m", "solved 1e-3 m"):
        table.add_column(col, justify="right")
    table.add_row(
        "wobjcal",
        f"{ours['poses_per_s']:,.0f}",
        "1",
        f"{100 * ours['solved_1e-6m']:.2f} %",  # type: ignore[operator]
        f"{100 * ours['solved_1e-3m']:.2f} %",  # type: ignore[operator]
    )
    for mode, r in runs.items():
        table.add_row(
            f"PyBullet {mode}",
            f"{r['poses_per_s']:,.0f}",
            f"{r['ratio_median']:.1f}x ({r['ratio_min']:.0f}-{r['ratio_max']:.0f})",
            f"{100 * r['solved_1e-6m']:.2f} %",
            f"{100 * r['solved_1e-3m']:.2f} %",
        )
    console.print(table)
    console.print(
        f"our round trip max {ours['max_pos_err_m_valid']:.2e} m; PyBullet FK of our solutions "
        f"within {agree:.2e} m; {ours['solutions_per_pose_mean']:.2f} solutions per pose; "
        f"wrote {args.out}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
