"""Safe search starts (planner.program.safety) in every exporter, and the nominal-frame RAPID
program run in the RAPID interpreter against a misplaced part."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from calib.frames import invert_transform, make_transform, matrix_from_rotvec, transform_points
from calib.plan.file import load_plan
from planner.export import export_files
from planner.export.job import ToolData, build_job
from planner.export.rapid import export_rapid
from planner.program.safety import SafetySpec
from tests.box_part import BoxProbe, distance_to_box
from tests.planner.export.test_export_rapid_adaptive import full_misplacement, rapid_search
from tests.rapid_interp import Machine

VALID = Path(__file__).resolve().parents[2] / "data" / "plans" / "valid_three_two_one.json"


def test_bound_holds_for_sampled_misplacements(rng: np.random.Generator) -> None:
    """A start at the clearance stays >= the sensing distance from every misplaced face, random
    or worst case; in the worst case 0.5 mm inside the margin does not (the bound is tight)."""
    spec = SafetySpec(pivot_wobj_m=(0.0, -0.3, -0.1))
    c = np.asarray(spec.pivot_wobj_m)
    n = np.array([1.0, 0.0, 0.0])
    worst_ok, worst_short = np.inf, np.inf
    for k in range(400):
        p = np.array([0.0, rng.uniform(-0.9, 0.0), rng.uniform(-0.3, 0.0)])
        if k % 2:  # random directions at the tolerance
            axis, t = rng.normal(size=3), rng.normal(size=3)
        else:  # the worst case: translation along the normal, rotation lifting p along it
            axis, t = np.cross(p - c, n), n.copy()
        R = matrix_from_rotvec(axis / np.linalg.norm(axis) * spec.max_angle_rad)
        t *= spec.max_translation_m / np.linalg.norm(t)
        T = make_transform(R, c - R @ c + t)  # nominal -> true, at the tolerance
        n_true, p_true = R @ n, transform_points(T, p)
        clear = spec.start_clearance_m(p)
        worst_ok = min(worst_ok, float(n_true @ (p + clear * n - p_true)))
        short = clear - spec.margin_m - 0.0005
        worst_short = min(worst_short, float(n_true @ (p + short * n - p_true)))
    assert worst_ok >= spec.sensing_distance_m
    assert worst_short < spec.sensing_distance_m


def test_short_plan_starts_are_moved_out_in_every_format() -> None:
    """The test plan starts its searches 30 mm out: too close for 20 mm / 3 deg; every
    program starts them at the safe clearance instead."""
    plan = load_plan(VALID)
    job = build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4)))
    for t, p in zip(job.targets, plan.points, strict=True):
        n = np.asarray(p.normal)
        face = t.T_wobj_start[:3, 3] if t.kind == "edge" else np.asarray(p.position_m)
        out = float(n @ (t.safe_start[:3, 3] - face))
        assert out >= job.safety.start_clearance_m(face) - 1e-12
        assert out > p.search.start_offset_m  # moved out: the plan's start is not safe
    rapid = export_rapid(job)
    for t in job.targets:
        assert f"MoveJ p{t.point_id}_safe," in rapid
        assert re.search(rf"^\s+PROC Probe_p{t.point_id}\(num i\)$", rapid, re.M)
    src = export_files(job, "krl")[".src"]
    assert all(f"PTP x{t.point_id}_safe" in src for t in job.targets)
    assert "NOMINAL FRAME" in src and "SAFE FOR: part misplaced up to 20.0 mm" in src
    ur = export_files(job, "urscript")[".script"]
    assert "NOMINAL FRAME" in ur and ur.count('probe("') == len(job.targets)
    from tests.planner.export.test_export_fanuc import (
        with_arms,  # FANUC's CONFIG needs a configuration
    )

    ls = export_files(with_arms(job), "fanuc")[".ls"]  # poses checked in test_export_fanuc.py
    assert "NOMINAL FRAME" in ls and ls.count("SKIP CONDITION DI[1]=ON") == len(job.targets)
    assert "NOMINAL FRAME" in rapid


@pytest.mark.parametrize("seed", range(10))
def test_nominal_program_never_starts_a_search_near_the_part(seed: int) -> None:
    plan = load_plan(VALID)
    rng = np.random.default_rng(seed)
    T_nom = make_transform(matrix_from_rotvec([0.0, 0.2, 0.1]), [1.4, -0.3, 0.8])
    T_true = T_nom @ full_misplacement(plan, rng)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    m = Machine(export_rapid(job), rapid_search(BoxProbe(T_true)))
    m.main()
    # nominal frame: wobjCal stays the nominal frame
    assert np.abs(m.wobj_matrix_m("wobjCal") - T_nom).max() < 1e-6
    ok = m.globals["measuredOk"]
    assert sum(ok[:5]) == 5  # the approach points are all found
    sd = plan.validation.sensor.sensing_distance_m
    T_true_base = invert_transform(T_true)
    for mo in m.motions:
        if mo.kind == "SearchL":
            dist = distance_to_box(transform_points(T_true_base, mo.start_m))
            assert (abs(dist) < 1e-9) if mo.neg_flank else (dist > sd), dist
        if mo.kind == "MoveJ":
            assert distance_to_box(transform_points(T_true_base, mo.target_m)) > sd
    # measured points lie on the true part
    for i in range(5):
        p = np.array([m.globals["measured"][i].f[c] for c in "xyz"]) / 1000.0
        assert abs(distance_to_box(transform_points(T_true_base, p))) < 1e-9
