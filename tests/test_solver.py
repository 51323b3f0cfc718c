"""make_ik_solver: picks OPW or numeric, IKSolutions shape and contents."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet_data

from planner.kinematics.chain import KinematicChain
from planner.kinematics.solver import IKSolutions, make_ik_solver

IRB4400 = Path(__file__).resolve().parent.parent / "assets/robots/irb4400/irb4400.urdf"
IIWA = Path(pybullet_data.getDataPath()) / "kuka_iiwa/model.urdf"


def test_iiwa_uses_numeric_and_solves(rng: np.random.Generator) -> None:
    chain = KinematicChain.from_urdf(IIWA)
    solver = make_ik_solver(chain, n_seeds=6)
    assert solver.kind == "numeric"
    assert solver.why_not_opw
    q_true = rng.uniform(chain.lower, chain.upper, (10, 7))
    sol = solver.solve(chain.fk(q_true))
    assert isinstance(sol, IKSolutions)
    assert sol.q.shape[0] == 10 and sol.q.shape[2] == 7
    assert sol.valid.shape == sol.branch.shape == sol.q.shape[:2]
    assert sol.found.mean() >= 0.9
    q_near, found = sol.nearest(q_true)
    np.testing.assert_allclose(chain.fk(q_near[found]), chain.fk(q_true[found]), atol=1e-6)
