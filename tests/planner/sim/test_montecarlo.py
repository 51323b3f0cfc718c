"""Monte Carlo validation: exactness without noise, repeatability, robustness report."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from calib.errors import InputError, ShapeError
from calib.models.proximity import ProximitySensor
from calib.models.robot_error import RobotErrorModel
from calib.probing import SearchSpec
from planner.parts.stator import StatorGeometry
from planner.parts.stator_demo import nominal_T_base_wobj, stator_ah_points
from planner.parts.stator_mesh import build_stator_mesh
from planner.sim.montecarlo import simulate_stator_ah

GEOM = StatorGeometry.full_section()
POINTS = stator_ah_points(GEOM)
T_NOM = nominal_T_base_wobj()


def test_noise_free_flat_part_gives_the_true_pose() -> None:
    """No noise, a point sensor and a flat part without holes or bulge: the A-H procedure
    driven by the simulated searches finds the misplaced part to ~1e-9."""
    flat = dataclasses.replace(GEOM, n_layers=0, bolt_bulge_m=0.0)
    report = simulate_stator_ah(
        POINTS,
        GEOM,
        T_NOM,
        3,
        np.random.default_rng(3),
        sensor=ProximitySensor.ideal(),
        robot_error=RobotErrorModel.none(),
        mesh=build_stator_mesh(flat),
        edge_tolerance_m=1e-13,
    )
    assert report.n_ok == 3, report.failures
    assert np.abs(report.delta_procedure[:, :3]).max() < 1e-9
    assert np.abs(report.delta_procedure[:, 3:]).max() < 1e-9
    assert np.abs(report.delta_best_fit).max() < 1e-9


@pytest.mark.slow
def test_seeded_run_is_repeatable_across_workers_and_sane() -> None:
    a = simulate_stator_ah(POINTS, GEOM, T_NOM, 200, np.random.default_rng(11), workers=2)
    b = simulate_stator_ah(POINTS, GEOM, T_NOM, 200, np.random.default_rng(11), workers=1)
    assert np.array_equal(a.delta_procedure, b.delta_procedure)
    assert np.array_equal(a.delta_best_fit, b.delta_best_fit)
    assert a.failures == b.failures and a.landings == b.landings
    assert a.n_ok >= 190
    # sane: origin within a millimetre, rotations within 1 deg (about y, the weakest: F and H
    # run their edge searches from their face approaches' measured points, as the RAPID
    # program does, 0.37 deg at 95.5 %), epsilon within 2 mm
    assert np.abs(a.delta_procedure[:, :3]).max() < 1e-3
    assert np.abs(a.delta_procedure[:, 3:]).max() < math.radians(1.0)
    eps = a.row("yz_epsilon", 95.5)
    assert 0.05 < eps.procedure < 2.0 and abs(eps.procedure_bias) < 1.0
    # errors scatter: a run with another seed differs
    c = simulate_stator_ah(POINTS, GEOM, T_NOM, 60, np.random.default_rng(12), workers=1)
    assert not np.array_equal(c.delta_procedure[:60], a.delta_procedure[:60])
    text = a.to_markdown()
    assert "WOCS yz-plane at epsilon" in text and "± 0.40 mm" in text


@pytest.mark.slow
def test_the_program_starts_from_the_safe_start_not_the_plans_start() -> None:
    """A plan start 8 mm out is inside the sensor's reach of a part misplaced by 20 mm; the
    program starts every search at its safe start (``planner.program.safety``), so no search
    starts detecting, and a search too short to reach the face from there is what fails."""
    near = SearchSpec("approach", start_offset_m=0.008, overtravel_m=0.060)
    points = stator_ah_points(GEOM, approach=near)
    report = simulate_stator_ah(points, GEOM, T_NOM, 60, np.random.default_rng(5), workers=1)
    assert not any("already detecting at start" in k for k in report.failures), report.failures
    assert report.n_ok == 60 - sum(report.failures.values())
    # a search that ends only 1 mm past the nominal face misses a part misplaced away
    short = SearchSpec("approach", start_offset_m=0.050, overtravel_m=0.001)
    report = simulate_stator_ah(
        stator_ah_points(GEOM, approach=short), GEOM, T_NOM, 60, np.random.default_rng(5),
        workers=1,
    )  # fmt: skip
    missed = {k: v for k, v in report.failures.items() if "no detection" in k}
    assert sum(missed.values()) >= 10, report.failures
    assert "no detection" in report.to_markdown()


def test_bad_arguments_are_named() -> None:
    with pytest.raises(ShapeError, match="n_trials"):
        simulate_stator_ah(POINTS, GEOM, T_NOM, 1, np.random.default_rng(0))
    with pytest.raises(InputError, match="procedure"):
        simulate_stator_ah(POINTS, GEOM, T_NOM, 10, np.random.default_rng(0), procedure="magic")
    with pytest.raises(ShapeError, match="missing"):
        simulate_stator_ah({"A": POINTS["A"]}, GEOM, T_NOM, 10, np.random.default_rng(0))


@pytest.mark.slow
def test_cell_vets_every_search_and_counts_unreachable_ones() -> None:
    from planner.demo import make_demo_cell

    cell = make_demo_cell(GEOM)
    try:
        T_cell = cell.T_world_wobj.copy()
        ok = simulate_stator_ah(POINTS, GEOM, T_NOM, 2, np.random.default_rng(4), cell=cell)
        assert ok.n_ok == 2, ok.failures
        assert np.allclose(cell.T_world_wobj, T_cell)  # put back
        # a plan whose part is placed 1.2 m further away than the cell can reach
        far = T_NOM.copy()
        far[0, 3] += 1.2
        bad = simulate_stator_ah(POINTS, GEOM, far, 2, np.random.default_rng(4), cell=cell)
        assert bad.n_ok == 0
        assert all("unreachable or colliding" in k for k in bad.failures), bad.failures
        # the cell's kind, carried from the hook to the report: out of reach, not a search
        kinds = {f.failed.cause.kind if f.failed else None for f in bad.failure_counts}
        assert kinds == {"reach"}, bad.failure_counts
    finally:
        cell.close()
