"""Confidence intervals against scipy on known normal samples, the paper's signed yz-plane
error convention, point and frame errors, and the Markdown table."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats as sps

from calib.errors import NonFiniteError, ShapeError
from calib.frames import make_transform, matrix_from_rotvec, random_transform, small_motion
from calib.stats import (
    CONFIDENCE_LEVELS,
    confidence_intervals,
    frame_errors,
    point_errors_wobj,
    signed_radial_error,
    to_markdown,
)

EPSILON = np.array([0.0, -1.0, -0.1])


def test_normal_intervals_match_scipy(rng: np.random.Generator) -> None:
    mu, sigma = 2e-4, 1.5e-4
    x = rng.normal(mu, sigma, size=400)
    table = confidence_intervals(x, "origin y")
    assert [r.level for r in table.rows] == list(CONFIDENCE_LEVELS)
    for r in table.rows:
        lo, hi = sps.norm.interval(r.level, loc=x.mean(), scale=x.std(ddof=1))
        assert r.lower == pytest.approx(lo, rel=1e-9)
        assert r.upper == pytest.approx(hi, rel=1e-9)
    # 95.5 % is the paper's "2 sigma"
    assert table.row("origin y", 0.955).z == pytest.approx(2.0, abs=0.01)


def test_intervals_recover_the_true_sigma_and_empirical_quantiles(
    rng: np.random.Generator,
) -> None:
    sigma = 3e-4
    x = rng.normal(-1e-4, sigma, size=200_000)
    table = confidence_intervals(x, "eps")
    for r in table.rows:
        assert r.half_width == pytest.approx(sps.norm.ppf(0.5 + r.level / 2) * sigma, rel=0.01)
    # empirical quantiles of |x - mean| agree with the normal ones where the sample resolves them
    for level, tol in ((0.955, 0.01), (0.99, 0.015), (0.999, 0.04)):
        r = table.row("eps", level)
        assert r.empirical_resolved
        assert r.empirical_half_width == pytest.approx(r.half_width, rel=tol)
    assert table.row("eps", 0.99999).empirical_resolved  # 2 samples expected outside
    assert not table.row("eps", 0.999999).empirical_resolved  # 0.2 expected: unresolved


def test_heavy_tails_show_in_the_empirical_column(rng: np.random.Generator) -> None:
    x = rng.standard_t(df=3, size=100_000) * 1e-4
    r = confidence_intervals(x, "t").row("t", 0.999)
    assert r.empirical_half_width > 1.3 * r.half_width  # the normal model underestimates


def test_signed_radial_error_follows_the_paper() -> None:
    e = np.array([[0.1, 3.0, 4.0], [-0.1, 3.0, 4.0], [0.0, 0.0, -2.0], [-2.0, 0.0, 0.0]])
    np.testing.assert_allclose(signed_radial_error(e), [5.0, -5.0, 2.0, -0.0])
    np.testing.assert_allclose(
        signed_radial_error(e, "xyz"), [np.sqrt(25.01), -np.sqrt(25.01), 2.0, -2.0]
    )
    assert signed_radial_error(e[None]).shape == (1, 4)


def test_point_and_frame_errors_match_known_motions(rng: np.random.Generator) -> None:
    T_true = random_transform(rng, 1.0, 2.0)
    angle = np.deg2rad(0.01)
    T_rot = T_true @ make_transform(matrix_from_rotvec([angle, 0.0, 0.0]))  # about wobj x
    err = point_errors_wobj(T_true, T_rot, EPSILON)
    # rotating about x moves epsilon = (0, -1, -0.1) within the yz-plane
    expected = matrix_from_rotvec([angle, 0.0, 0.0]) @ EPSILON - EPSILON
    np.testing.assert_allclose(err, expected, atol=1e-15)
    assert abs(err[0]) < 1e-15
    delta = np.array([1e-4, -2e-4, 3e-4, 1e-5, -2e-5, 3e-5])
    T_est = np.stack([T_true @ small_motion(delta), T_true])
    np.testing.assert_allclose(frame_errors(T_true, T_est), [delta, np.zeros(6)], atol=1e-15)
    errs = point_errors_wobj(T_true, T_est, EPSILON)
    assert errs.shape == (2, 3)
    lin = delta[:3] + np.cross(delta[3:], EPSILON)
    np.testing.assert_allclose(errs[0], lin, atol=1e-8)


def test_markdown_table_in_mm_and_degrees(rng: np.random.Generator) -> None:
    t = confidence_intervals(rng.normal(0.0, 1e-4, 400), "WOCS yz-plane origin", levels=[0.955])
    t = t + confidence_intervals(
        rng.normal(0.0, np.deg2rad(0.001), 400), "WOCS rotation y-axis", "rad", [0.955, 0.9999]
    )
    md = to_markdown(t, events_per_year={"WOCS yz-plane origin": 1000.0})
    lines = md.strip().splitlines()
    assert lines[0].startswith("| Quantity | Confidence level [%] | Frequency [times/year]")
    assert len(lines) == 2 + 3
    assert "| WOCS yz-plane origin | 95.5 | 45 |" in md
    hw_mm = t.row("WOCS yz-plane origin", 0.955).half_width * 1e3
    assert f"± {hw_mm:.4g} mm" in md
    hw_deg = np.rad2deg(t.row("WOCS rotation y-axis", 0.9999).half_width)
    assert f"± {hw_deg:.4g} deg" in md
    assert "—" in md  # 400 samples cannot resolve 99.99 % empirically
    assert "Frequency" not in t.to_markdown()


def test_bad_input_raises_named_errors() -> None:
    with pytest.raises(ShapeError, match="samples"):
        confidence_intervals([1.0], "x")
    with pytest.raises(ShapeError, match="samples"):
        confidence_intervals(np.zeros((3, 2)), "x")
    with pytest.raises(NonFiniteError, match="samples"):
        confidence_intervals([1.0, np.nan, 2.0], "x")
    with pytest.raises(ShapeError, match="levels"):
        confidence_intervals([1.0, 2.0], "x", levels=[0.5, 1.0])
    with pytest.raises(ShapeError, match="unit"):
        confidence_intervals([1.0, 2.0], "x", unit="mm")  # type: ignore[arg-type]
    with pytest.raises(ShapeError, match="errors_wobj"):
        signed_radial_error(np.zeros((4, 2)))
    with pytest.raises(ShapeError, match="plane"):
        signed_radial_error(np.zeros(3), plane="xy")  # type: ignore[arg-type]
    with pytest.raises(ShapeError, match="no row"):
        confidence_intervals([1.0, 2.0], "x").row("y", 0.99)
    with pytest.raises(ShapeError, match="T_base_wobj_est"):
        point_errors_wobj(np.eye(4), np.eye(3), EPSILON)


def test_normal_half_widths_are_the_tables_half_widths() -> None:
    """The report's rows take :func:`normal_half_widths` (no empirical quantiles): the same
    numbers as the table's normal intervals, to the bit."""
    from calib.stats import confidence_intervals, normal_half_widths

    x = np.random.default_rng(4).normal(0.0, 2e-4, 10_001)
    levels = [0.5, 0.955, 0.9999]
    want = [r.half_width for r in confidence_intervals(x, "q", "m", levels).rows]
    assert normal_half_widths(x, levels) == want
