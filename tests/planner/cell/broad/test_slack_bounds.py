"""Upper bounds of candidates' slacks (:mod:`planner.cell.broad.slack_bounds`) against Bullet.

Every bound must be at least Bullet's slack of the whole clearance query at that
configuration (a bound too low could drop the candidate the exact check chooses), on the
configurations of ``tests/planner/cell/broad/test_broad_phase.py``: random joints and probe poses
from 12 mm
inside to 2 mm outside a dense part, with a table, a post and a mesh fixture. And the bounds
must be worth having: near the table and in self-contact most candidates get one within a few
millimetres of Bullet's slack, and most links deep in the table or the post one below -1 cm.
"""

from __future__ import annotations

import numpy as np
import pytest

from planner.cell.broad.broad_phase import broad_phase_of
from planner.cell.broad.slack_bounds import SlackBounds
from planner.cell.cell import Cell
from planner.cell.kernels import bound_kernels
from planner.cell.kernels.gjk_kernels import BOX, CYLINDER, HULL
from tests.planner.cell.broad.test_broad_phase import MARGIN, cell, configurations  # noqa: F401  (fixture)


@pytest.mark.slow
def test_bounds_are_never_below_bullets_slack(cell: Cell) -> None:  # noqa: F811
    rng = np.random.default_rng(11)
    q, T_bf = configurations(cell, rng)
    broad = broad_phase_of(cell)
    plan = cell.checker.plan(MARGIN, cell.self_margin_m, None, True, False)
    env = broad.environment(cell)
    parts = broad.part_map(cell, plan, env)
    T_links = broad.link_poses(cell, q, T_bf)
    ps, ss, _ = broad.states(parts, env, T_links)
    ub = SlackBounds(broad, parts, env, plan).upper(T_links, ps, ss)
    bounded = apart = tight = deep = deep_shown = 0
    links = {b.name for b in broad.links}
    with cell.saved_state():
        for m in range(len(q)):
            cell.set_joint_positions(q[m])
            cl = cell.clearance(MARGIN, sensor_wobj_allowed=True)
            assert ub[m] >= cl.slack_m, (m, ub[m], cl)
            bounded += bool(np.isfinite(ub[m]))
            # GJK bounds distances, not depths: tight where the limiting pair is a bounded
            # kind (a link against the table or the post, or a self pair) and not in contact
            if (
                cl.pair is not None
                and cl.clearance_m >= 0
                and cl.pair[1] in {"table", "post"} | links
            ):
                apart += 1
                tight += ub[m] - cl.slack_m <= 0.003
            # and against a box or a cylinder, depths: points of the link deep inside it
            if cl.pair is not None and cl.clearance_m < -0.01 and cl.pair[1] in {"table", "post"}:
                deep += 1
                deep_shown += ub[m] < -0.01
    assert bounded >= 200, bounded
    assert apart >= 30 and tight >= 0.9 * apart, (tight, apart)
    assert deep >= 50 and deep_shown >= 0.7 * deep, (deep_shown, deep)


def _T(p: tuple[float, float, float], rz: float = 0.0) -> np.ndarray:
    c, s = np.cos(rz), np.sin(rz)
    return np.ascontiguousarray(np.array([[c, -s, 0, p[0]], [s, c, 0, p[1]], [0, 0, 1, p[2]]]))


def test_gjk_upper_on_known_geometry() -> None:
    """Two unit boxes 0.25 m apart along x; a cylinder over a box; overlapping boxes; a hull
    (a tetrahedron) beside a box: the bound is the distance (within 1e-7 m) or 0."""
    rng = np.random.default_rng(3)
    half = np.array([0.5, 0.5, 0.5])
    none = np.zeros((1, 3))
    up = bound_kernels.gjk_upper
    d = up(BOX, _T((0, 0, 0)), half, none, 0, 0, BOX, _T((1.25, 0.3, -0.2)), half, none, 0, 0,
           1e-9)  # fmt: skip
    assert abs(d - 0.25) < 1e-7
    cyl = np.array([0.1, 0.2, 0.0])  # radius, half length (axis z)
    d = up(CYLINDER, _T((0.2, 0.1, 0.9)), cyl, none, 0, 0, BOX, _T((0, 0, 0)), half, none, 0, 0,
           1e-9)  # fmt: skip
    assert abs(d - 0.2) < 1e-7
    d = up(BOX, _T((0, 0, 0)), half, none, 0, 0, BOX, _T((0.9, 0.2, 0.1), 0.3), half, none, 0,
           0, 1e-9)  # fmt: skip
    assert d == 0.0
    tet = np.ascontiguousarray([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]], dtype=float)
    for _ in range(20):  # the tetrahedron's corner (0, 0, 0) nearest to the box's +x face
        gap = rng.uniform(0.001, 0.3)
        d = up(HULL, _T((0.5 + gap, 0.0, 0.0)), np.zeros(3), tet, 0, 4, BOX, _T((0, 0, 0)),
               half, none, 0, 0, 1e-9)  # fmt: skip
        assert abs(d - gap) < 1e-7
