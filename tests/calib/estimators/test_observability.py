"""Observability: full layouts pass, each missing DOF is named in words, the conditioning figure
agrees with the best fit's covariance, and bad layouts raise named errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from calib.errors import DegenerateGeometryError, NonFiniteError, ShapeError, UnobservableError
from calib.estimators.best_fit import best_fit
from calib.estimators.layout import random_face_layout
from calib.estimators.observability import WEAK_NOISE_GAIN, analyze_layout, require_observable
from calib.frames import random_transform, transform_directions, transform_points
from calib.probing import ProbePoint


def _p(i: str, pos, n) -> ProbePoint:
    n = np.asarray(n, dtype=float)
    return ProbePoint(i, tuple(map(float, pos)), tuple(n / np.linalg.norm(n)))


def _box() -> list[ProbePoint]:
    return [
        _p("a", (0, -0.1, -0.1), (1, 0, 0)),
        _p("b", (0, -0.8, -0.1), (1, 0, 0)),
        _p("c", (0, -0.4, -0.5), (1, 0, 0)),
        _p("d", (-0.1, -0.2, 0), (0, 0, 1)),
        _p("e", (-0.1, -0.7, 0), (0, 0, 1)),
        _p("f", (-0.1, 0, -0.2), (0, 1, 0)),
    ]


def _vertical_pair() -> list[ProbePoint]:
    """Two points on a vertical face at 45 deg between the side (+x) and short side (+y)."""
    n = (1.0, 1.0, 0.0)
    return [_p("v0", (0.1, 0.0, -0.1), n), _p("v1", (0.15, -0.05, -0.4), n)]


def _cylinder(axis_point, n: int = 8, radius: float = 0.1) -> list[ProbePoint]:
    """Points on a cylinder about an axis parallel to wobj z, with radial normals."""
    c = np.asarray(axis_point, dtype=float)
    out = []
    for k in range(n):
        a = 2 * np.pi * k / n + 0.3
        r = np.array([np.cos(a), np.sin(a), 0.0])
        out.append(_p(f"c{k}", c + radius * r + [0, 0, -0.05 - 0.03 * (k % 3)], r))
    return out


def test_box_layout_is_observable_and_ok() -> None:
    rep = require_observable(_box())
    assert rep.observable and rep.rank == 6 and rep.rating == "ok"
    assert rep.unconstrained == () and rep.messages == ()
    assert rep.noise_gain == pytest.approx(1.0 / rep.singular_values[-1])


@pytest.mark.parametrize(
    ("points", "names"),
    [
        ([p for p in _box() if p.id != "f"], ["translation along wobj y"]),
        (
            [*(p for p in _box() if p.id not in "de"), *_vertical_pair()],
            ["translation along wobj z"],
        ),
        (
            [
                _p("a", (0, 0, 0), (0, 0, 1)),
                _p("b", (1, 0, 0), (0, 0, 1)),
                _p("c", (0, 1, 0), (0, 0, 1)),
            ],
            ["translation along wobj x", "translation along wobj y", "rotation about wobj z"],
        ),
        (
            # a cylinder about z through the origin plus the top face: turning about z is free
            [*_cylinder((0, 0, 0)), _p("t", (0.05, 0, 0), (0, 0, 1))],
            ["rotation about wobj z"],
        ),
        (
            [*_cylinder((0.2, 0.3, 0)), _p("t", (0.25, 0.3, 0), (0, 0, 1))],
            ["rotation about an axis parallel to wobj z through (200.0, 300.0, 0.0) mm"],
        ),
    ],
)
def test_each_missing_dof_is_named(points, names) -> None:
    rep = analyze_layout(points)
    assert not rep.observable and rep.rating == "unobservable"
    assert sorted(m.name for m in rep.unconstrained) == sorted(names)
    assert rep.rank == 6 - len(names)
    with pytest.raises(UnobservableError) as info:
        require_observable(points)
    assert sorted(info.value.unconstrained) == sorted(names)
    assert isinstance(info.value, ValueError)


def test_translation_message_gives_the_reason() -> None:
    rep = analyze_layout([*(p for p in _box() if p.id not in "de"), *_vertical_pair()])
    assert rep.messages == (
        "translation along wobj z is not constrained: "
        "no point lies on a face whose normal has a z component",
    )


def test_two_general_faces_leave_their_common_line_free(rng: np.random.Generator) -> None:
    n1 = np.array([1.0, 0.0, 0.0])
    n2 = np.array([0.0, 0.6, 0.8])
    pts = [_p(f"a{k}", (0, y, z), n1) for k, (y, z) in enumerate([(0, 0), (0.5, 0.1), (0.2, 0.6)])]
    base = n2 * 0.3
    e = np.cross(n2, [1.0, 0.0, 0.0])
    pts += [_p("b0", base + 0.1 * e, n2), _p("b1", base + 0.5 * e + [-0.2, 0, 0], n2)]
    pts += [_p("b2", base + 0.3 * e + [-0.4, 0, 0], n2)]
    rep = analyze_layout(pts)
    assert rep.rank == 5
    (m,) = rep.unconstrained
    assert m.name == "translation along wobj (0, 0.8, -0.6)"
    line = np.cross(n1, n2) / np.linalg.norm(np.cross(n1, n2))
    assert abs(abs(m.motion[:3] @ line) - 1.0) < 1e-9 and np.abs(m.motion[3:]).max() < 1e-12


def test_collinear_points_are_diagnosed() -> None:
    pts = [
        _p("a", (0, 0, 0), (1, 0, 0)),
        _p("b", (0, 0.5, 0), (0, 0, 1)),
        _p("c", (0, 0.2, 0), (0, 1, 0)),
        _p("d", (0, 0.3, 0), (1, 0, 1)),
        _p("e", (0, 0.7, 0), (1, 1, 1)),
        _p("f", (0, 0.9, 0), (1, -1, 2)),
    ]
    rep = analyze_layout(pts)
    assert "all 6 points lie on one line" in rep.problems
    assert "rotation about wobj y" in [m.name for m in rep.unconstrained]
    with pytest.raises(UnobservableError, match="one line"):
        require_observable(pts)


def test_parallel_faces_are_diagnosed() -> None:
    pts = [
        _p("a", (0, 0, 0), (0, 0, 1)),
        _p("b", (1, 0, 0), (0, 0, 1)),
        _p("c", (0, 1, 0.2), (0, 0, 1)),
    ]
    pts.append(_p("d", (0.3, 0.3, -0.5), (0, 0, -1)))
    with pytest.raises(UnobservableError, match="all faces are parallel"):
        require_observable(pts)


def test_near_parallel_faces_rate_weak_and_gain_matches_best_fit_covariance() -> None:
    tilt = np.deg2rad(3.0)
    # the 'top' face is tilted only 3 deg away from the side face: z is barely seen
    n_top = (np.cos(tilt), 0, np.sin(tilt))
    pts = [
        *_box()[:3],
        _p("d", (0.2, -0.2, 0.1), n_top),
        _p("e", (0.2, -0.7, 0.1), n_top),
        _p("f", (-0.1, 0, -0.2), (0, 1, 0)),
    ]
    rep = analyze_layout(pts)
    assert rep.observable and rep.rating == "weak" and rep.noise_gain > WEAK_NOISE_GAIN
    # independent check: the largest standard deviation of the best fit in the same scaled,
    # centroid-based coordinates (sigma = 1) equals the noise gain
    q = np.array([p.position_m for p in pts])
    cov = best_fit(pts, q, np.eye(4)).unit_covariance
    c, L = q.mean(0), np.sqrt(np.mean(np.sum((q - q.mean(0)) ** 2, axis=1)))
    # origin-based (t, w) -> centroid-based scaled (t + w x c, L w)
    M = np.zeros((6, 6))
    M[:3, :3] = np.eye(3)
    M[:3, 3:] = -np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])
    M[3:, 3:] = L * np.eye(3)
    worst = np.sqrt(np.linalg.eigvalsh(M @ cov @ M.T).max())
    assert worst == pytest.approx(rep.noise_gain, rel=1e-6)


@settings(derandomize=True, max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_conditioning_is_invariant_under_rigid_motion_and_order(seed: int) -> None:
    rng = np.random.default_rng(seed)
    faces = random_face_layout(rng, (3, 2, 2), n_edge_points=1)
    rep = analyze_layout(faces.points)
    assert rep.observable
    T = random_transform(rng, 3.0, np.pi)
    moved = []
    for p in faces.points:
        edge = None if p.edge_normal is None else tuple(transform_directions(T, p.edge_normal))
        moved.append(
            ProbePoint(
                p.id,
                tuple(transform_points(T, p.position_m)),
                tuple(transform_directions(T, p.normal)),
                edge_normal=edge,
            )
        )
    perm = rng.permutation(len(moved))
    rep2 = analyze_layout([moved[i] for i in perm])
    np.testing.assert_allclose(rep2.singular_values, rep.singular_values, rtol=1e-9, atol=1e-12)


def test_bad_layouts_raise_named_errors() -> None:
    with pytest.raises(ShapeError, match="at least one"):
        analyze_layout([])
    with pytest.raises(ShapeError, match=r"points\[1\] must be a ProbePoint"):
        analyze_layout([_box()[0], (0.0, 0.0, 0.0)])  # type: ignore[list-item]
    with pytest.raises(DegenerateGeometryError, match="'a' and 'g' coincide"):
        analyze_layout([*_box(), _p("g", (0, -0.1, -0.1), (0, 0, 1))])
    with pytest.raises(ShapeError, match="unique"):
        analyze_layout([*_box(), _box()[0]])
    with pytest.raises(NonFiniteError, match=r"points\[x\].position_m"):
        ProbePoint("x", (0.0, np.nan, 0.0), (1.0, 0.0, 0.0))
    with pytest.raises(NonFiniteError, match=r"points\[x\].normal"):
        ProbePoint("x", (0.0, 0.0, 0.0), (np.inf, 0.0, 0.0))
