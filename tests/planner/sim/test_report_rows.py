"""What each report row measures (planner.sim.rows): the signed error measures, samples about
the mean with the bias apart, and the predicted spread against a brute-force Gaussian sample."""

from __future__ import annotations

import numpy as np
import pytest

from planner.sim.rows import (
    RowSpec,
    frame_rows,
    measure,
    point_sigma,
    predicted_sigma,
    samples_and_bias,
)


def test_measures_are_signed_like_the_paper() -> None:
    e = np.array([[0.1, 3.0, 4.0], [-0.1, 3.0, 4.0], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(measure(e, "yz"), [5.0, -5.0, 0.0])
    np.testing.assert_allclose(measure(e, "x"), [0.1, -0.1, 0.0])
    np.testing.assert_allclose(measure(e, "xy"), np.hypot([0.1, -0.1, 0], [3, 3, 0]) * [1, 1, 1])
    np.testing.assert_allclose(
        measure(e, "xyz"), [np.linalg.norm(e[0]), -np.linalg.norm(e[1]), 0.0]
    )


@pytest.mark.parametrize("components", ["xyz", "yz", "xy", "xz"])
def test_a_length_is_numpys_norm_to_the_bit(components: str, rng: np.random.Generator) -> None:
    """The rows sum a length's squares themselves (fast on millions of samples): the same
    numbers as ``numpy.linalg.norm`` of the axes, signed by the remaining one."""
    e = rng.normal(0.0, 1e-4, (300, 40, 3))
    axes = ["xyz".index(c) for c in components]
    sign = 0 if components == "xyz" else next(i for i in range(3) if i not in axes)
    length = np.linalg.norm(e[..., axes], axis=-1)
    assert np.array_equal(measure(e, components), np.where(e[..., sign] >= 0, length, -length))


def test_frame_row_samples_and_bias(rng: np.random.Generator) -> None:
    delta = rng.normal(0.0, 1e-4, (500, 6)) + np.array([1e-4, 0, 0, 0, 0, 0])
    rows = frame_rows((95.5,))
    s, bias = samples_and_bias(rows[0], delta)
    assert bias == pytest.approx(delta[:, 0].mean()) and abs(s.mean()) < 1e-15
    assert predicted_sigma(rows[3], np.diag([1, 2, 3, 4, 5, 6.0])) == pytest.approx(2.0)


@pytest.mark.parametrize("components", ["yz", "xyz", "z"])
def test_predicted_spread_of_a_point_row_matches_a_gaussian_sample(
    components: str, rng: np.random.Generator
) -> None:
    """The same measure applied to 200,000 Gaussian frame errors gives the same spread."""
    A = rng.normal(size=(6, 6)) * np.array([1e-4] * 3 + [1e-4] * 3)
    cov = A @ A.T
    spec = RowSpec(
        "k",
        "k",
        "mm",
        (95.5,),
        points_wobj=np.array([[0.0, -1.0, -0.1], [0.3, 0.2, 0.0]]),
        components=components,
    )
    delta = rng.multivariate_normal(np.zeros(6), cov, size=200_000)
    s, _ = samples_and_bias(spec, delta)
    assert predicted_sigma(spec, cov) == pytest.approx(float(np.std(s, ddof=1)), rel=0.01)


def test_point_sigma_of_one_axis_is_exact() -> None:
    S = np.array([np.diag([1.0, 4.0, 9.0]), np.diag([1.0, 16.0, 1.0])])
    assert point_sigma(S, "y") == pytest.approx(np.sqrt(10.0))


def test_a_failed_x_offset_run_leaves_the_row_to_the_other_trials(
    rng: np.random.Generator,
) -> None:
    """One trial whose x-offset search failed is listed as a failure; the row is the others'."""
    from types import SimpleNamespace

    from calib.models import ProximitySensor
    from planner.sim.predict import Prediction
    from planner.sim.report_points import XOFFSET_KEYS
    from planner.sim.summary import build_report
    from planner.sim.trial import TrialResult

    targets = np.zeros((2, 3, 3))
    setup = SimpleNamespace(
        xoffset=SimpleNamespace(targets_wobj=targets),
        method="hultman2013",
        program=SimpleNamespace(describe=lambda: ["RAPID, adaptive A-H", "1. a step"]),
        sensor=ProximitySensor(),
        noise_figures=(),
    )
    spec = RowSpec(
        XOFFSET_KEYS[1], "x", "mm", (95.5,), points_wobj=targets.reshape(-1, 3), components="x"
    )
    x = rng.normal(0.0, 1e-4, (50, 6))
    x[7] = np.nan
    results = [
        TrialResult("", (), (), np.zeros(6), np.zeros(6), xi, "PX1_11: why" if i == 7 else "")
        for i, xi in enumerate(x)
    ]
    pred = Prediction(np.eye(6) * 1e-8, np.eye(6) * 1e-8, xoffset_sigma_m=1e-4)
    report = build_report(setup, results, [], None, [spec], pred, None, 1.0, 1, 0)  # type: ignore[arg-type]
    assert report.failures == {"x-offset PX1_11: why": 1} and report.n_ok == 50
    assert np.isfinite(report.rows[0].procedure)
    assert len(report.samples_procedure[XOFFSET_KEYS[1]]) == 49 * 6


def test_rows_on_two_threads_are_the_rows_of_one(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``build_rows`` computes large reports on two threads: the same rows, samples and order
    as one thread (frame, point, extra-error and protocol rows alike)."""
    from planner.sim import summary
    from planner.sim.summary import RowInputs, build_rows

    specs = [
        *frame_rows((95.5, 99.99)),
        RowSpec("pts", "points", "mm", (95.5,), points_wobj=rng.normal(0, 0.3, (40, 3))),
        RowSpec(
            "yz", "plane", "mm", (99.99,), points_wobj=rng.normal(0, 0.3, (7, 3)), components="yz"
        ),
        RowSpec("extra", "x", "mm", (95.5,), points_wobj=np.zeros((3, 3)), components="x"),
    ]
    cov = np.diag(rng.uniform(1e-9, 1e-8, 6))
    inputs = [
        RowInputs(
            rng.normal(0, 1e-4, (300, 6)),
            cov,
            {"extra": (rng.normal(0, 1e-4, (300, 3, 3)), 2e-4)},
            rng.normal(0, 1e-4, (60, 6)),
        )
        for _ in range(2)
    ]
    monkeypatch.setattr(summary, "PARALLEL_SAMPLES", 10**12)
    one = build_rows(specs, *inputs)
    monkeypatch.setattr(summary, "PARALLEL_SAMPLES", 0)
    two = build_rows(specs, *inputs)
    assert [r.key for r in two[0]] == [r.key for r in one[0]]
    for a, b in zip(one[0], two[0], strict=True):
        assert repr(a) == repr(b)
    for k in (1, 2):
        assert one[k].keys() == two[k].keys()
        for key in one[k]:
            np.testing.assert_array_equal(one[k][key], two[k][key])
