"""The step-by-step estimate of :func:`calib.estimators.runners.run_best_fit` (the frame each
later search is commanded in)."""

from __future__ import annotations

import numpy as np
import pytest

from calib.estimators.layout import search_constraint_set
from calib.estimators.runners import fixed_motions, leading_points, min_norm_update
from calib.probing import ProbePoint, SearchSpec

TOP = (0.0, 0.0, 1.0)


def _edge(pid: str, p: tuple[float, float, float], d: tuple[float, float, float]) -> ProbePoint:
    return ProbePoint(pid, p, TOP, SearchSpec("edge", 0.03, 0.04, d), d)


#: The plate's suggested layout with a proximity sensor (mm in the names, metres here): three
#: approaches on the top, then edge searches toward +x at y = 215.9, toward +y and -y both at
#: x = 101.6 (parallel rows: together they fix y, not the turn about z), then -x at y = 88.9.
PLATE = [
    ProbePoint("S1", (0.13123, 0.28492, 0.0127), TOP),
    ProbePoint("S2", (0.01695, 0.04451, 0.0127), TOP),
    ProbePoint("S3", (0.18822, 0.16735, 0.0127), TOP),
    _edge("S4", (0.2032, 0.2159, 0.0127), (1.0, 0.0, 0.0)),
    _edge("S5", (0.1016, 0.3048, 0.0127), (0.0, 1.0, 0.0)),
    _edge("S6", (0.1016, 0.0, 0.0127), (0.0, -1.0, 0.0)),
    _edge("S7", (0.0, 0.0889, 0.0127), (-1.0, 0.0, 0.0)),
]


def test_parallel_edge_searches_measured_apart_do_not_turn_the_estimate() -> None:
    """S5 and S6 measured 60 um apart along x and 0.044 mm apart in width (sensor noise) once
    turned the estimate by 40 degrees and commanded S7 63 m away ("not detecting at start")."""
    cs = search_constraint_set(PLATE)
    sub = leading_points(cs, 6)
    q = np.array([p.position_m for p in PLATE[:6]], dtype=np.float64)
    q[4, 0] += 60e-6  # S5's track ran 60 um off its nominal x
    q[5, 1] += 0.044e-3  # S6 reports the plate 0.044 mm narrower
    T = min_norm_update(sub, q, np.eye(4), cs.centroid_m, cs.scale_m)
    assert np.linalg.norm(T[:3, 3]) < 0.1e-3
    assert np.degrees(np.arccos(np.clip((np.trace(T[:3, :3]) - 1) / 2, -1, 1))) < 1e-3
    # the turn about z is not among the motions the six fix; the seven fix all six
    V = fixed_motions(sub, cs.centroid_m, cs.scale_m)
    assert V.shape == (6, 5)
    assert fixed_motions(cs, cs.centroid_m, cs.scale_m).shape == (6, 6)


def test_a_fixed_motion_is_still_updated_as_before() -> None:
    """With all seven points the update is the least-squares fit: a true shift is found."""
    cs = search_constraint_set(PLATE)
    shift = np.array([0.4e-3, -0.3e-3, 0.2e-3])
    q = np.array([p.position_m for p in PLATE], dtype=np.float64) + shift
    T = min_norm_update(cs, q, np.eye(4))
    assert T[:3, 3] == pytest.approx(shift, abs=1e-9)
