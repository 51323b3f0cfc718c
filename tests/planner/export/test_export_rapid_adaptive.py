"""The adaptive A-H RAPID program, run in a RAPID interpreter against an ideal part, does what
:func:`calib.paper.stator_procedure.run_stator_procedure` does; and no search starts near the
part."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from calib.frames import invert_transform, make_transform, transform_points
from calib.paper.stator_procedure import run_stator_procedure
from calib.plan.file import load_plan
from calib.plan.measurements import measurements_from_json
from calib.probing import SearchCommand
from calib.procedures.hultman2013 import points_by_role
from planner.export.job import ToolData, build_job
from planner.export.rapid import export_rapid
from planner.plan_cell import nominal_T_base_wobj
from tests.box_part import BoxProbe, distance_to_box
from tests.rapid_interp import Machine

PLAN = Path(__file__).resolve().parents[3] / "assets" / "plans" / "stator_section_ah.json"


def rapid_search(probe: BoxProbe):  # type: ignore[no-untyped-def]
    """The interpreter's SearchL callback: one command to the ideal probe."""

    def search(start, end, axis, neg_flank):  # type: ignore[no-untyped-def]
        length = float(np.linalg.norm(end - start))
        cmd = SearchCommand(
            point_id="",
            kind="edge" if neg_flank else "approach",
            start_m=start,
            direction=(end - start) / length,
            length_m=length,
            sensor_axis=axis,
            T_base_wobj_estimate=np.eye(4),
            nominal_m=start,
        )
        res = probe(cmd)
        if res.point_m is None:
            return "ERR_SIGSUPSEARCH" if "at start" in res.reason else "ERR_WHLSEARCH"
        return res.point_m

    return search


def full_misplacement(plan, rng: np.random.Generator) -> np.ndarray:  # type: ignore[no-untyped-def]
    """``T_nominal_true`` with translation and rotation exactly at the tolerance."""
    from calib.frames import matrix_from_rotvec

    m = plan.validation.misplacement
    c = np.mean([p.position_m for p in plan.points], axis=0)
    t = rng.normal(size=3)
    t *= m.max_translation_m / np.linalg.norm(t)
    axis = rng.normal(size=3)
    R = matrix_from_rotvec(axis / np.linalg.norm(axis) * m.max_angle_rad)
    return make_transform(R, c - R @ c + t)


VARIANTS = {
    "plan": {},
    "from_measured": {"edge_start_from_measured": True, "edge_start_offset_m": 0.004},
    "event_offset": {"edge_event_offset_m": 0.002},
    "no_retake": {"retake_c_d": False},
}


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_program_frame_equals_the_procedure(seed: int, variant: str) -> None:
    import msgspec

    plan = load_plan(PLAN)
    # the box's ideal sensor reports an edge at the edge: the plan says so (offset 0, measured),
    # else every face takes the sensor model's 6.3 mm (planner.program.settings)
    proc = msgspec.structs.replace(
        plan.procedure, **{"edge_event_offset_m": 0.0, **VARIANTS[variant]}
    )
    plan = msgspec.structs.replace(plan, procedure=proc)
    rng = np.random.default_rng(seed)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, rng)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    m = Machine(export_rapid(job), rapid_search(BoxProbe(T_true)))
    m.main()
    assert m.tp[-2].startswith("wobjcal: A-H done"), m.tp
    T_prog = m.wobj_matrix_m("wobjCal")
    points = points_by_role(plan.role_points())
    ref = run_stator_procedure(points, T_nom, BoxProbe(T_true), plan.procedure)
    assert np.abs(T_prog[:3, 3] - ref.T_base_wobj[:3, 3]).max() < 1e-6
    dR = T_prog[:3, :3].T @ ref.T_base_wobj[:3, :3]
    assert np.arccos(np.clip((np.trace(dR) - 1) / 2, -1, 1)) < 1e-6
    if variant != "event_offset":  # both found the true part (noise-free: exact)
        assert np.abs(T_prog[:3, 3] - T_true[:3, 3]).max() < 1e-6
    # the MEASURED file replays to the same frame through the plan's measurements model
    text = m.files["wobjcal_measured.json"]
    meas = measurements_from_json(text, "program")
    retaken = {"C", "D"} if plan.procedure.retake_c_d else set()
    assert set(meas.points) == set("ABCDEFGH") and set(meas.retakes) == retaken
    table = {k: np.asarray(v) / 1000.0 for k, v in meas.points.items()}
    table |= {f"{k}2": np.asarray(v[0]) / 1000.0 for k, v in meas.retakes.items()}
    for key, p in ref.measured_m.items():
        assert np.abs(table[key] - p).max() < 1e-6, key
    json.loads(text)


