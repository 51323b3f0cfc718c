"""The compiled Gauss-Newton update (:mod:`calib.estimators.min_norm_kernel`) against the same
loop written with numpy's pseudo-inverse (what :func:`min_norm_update` ran before), over random
layouts: full rank, rank-deficient bases, few and many points, misplacements large and small."""

from __future__ import annotations

import numpy as np
import pytest

from calib.errors import NonFiniteError
from calib.estimators.layout import (
    ConstraintSet,
    constraint_jacobian,
    constraint_set,
    cross_rows,
    small_motion_matrix,
)
from calib.estimators.min_norm_kernel import _min_norm_solve
from calib.estimators.runners import fixed_motions, leading_points, min_norm_update
from calib.frames import small_motion
from calib.probing import ProbePoint

FloatArray = np.ndarray


def _numpy_update(
    cs: ConstraintSet, q: FloatArray, T0: FloatArray, c: FloatArray, L: float, V: FloatArray
) -> FloatArray:
    """The update as written with numpy before it was compiled (the reference)."""
    T = T0.copy()
    for _ in range(10):
        x = (q - T[:3, 3]) @ T[:3, :3]
        r = np.einsum("ij,ij->i", cs.normals, x - cs.nominal_m)
        J = constraint_jacobian(cs.normals, x - c)
        J[:, 3:] /= L
        step = -V @ (np.linalg.pinv(J @ V, rcond=1e-9) @ r)
        w = step[3:] / L
        T = T @ small_motion_matrix(np.concatenate([step[:3] - cross_rows(w, c), w]))
        if float(np.max(np.abs(step))) < 1e-9:
            break
    return T


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
def test_the_compiled_update_is_the_numpy_update(seed: int) -> None:
    rng = np.random.default_rng(seed)
    points = _random_box_points(rng, int(rng.integers(3, 12)))
    cs = constraint_set(points)
    sub = leading_points(cs, int(rng.integers(1, len(points) + 1)))  # often rank-deficient
    c, L = cs.centroid_m, float(cs.scale_m)
    V = fixed_motions(sub, c, L)
    delta = np.concatenate([rng.normal(0, 5e-3, 3), rng.normal(0, np.radians(1.0), 3)])
    T_true = small_motion(delta)
    q = sub.nominal_m @ T_true[:3, :3].T + T_true[:3, 3] + rng.normal(0, 20e-6, sub.nominal_m.shape)
    want = _numpy_update(sub, q, np.eye(4), c, L, V)
    got = min_norm_update(sub, q, np.eye(4), c, L, basis=V)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_the_solve_is_numpys_pseudo_inverse_with_its_cut_off() -> None:
    """Full rank, a column of zeros, two parallel columns, one column 1e-12 of the others (cut),
    and one at 1e-6 (kept): each as ``numpy.linalg.pinv(A, rcond=1e-9) @ b``."""
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
        weak = A @ np.linalg.qr(rng.normal(size=(5, 5)))[0]
        u, s, vt = np.linalg.svd(weak, full_matrices=False)
        s[-1] = s[0] * scale
        cases.append((u * s) @ vt)
    for M in cases:
        want = np.linalg.pinv(M, rcond=1e-9) @ b
        got = _min_norm_solve(np.ascontiguousarray(M), b)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert _min_norm_solve(np.zeros((4, 0)), b[:4]).shape == (0,)


def test_a_measurement_that_is_not_finite_is_named() -> None:
    cs = constraint_set(_random_box_points(np.random.default_rng(1), 6))
    q = cs.nominal_m.copy()
    q[2, 1] = np.nan
    with pytest.raises(NonFiniteError, match="measured"):
        min_norm_update(cs, q, np.eye(4))
