"""Tests of ``calib.units``: one unit table for the plan and the mesh loaders."""

from __future__ import annotations

import json
from pathlib import Path
from typing import get_args

import numpy as np
import pytest
import trimesh

from calib.errors import InputError
from calib.plan.base import MeshUnits
from calib.plan.file import PlanError, load_plan, plan_from_json, resolve_ref
from calib.units import ALIASES, MESH_UNITS, METRES_PER_UNIT, canonical_unit, metres_per_unit
from planner.cell.scene.workobject import load_work_object
from webui.backend import load_mesh

REPO = Path(__file__).resolve().parents[2]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"


def test_plan_units_are_the_table() -> None:
    assert get_args(MeshUnits) == MESH_UNITS
    schema = json.loads((REPO / "assets" / "schema" / "wobjcal.plan-1.schema.json").read_text())
    assert '"enum": ' + json.dumps(sorted(MESH_UNITS)) in json.dumps(schema)


def _cube_plan(tmp_path: Path, units: str) -> Path:
    """A plan whose work object is a 1 m cube written in ``units`` (STL: float32 vertices)."""
    side = 1.0 / METRES_PER_UNIT[canonical_unit(units)] if units != "auto" else 1.0
    trimesh.creation.box(extents=[side] * 3).export(tmp_path / "cube.stl")
    raw = json.loads(STATOR.read_text())
    raw["work_object"].update(mesh="cube.stl", units=units, sha256=None)
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(raw))
    return path


@pytest.mark.parametrize("units", MESH_UNITS)
def test_every_plan_unit_loads_a_1m_cube(tmp_path: Path, units: str) -> None:
    plan = load_plan(_cube_plan(tmp_path, units))
    assert plan.work_object.units == units
    ref = resolve_ref(plan.work_object.mesh, tmp_path)
    loaded = load_work_object(ref, units=plan.work_object.units)
    np.testing.assert_allclose(loaded.mesh.extents, [1.0, 1.0, 1.0], rtol=1e-6)
    assert loaded.report.units == (units if units != "auto" else "m")
    ui_mesh = load_mesh(plan.work_object.mesh, plan.work_object.units, tmp_path)
    np.testing.assert_allclose(ui_mesh.extents, [1.0, 1.0, 1.0], rtol=1e-6)


@pytest.mark.parametrize("alias", sorted(ALIASES))
def test_loader_accepts_aliases(tmp_path: Path, alias: str) -> None:
    side = 1.0 / metres_per_unit(alias)
    trimesh.creation.box(extents=[side] * 3).export(tmp_path / "cube.stl")
    loaded = load_work_object(tmp_path / "cube.stl", units=alias)
    np.testing.assert_allclose(loaded.mesh.extents, [1.0, 1.0, 1.0], rtol=1e-6)
    assert loaded.report.units == ALIASES[alias]


def test_unknown_unit_is_rejected_at_plan_load() -> None:
    raw = json.loads(STATOR.read_text())
    raw["work_object"]["units"] = "furlong"
    with pytest.raises(PlanError) as err:
        plan_from_json(json.dumps(raw), "x.json")
    msg = str(err.value)
    assert "work_object.units" in msg and "'furlong'" in msg
    assert all(repr(u) in msg for u in MESH_UNITS)


def test_canonical_unit_names_the_field_and_the_valid_values() -> None:
    assert canonical_unit("inch") == "in" and canonical_unit("auto") == "auto"
    with pytest.raises(InputError, match=r"^fixture\.units: unknown length unit 'ft' \(valid: 'm'"):
        canonical_unit("ft", "fixture.units")
    with pytest.raises(InputError, match="'auto' has no fixed scale"):
        metres_per_unit("auto")
