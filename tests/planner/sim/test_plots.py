"""PNG plots of a validation report."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from planner.parts.stator import EPSILON_M, StatorGeometry
from planner.parts.stator_demo import nominal_T_base_wobj, stator_ah_points
from planner.sim.error_map import error_quantiles
from planner.sim.montecarlo import simulate_stator_ah
from planner.sim.plots import histogram_figure, save_validation_plots, scatter_figure


@pytest.fixture(scope="module")
def report():
    g = StatorGeometry.full_section()
    return simulate_stator_ah(
        stator_ah_points(g), g, nominal_T_base_wobj(), 30, np.random.default_rng(2), workers=1
    )


@pytest.mark.slow
def test_plots_are_written_as_png(report, tmp_path) -> None:
    paths = save_validation_plots(report, tmp_path / "plots")
    assert [p.name for p in paths] == ["histograms.png", "scatter.png", "error_map.png"]
    for p in paths:
        with Image.open(p) as im:
            assert im.format == "PNG" and im.size[0] > 800 and im.size[1] > 400
    assert not list((tmp_path / "plots").glob("*.tmp*"))  # atomic: no leftovers


@pytest.mark.slow
def test_scatter_shows_every_calibration_about_the_mean(report) -> None:
    fig = scatter_figure(report, np.asarray(EPSILON_M))
    ax_origin, ax_eps = fig.axes
    crosses = ax_eps.lines[0]  # the A-H procedure's points at epsilon
    y, z = crosses.get_xdata(), crosses.get_ydata()
    assert len(y) == report.n_ok
    assert abs(np.mean(y)) < 1e-9 and abs(np.mean(z)) < 1e-9
    assert len(ax_origin.lines[0].get_xdata()) == report.n_ok


def test_histograms_have_one_panel_per_table_row(report) -> None:
    fig = histogram_figure(report)
    titles = [ax.get_title() for ax in fig.axes]
    assert "WOCS yz-plane at epsilon" in titles and len(titles) == 9


def test_error_map_grows_away_from_the_probed_region(report) -> None:
    """The map is the 95.5 % quantile of each surface point's error length: at the far end of
    the 2 m section (rotation errors times 2 m) it is larger than beside the probe points, and
    it equals the quantile computed point by point."""
    emap = report.error_map
    assert emap is not None and emap.level_percent == 95.5
    y = emap.points_wobj[:, 1]
    near, far = emap.error_m[y > -0.6].mean(), emap.error_m[y < -1.6].mean()
    assert far > 1.5 * near > 0
    p = emap.points_wobj[:3]
    again = error_quantiles(report.delta_procedure, p, 95.5)
    np.testing.assert_allclose(again, emap.error_m[:3], rtol=1e-12)
    from planner.sim.rows import point_errors

    one = np.linalg.norm(point_errors(report.delta_procedure, p[:1]), axis=2)[:, 0]
    assert again[0] == pytest.approx(np.quantile(one, 0.955))
