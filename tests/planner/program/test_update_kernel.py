"""The compiled update of a steered program (:mod:`planner.program.update_kernel`, through
:func:`planner.program.steering.steer`) against ``calib``'s numpy update
(:func:`calib.estimators.runners.min_norm_update`, the reference) over random layouts: full
rank, rank-deficient bases, few and many points; its pseudo-inverse against numpy's."""

from __future__ import annotations

import numpy as np
import pytest

from calib.errors import NonFiniteError
from calib.estimators.layout import constraint_set
from calib.estimators.runners import fixed_motions, min_norm_update
from calib.frames import small_motion
from calib.probing import ProbePoint
from planner.program.steering import ITERATIONS, steer
from planner.program.update_kernel import MAX_SWEEPS, min_norm_solve


def _random_box_points(rng: np.random.Generator, n: int) -> list[ProbePoint]:
    """``n`` points on the faces of a random box (a part's layout), metres."""
    size = rng.uniform(0.05, 1.0, 3)
    out = []
    for i in range(n):
        axis = int(rng.integers(3))
        sign = 1.0 if rng.random() < 0.5 else -1.0
        p = rng.uniform(0.1, 0.9, 3) * size
        p[axis] = size[axis] if sign > 0 else 0.0
        normal = np.zeros(3)
        normal[axis] = sign
        out.append(ProbePoint(f"P{i}", tuple(p), tuple(normal)))
    return out


@pytest.mark.parametrize("seed", range(40))
def test_the_compiled_update_is_calibs_update(seed: int) -> None:
    """The first ``k`` points of a random layout (often fixing fewer than six motions), the
    part misplaced by millimetres and a degree, measured with 20 um of noise."""
    rng = np.random.default_rng(seed)
    points = _random_box_points(rng, int(rng.integers(3, 12)))
    whole = constraint_set(points)
    c, L = whole.centroid_m, float(whole.scale_m)
    first = points[: int(rng.integers(1, len(points) + 1))]
    cs = constraint_set(first)
    delta = np.concatenate([rng.normal(0, 5e-3, 3), rng.normal(0, np.radians(1.0), 3)])
    T_true = small_motion(delta)
    true_m = np.array([p.position_m for p in first]) @ T_true[:3, :3].T + T_true[:3, 3]
    measured = {p.id: q + rng.normal(0, 20e-6, 3) for p, q in zip(first, true_m, strict=True)}
    q = np.array([measured[p.id] for p in first])
    want = min_norm_update(cs, q, np.eye(4), c, L, ITERATIONS, fixed_motions(cs, c, L))
    got = steer(first, measured, np.eye(4), c, L)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_the_solve_is_numpys_pseudo_inverse_with_its_cut_off() -> None:
    """Full rank, a column of zeros, two parallel columns, one singular value 1e-12 of the
    largest (cut) and one 1e-6 (kept): each as ``numpy.linalg.pinv(A, rcond=1e-9) @ b``."""
    rng = np.random.default_rng(7)
    A = rng.normal(size=(8, 5))
    b = rng.normal(size=8)
    cases = [A.copy()]
    zero = A.copy()
    zero[:, 2] = 0.0
    cases.append(zero)
    parallel = A.copy()
    parallel[:, 3] = 2.0 * parallel[:, 1]
    cases.append(parallel)
    for scale in (1e-12, 1e-6):
        u, s, vt = np.linalg.svd(A, full_matrices=False)
        s[-1] = s[0] * scale
        cases.append((u * s) @ vt)
    for M in cases:
        want = np.linalg.pinv(M, rcond=1e-9) @ b
        got, _ = min_norm_solve(np.ascontiguousarray(M), b)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert min_norm_solve(np.zeros((4, 0)), b[:4])[0].shape == (0,)


def test_the_solve_converges_on_wide_and_rank_deficient_matrices() -> None:
    """Random matrices of up to 6 columns, wide ones and ones of lower rank among them, take
    far fewer sweeps than the limit (a tolerance near machine precision kept rotating nearly
    null columns until the limit), and still give numpy's pseudo-inverse."""
    rng = np.random.default_rng(3)
    worst = 0
    for _ in range(2000):
        m, r = int(rng.integers(1, 10)), int(rng.integers(1, 7))
        rank = int(rng.integers(1, min(m, r) + 1))
        A = np.ascontiguousarray(rng.normal(size=(m, rank)) @ rng.normal(size=(rank, r)))
        b = rng.normal(size=m)
        y, sweeps = min_norm_solve(A, b)
        worst = max(worst, sweeps)
        want = np.linalg.pinv(A, rcond=1e-9) @ b
        np.testing.assert_allclose(y, want, rtol=0, atol=1e-9 * max(1.0, np.abs(want).max()))
    assert worst < 12 < MAX_SWEEPS


def test_a_measurement_that_is_not_finite_is_named() -> None:
    points = _random_box_points(np.random.default_rng(1), 6)
    measured = {p.id: np.asarray(p.position_m, float) for p in points}
    measured["P2"] = np.array([0.0, np.nan, 0.0])
    with pytest.raises(NonFiniteError, match="NaN"):
        steer(points, measured, np.eye(4), np.zeros(3), 0.3)


def test_the_preloaded_kernel_is_the_one_an_update_runs() -> None:
    """A fork server's :func:`load_kernel` compiles (or loads) the version of the kernel for the
    argument types :func:`steer` passes: a worker's first update then compiles nothing."""
    from planner.program import update_kernel

    update_kernel.load_kernel()
    before = set(update_kernel.gauss_newton.signatures)
    points = _random_box_points(np.random.default_rng(2), 7)
    measured = {p.id: np.asarray(p.position_m, float) + 1e-4 for p in points}
    steer(points, measured, np.eye(4), np.zeros(3), 0.3)
    assert set(update_kernel.gauss_newton.signatures) == before
