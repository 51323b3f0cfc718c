"""The vectorized OPW solver against a straightforward, pose-by-pose reference implementation.

The reference follows the formulas of ``docs/kinematics.md`` with scalar ``math`` calls, one
branch and one joint at a time, and lists the 2*pi variants with ``itertools.product``; the
solver (limit filtering before the wrist, packing without Python loops over solutions) must
give the same solutions in the same order, to 1e-12 rad.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from calib.frames import invert_transform
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.opw import OPWParameters, opw_fk
from planner.robot.kinematics.opw_robot import OPWRobot
from planner.robot.kinematics.solver import make_ik_solver

ROOT = Path(__file__).resolve().parents[3]
IRB4400 = ROOT / "assets/robots/irb4400/irb4400.urdf"
KUKA_STYLE = Path(__file__).resolve().parents[2] / "data/kuka_style_opw.urdf"


def _wrap(x: float) -> float:
    return x - 2.0 * math.pi * round(x / (2.0 * math.pi))


def _rz(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def reference_branches(p: OPWParameters, T: np.ndarray) -> list[list[float] | None]:
    """The 8 branches (shoulder, elbow, wrist bits 4, 2, 1) of one pose ``T_opw_ee``."""
    R, pos = T[:3, :3], T[:3, 3]
    C = pos - p.c4 * R[:, 2]
    k = math.hypot(p.a2, p.c3)
    psi3 = math.atan2(p.a2, p.c3)
    out: list[list[float] | None] = []
    for shoulder in (0, 1):
        r2 = C[0] ** 2 + C[1] ** 2
        rho = math.sqrt(max(r2 - p.b**2, 0.0))
        phi, lam = math.atan2(C[1], C[0]), math.atan2(p.b, rho)
        t1 = phi - lam if shoulder == 0 else phi + lam - math.pi
        x = rho - p.a1 if shoulder == 0 else -rho - p.a1
        z = C[2] - p.c1
        D = (x * x + z * z - p.c2**2 - k * k) / (2.0 * p.c2 * k)
        reachable = r2 - p.b**2 >= -1e-18 and abs(D) <= 1.0 + 1e-14
        D = min(1.0, max(-1.0, D))
        for elbow in (0, 1):
            if not reachable:
                out += [None, None]
                continue
            beta = math.acos(D) * (1.0 if elbow == 0 else -1.0)
            t3 = beta - psi3
            t2 = math.atan2(x, z) - math.atan2(k * math.sin(beta), p.c2 + k * math.cos(beta))
            M = (_rz(t1) @ _ry(t2 + t3)).T @ R
            t5 = math.atan2(math.hypot(M[0, 2], M[1, 2]), M[2, 2])
            if math.hypot(M[0, 2], M[1, 2]) < 1e-10:
                t4 = 0.0
                t6 = math.atan2(M[1, 0], M[0, 0]) if M[2, 2] > 0 else math.atan2(M[0, 1], M[1, 1])
            else:
                t4, t6 = math.atan2(M[1, 2], M[0, 2]), math.atan2(M[2, 1], -M[2, 0])
            for wrist in (0, 1):
                theta = [t1, t2, t3, t4, t5, t6]
                if wrist:
                    theta[3:] = [t4 + math.pi, -t5, t6 + math.pi]
                out.append(
                    [
                        _wrap(s * (t + o))
                        for s, t, o in zip(p.sign_corrections, theta, p.offsets, strict=True)
                    ]
                )
    return out


def reference_solutions(robot: OPWRobot, T_base_tip: np.ndarray) -> list[tuple[list[float], int]]:
    """All solutions within limits of one pose, by branch then variant, with their branch."""
    T = invert_transform(robot.T_base_opw) @ T_base_tip @ invert_transform(robot.T_ee_tip)
    counts = robot.turn_counts
    sols = []
    for b, q in enumerate(reference_branches(robot.params, T)):
        if q is None:
            continue
        values = []
        for j, (v, lo, hi) in enumerate(zip(q, robot.lower, robot.upper, strict=True)):
            if not (math.isfinite(lo) and math.isfinite(hi)):
                values.append([v])
            elif counts[j] == 1 and lo >= -math.pi and hi <= math.pi:
                values.append([v] if lo - 1e-12 <= v <= hi + 1e-12 else [])
            else:
                v_lo = v - 2 * math.pi * math.floor((v - lo + 1e-12) / (2 * math.pi))
                cands = [v_lo + 2 * math.pi * i for i in range(counts[j])]
                values.append([c for c in cands if c <= hi + 1e-12])
        sols += [(list(s), b) for s in itertools.product(*values)]
    return sols


def _compare(
    robot: OPWRobot, T: np.ndarray, q: np.ndarray, valid: np.ndarray, br: np.ndarray
) -> None:
    for i in range(T.shape[0]):
        ref = reference_solutions(robot, T[i])
        assert int(valid[i].sum()) == len(ref), f"pose {i}: solution count"
        assert valid[i, : len(ref)].all()
        if ref:
            np.testing.assert_allclose(q[i, : len(ref)], [s for s, _ in ref], rtol=0, atol=1e-12)
            assert [int(b) for b in br[i, : len(ref)]] == [b for _, b in ref], f"pose {i}"
        assert np.isnan(q[i, len(ref) :]).all()
        assert (br[i, len(ref) :] == -1).all()


@pytest.mark.parametrize("path", [IRB4400, KUKA_STYLE], ids=["irb4400", "kuka_style"])
def test_solver_matches_the_reference(path: Path, rng: np.random.Generator) -> None:
    chain = KinematicChain.from_urdf(path, base_link="base_link")
    solver = make_ik_solver(chain)
    assert solver.kind == "opw" and solver.opw is not None and solver.opw_exact
    q_in = rng.uniform(chain.lower, chain.upper, (150, 6))
    T = chain.fk(q_in)
    T[100:120, :3, 3] *= 1.8  # some unreachable poses
    sol = solver.solve(T)
    _compare(solver.opw, T, sol.q, sol.valid, np.asarray(solver.opw.solve(T)[2]))
    # the configuration code of every solution: OPW branch bits 4, 2 and the sign of axis 5
    ref_codes = np.where(sol.valid, (solver.opw.solve(T)[2] & 6) + (sol.q[:, :, 4] < 0), -1)
    np.testing.assert_array_equal(sol.branch, ref_codes)
    # the batched path (several chunks) equals the one-shot path from all 8 branches
    q8, ok8 = solver.opw.ik_branches(T)
    for a, b in zip(solver.opw.expand(q8, ok8), solver.opw.solve(T), strict=True):
        np.testing.assert_array_equal(a, b)


def test_multi_turn_and_continuous_joints_match_the_reference(rng: np.random.Generator) -> None:
    # axis 1 over 2 turns (a multi-turn arm joint), axis 4 continuous, axis 6 over 3 turns,
    # odd offsets and signs, a lateral offset b
    p = OPWParameters(
        0.1,
        -0.12,
        0.07,
        0.5,
        0.7,
        0.6,
        0.1,
        (0.1, -0.3, 0.2, 0.0, 0.4, -1.0),
        (1, -1, 1, -1, 1, -1),
    )
    lower = np.array([-2 * np.pi, -2.0, -2.5, -np.inf, -2.0, -3 * np.pi])
    upper = np.array([2 * np.pi, 2.0, 2.5, np.inf, 2.0, 3 * np.pi])
    T_base_opw = np.eye(4)
    T_base_opw[:3, 3] = (0.1, -0.2, 0.3)
    robot = OPWRobot(p, T_base_opw, np.eye(4), lower, upper)
    assert robot.turn_counts == (2, 1, 1, 1, 1, 3)
    q_in = rng.uniform(np.maximum(lower, -np.pi), np.minimum(upper, np.pi), (120, 6))
    T = T_base_opw @ opw_fk(p, q_in)
    q, valid, b = robot.solve(T)
    _compare(robot, T, q, valid, b)
    assert valid.any(axis=1).all()


def test_chunks_do_not_change_the_result(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch
) -> None:
    import planner.robot.kinematics.opw_robot as opw_robot

    chain = KinematicChain.from_urdf(IRB4400)
    solver = make_ik_solver(chain)
    T = chain.fk(rng.uniform(chain.lower, chain.upper, (300, 6)))
    whole = solver.solve(T)
    monkeypatch.setattr(opw_robot, "CHUNK", 7)
    chunked = solver.solve(T)
    np.testing.assert_array_equal(whole.q, chunked.q)
    np.testing.assert_array_equal(whole.valid, chunked.valid)
    np.testing.assert_array_equal(whole.branch, chunked.branch)
