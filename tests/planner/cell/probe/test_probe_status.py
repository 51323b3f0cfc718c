"""Tests of planner.cell.probe.probe_status: the heat map's statuses against the full check.

:func:`probe_statuses` stops at the first candidate that settles a point's status instead of
finding the least-bad pose; its statuses must be :func:`check_probes`'s on every point, and
its reasons too wherever it found the same pose.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from planner.cell.cell import Cell
from planner.cell.probe.probe_status import EVERY_POSE_HITS, NO_POSE_WITH_MARGIN, probe_statuses
from planner.cell.probe.reachability import sample_surface
from tests.cells import add_box_on_table


def _compare(cell: Cell, pts: np.ndarray, nrm: np.ndarray, **kw: float) -> tuple[int, int]:
    """Asserts equal statuses (and reasons where exact); returns the points decided by the
    shortcut: all of them, and the marginal ones."""
    full = cell.check_probes(pts, nrm, **kw)  # type: ignore[arg-type]
    st = probe_statuses(cell, pts, nrm, **kw)  # type: ignore[arg-type]
    assert list(st.statuses) == [r.status for r in full]
    for i, r in enumerate(full):
        if st.exact[i]:
            assert st.reasons[i] == r.reason
        else:
            assert st.reasons[i] == (
                EVERY_POSE_HITS if r.status == "infeasible" else NO_POSE_WITH_MARGIN
            )
    marginal = [s == "marginal" and not e for s, e in zip(st.statuses, st.exact)]
    return int((~st.exact).sum()), sum(marginal)


@pytest.fixture(scope="module")
def demo() -> Iterator[Cell]:
    from planner.demo import make_demo_cell

    with make_demo_cell(use_acl_cache=False) as c:
        yield c


@pytest.mark.slow
def test_demo_heat_map_statuses_equal_the_full_check(demo: Cell) -> None:
    """300 stator samples at the heat map's settings (most collide in every pose: the case the
    shortcut is for) and 60 at a click's."""
    from webui.heatmap import MAX_CHECKS, ROTATION_STEP_DEG

    pts, nrm, _ = sample_surface(demo.work_object.mesh, 300, np.random.default_rng(5))
    not_exact, _ = _compare(
        demo, pts, nrm, rotation_step_deg=ROTATION_STEP_DEG, max_checks=MAX_CHECKS
    )
    assert not_exact >= 100  # the shortcut decided many points (136 when written)
    _compare(demo, pts[:60], nrm[:60])


@pytest.mark.slow
def test_box_near_the_table_statuses_equal_the_full_check() -> None:
    """A dense box on a table with a post, points pushed up to 12 mm into the part: collisions
    with table, post and part at every depth, marginal poses and joint limits."""
    rng = np.random.default_rng(9)
    with Cell(use_acl_cache=False) as c:
        add_box_on_table(c, 0.02, (1.05, -0.2, 0.75))
        pts, nrm, _ = sample_surface(c.work_object.mesh, 400, rng)
        pts[200:] += nrm[200:] * rng.uniform(-0.012, 0.0, size=(200, 1))
        not_exact, marginal = _compare(c, pts, nrm)
        assert not_exact >= 60 and marginal >= 20  # both verdicts (59 + 45 when written)


def test_no_points_and_bad_input(demo: Cell) -> None:
    st = probe_statuses(demo, np.zeros((0, 3)), np.zeros((0, 3)))
    assert st.statuses == () and st.exact.size == 0
    with pytest.raises(ValueError, match="normals_wobj"):
        probe_statuses(demo, np.zeros((2, 3)), np.zeros((3, 3)))
