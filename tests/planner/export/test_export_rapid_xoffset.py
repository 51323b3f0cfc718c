"""The x-offset run (eq. 13-14) in the adaptive RAPID program, run in the RAPID interpreter:
its searches, its matrix and its slot targets agree with :mod:`calib.paper.xoffset`."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from calib.frames import invert_transform, transform_directions, transform_points
from calib.paper.xoffset import slot_target, xoffset_matrix
from calib.plan.file import load_plan
from planner.export.job import ToolData, build_job
from planner.export.rapid import export_rapid
from planner.plan_cell import nominal_T_base_wobj
from tests.rapid_interp import Machine, ProgramExit

PLAN = Path(__file__).resolve().parents[3] / "assets" / "plans" / "stator_section_ah.json"


def affine_face(T_base_wobj: np.ndarray, c: float, a: float, b: float):  # type: ignore[no-untyped-def]
    """A SearchL callback: the side face is ``x = c + a y + b z`` in the wobj frame."""
    T_wb = invert_transform(T_base_wobj)

    def search(start, end, axis, neg_flank):  # type: ignore[no-untyped-def]
        s, e = transform_points(T_wb, start), transform_points(T_wb, end)
        d = e - s
        f = lambda p: p[0] - (c + a * p[1] + b * p[2])  # noqa: E731
        t = f(s) / (f(s) - f(e))
        if not 0.0 <= t <= 1.0:
            return "ERR_WHLSEARCH"
        return transform_points(T_base_wobj, s + t * d)

    return search


def test_x_offset_matrix_and_slot_targets_match_the_python_of_eq_14() -> None:
    plan = load_plan(PLAN)
    T = nominal_T_base_wobj(plan)
    job = build_job(plan, T, ToolData(T_flange_tcp=np.eye(4)))
    c, a, b = 0.0004, -0.0003, 0.002  # an affine bulge: eq. 14 reproduces it exactly
    m = Machine(export_rapid(job), affine_face(T, c, a, b))
    m.globals["wobjCal"] = m.globals["wobjNominal"]  # the frame after A-H: here the nominal
    m.call("XOffsetRun", [])
    run = plan.procedure.xoffset  # type: ignore[union-attr]
    grid = run.grid
    px = np.array([[p.f["x"], p.f["y"], p.f["z"]] for p in m.globals["pxMeas"]]) / 1e3
    px = px.reshape(2, 21, 3)
    assert np.allclose(px[..., 0], c + a * px[..., 1] + b * px[..., 2], atol=1e-9)
    mx_rapid = np.asarray(m.globals["mxW"], float).reshape(grid.n_layers, grid.n_slots) / 1e3
    mx_python = xoffset_matrix(px, grid)
    np.testing.assert_allclose(mx_rapid, mx_python, atol=1e-9)
    yy, zz = np.meshgrid(grid.slot_y_m, grid.layer_z_m)
    np.testing.assert_allclose(mx_rapid, c + a * yy + b * zz, atol=1e-9)
    # the paper's target function: slot 40, layer 6, 5 mm out, in wobjCal
    target = m.call("SlotTarget", [40, 6, 5.0])
    T_t = slot_target(T, grid, 40, 6, standoff_m=0.005, xoffset=mx_python)
    trans = target.f["trans"].f
    got = np.array([trans["x"], trans["y"], trans["z"]]) / 1e3
    np.testing.assert_allclose(transform_points(T, got), T_t[:3, 3], atol=1e-9)
    # searched along -x of the work object, from 20 mm out
    search = next(mo for mo in m.motions if mo.kind == "SearchL")
    d = transform_directions(invert_transform(T), search.target_m - search.start_m)
    np.testing.assert_allclose(d / np.linalg.norm(d), [-1, 0, 0], atol=1e-9)
    start = transform_points(invert_transform(T), search.start_m)
    assert start[0] - (c + a * start[1] + b * start[2]) > 0.019


def test_a_failed_x_offset_search_stops_the_program_with_its_name() -> None:
    plan = load_plan(PLAN)
    T = nominal_T_base_wobj(plan)
    job = build_job(plan, T, ToolData(T_flange_tcp=np.eye(4)))
    m = Machine(export_rapid(job), lambda *args: "ERR_WHLSEARCH")
    m.globals["wobjCal"] = m.globals["wobjNominal"]
    with pytest.raises(ProgramExit):
        m.call("XOffsetRun", [])
    assert any("x-offset point PX1_1 not found" in t for t in m.tp), m.tp