def test_a_failed_search_stops_the_procedure_and_writes_the_file() -> None:
    plan = load_plan(PLAN)
    T_nom = nominal_T_base_wobj(plan)
    search = rapid_search(BoxProbe(T_nom))
    calls: list[int] = []

    def failing(start, end, axis, neg_flank):  # type: ignore[no-untyped-def]
        calls.append(1)
        return "ERR_WHLSEARCH" if len(calls) == 3 else search(start, end, axis, neg_flank)

    m = Machine(export_rapid(build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))), failing)
    m.globals["measuredOk"] = [True] * len(m.globals["measuredOk"])  # a previous run's values
    m.main()
    assert len(calls) == 3  # nothing searched after C failed
    assert any("A-H stopped: point C: no detection" in t for t in m.tp), m.tp
    meas = measurements_from_json(m.files["wobjcal_measured.json"], "program")
    assert set(meas.points) == {"A", "B"} and set(meas.failed) == {"C"}  # D-H not tried


@pytest.mark.parametrize("seed", range(12))
def test_no_search_starts_near_the_misplaced_part(seed: int) -> None:
    plan = load_plan(PLAN)
    rng = np.random.default_rng(100 + seed)
    T_nom = nominal_T_base_wobj(plan)
    T_true = T_nom @ full_misplacement(plan, rng)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))
    m = Machine(export_rapid(job), rapid_search(BoxProbe(T_true)))
    m.main()
    assert m.tp[-2].startswith("wobjcal: A-H done"), m.tp
    sd = plan.validation.sensor.sensing_distance_m
    T_true_base = invert_transform(T_true)
    searches = [mo for mo in m.motions if mo.kind == "SearchL"]
    n_px = 2 * 21  # the x-offset run: every second tooth of 42 slots at two levels
    assert len(searches) == 12 + n_px  # 10 measurements + the approaches before F and H
    # approach searches start at least the sensing distance outside the true part; edge
    # searches start at the measured face point: on the surface (tracking), never inside
    for mo in searches:
        dist = distance_to_box(transform_points(T_true_base, mo.start_m))
        if mo.neg_flank:
            assert abs(dist) < 1e-9, dist
        else:
            assert dist > sd, dist
    for mo in m.motions:
        if mo.kind == "MoveJ":
            assert distance_to_box(transform_points(T_true_base, mo.target_m)) > sd


def test_old_nominal_edge_start_would_hit_a_part_misplaced_towards_the_robot() -> None:
    """The check above can fail: the plan's own edge start (TCP on the nominal face) lies
    within the sensing distance of a part moved 10 mm along +x."""
    plan = load_plan(PLAN)
    f = next(p for p in plan.points if p.role == "F")
    start_w = np.array(f.position_m) - f.search.start_offset_m * np.array(f.search.edge_direction)
    T_true = make_transform(np.eye(3), [0.010, 0.0, 0.0])  # nominal -> true
    s_true = transform_points(invert_transform(T_true), start_w)
    assert distance_to_box(s_true) < plan.validation.sensor.sensing_distance_m
