"""Tests of planner.robot.reach: the reach model and the no-IK reasons, against the arm's
geometry."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from calib.frames import make_transform
from planner.builtins import robot_urdf
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.solver import make_ik_solver
from planner.robot.reach import cell_reach_model, opw_wrist_reason, reach_model

# IRB 4400 figures (assets/robots/irb4400/README.md)
A1, C1, C2, C3, A2, C4 = 0.200, 0.680, 0.890, 0.880, 0.150, 0.140


@pytest.fixture(scope="module")
def chain() -> KinematicChain:
    return KinematicChain.from_urdf(robot_urdf("builtin:irb4400"))


def test_reach_of_the_builtin_arm(chain: KinematicChain, rng) -> None:
    model = reach_model(chain, rng)
    np.testing.assert_allclose(model.shoulder_m, [A1, 0.0, C1], atol=1e-9)
    np.testing.assert_allclose(model.axis, [0.0, 0.0, 1.0], atol=1e-12)
    # flange fully stretched: upper arm + |(forearm + flange, offset)|, sampled just below it
    stretched = C2 + math.hypot(C3 + C4, A2)
    assert stretched - 0.05 < model.reach_m <= stretched + 1e-9


def test_a_cell_reach_model_is_kept_per_chain_content(chain: KinematicChain) -> None:
    """The cells' reach model is the seed-0 model; the same robot loaded again gets the kept
    one; a robot with other limits gets its own."""
    import dataclasses

    kept = cell_reach_model(chain)
    fresh = reach_model(chain, np.random.default_rng(0))
    for name in ("axis_origin_m", "axis", "shoulder_m"):
        assert np.array_equal(getattr(kept, name), getattr(fresh, name))
    assert kept.reach_m == fresh.reach_m
    assert cell_reach_model(KinematicChain.from_urdf(robot_urdf("builtin:irb4400"))) is kept
    with pytest.raises(ValueError):  # read-only: a caller cannot change the kept model
        kept.shoulder_m[0] = 0.0
    short = dataclasses.replace(chain, upper=np.minimum(chain.upper, 0.3))
    other = cell_reach_model(short)
    assert other is not kept
    assert other.reach_m == reach_model(short, np.random.default_rng(0)).reach_m != kept.reach_m


def test_shoulder_turns_towards_the_target(chain: KinematicChain, rng) -> None:
    model = reach_model(chain, rng)
    p = np.array([[-2.0, 0.0, 0.3], [0.0, 3.0, 1.0]])
    np.testing.assert_allclose(
        model.shoulder_towards(p), [[-A1, 0.0, C1], [0.0, A1, C1]], atol=1e-12
    )


def test_wrist_centre_reasons(chain: KinematicChain) -> None:
    opw = make_ik_solver(chain).opw
    k = math.hypot(C3, A2)
    far = make_transform(p=[3.0, 0.0, C1])  # flange z along base z: wrist centre 0.14 m lower
    pattern = r"out of reach \(wrist centre (\d\.\d\d) m from the shoulder, reach (\d\.\d\d) m\)"
    out = opw_wrist_reason(opw, far[None])
    assert out.kind == "reach" and out.about_part
    m = re.fullmatch(pattern, out.text)
    assert m is not None
    assert float(m.group(1)) == pytest.approx(math.hypot(3.0 - A1, C4), abs=0.006)
    assert float(m.group(2)) == pytest.approx(C2 + k, abs=0.006)
    # close in front of the shoulder, inside the arm's dead zone |c2 - k|
    near = make_transform(p=[A1, 0.0, C1 + C4])
    close = opw_wrist_reason(opw, near[None])
    assert close.kind == "reach" and close.text.startswith("too close (wrist centre 0.00 m")


def test_batched_reasons_are_the_per_point_ones(chain: KinematicChain) -> None:
    """``no_ik_reasons`` of many points equals ``no_ik_reason`` point by point: out of reach,
    too close, joints at their limits (seeded poses all around the arm)."""
    from planner.robot.reach import no_ik_reason, no_ik_reasons

    rng = np.random.default_rng(11)
    solver = make_ik_solver(chain)
    model = reach_model(chain, np.random.default_rng(0))
    p = rng.uniform([-3, -3, -1], [3, 3, 3], size=(1500, 3))
    p[:1000] *= rng.uniform(0.05, 0.6, size=(1000, 1))  # many within reach
    T = np.tile(np.eye(4), (1500, 8, 1, 1))
    rot = rng.normal(size=(1500, 8, 3))
    from scipy.spatial.transform import Rotation

    T[..., :3, :3] = Rotation.from_rotvec(rot.reshape(-1, 3)).as_matrix().reshape(1500, 8, 3, 3)
    T[..., :3, 3] = p[:, None]
    none = ~solver.solve(T.reshape(-1, 4, 4)).valid.reshape(1500, -1).any(axis=1)
    T = T[none]
    expected = [no_ik_reason(model, solver, chain, t) for t in T]
    assert no_ik_reasons(model, solver, chain, T) == expected
    words = {e.text.split(" (")[0] for e in expected}
    assert {"out of reach", "joint 2 at limit", "joint 3 at limit"} <= words
    assert {e.kind for e in expected} == {"reach", "joint_limit"}
    assert all(e.about_part == e.text.startswith("out of reach") for e in expected)
    assert no_ik_reasons(model, solver, chain, T[:0]) == []
