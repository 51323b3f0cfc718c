"""Tests of planner.plan_cell: frames of the plan, the tool data, the cell built from a plan."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib.frames import invert_transform
from calib.plan.file import load_plan
from planner.plan_cell import T_base_world, nominal_T_base_wobj, open_cell, tool_data
from planner.robot.urdf import load_urdf

REPO = Path(__file__).resolve().parents[3]
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
CABLE_FEEDER = REPO / "assets" / "tools" / "cable_feeder" / "cable_feeder.urdf"
DATA = REPO / "tests" / "data" / "plans"


def test_nominal_frames() -> None:
    plan = load_plan(DATA / "valid_three_two_one.json")
    T_wb = plan.cell.robot.T_world_base.matrix()
    np.testing.assert_allclose(T_base_world(plan), invert_transform(T_wb), atol=1e-15)
    np.testing.assert_allclose(
        nominal_T_base_wobj(plan), plan.work_object.T_world_wobj.matrix(), atol=1e-12
    )


def test_tool_data_of_builtin_cable_feeder() -> None:
    plan = load_plan(STATOR)
    tool, note = tool_data(plan, STATOR.parent)
    assert tool.T_flange_tcp.shape == (4, 4)
    assert tool.T_flange_tcp[2, 3] > 0.2  # the sensor TCP sits well in front of the flange
    assert tool.mass_kg == 5.0 and "placeholder" in note
    assert 0.0 < tool.cog_m[2] < tool.T_flange_tcp[2, 3]


def _mass_and_com_from_xml(path: Path) -> tuple[float, np.ndarray]:
    """Independent of the parser: sum the <inertial>s of a URDF with every joint at zero."""

    def origin(e: ET.Element | None) -> np.ndarray:
        T = np.eye(4)
        if e is not None:
            rpy = [float(v) for v in e.get("rpy", "0 0 0").split()]
            T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
            T[:3, 3] = [float(v) for v in e.get("xyz", "0 0 0").split()]
        return T

    root = ET.parse(path).getroot()
    joint_above = {j.find("child").get("link"): j for j in root.findall("joint")}

    def pose(link: str) -> np.ndarray:
        j = joint_above.get(link)
        if j is None:
            return np.eye(4)
        return pose(j.find("parent").get("link")) @ origin(j.find("origin"))

    masses, points = [], []
    for link in root.findall("link"):
        inertial = link.find("inertial")
        if inertial is not None:
            masses.append(float(inertial.find("mass").get("value")))
            points.append((pose(link.get("name")) @ origin(inertial.find("origin")))[:3, 3])
    m = np.array(masses)
    return float(m.sum()), m @ np.array(points) / m.sum()


def test_tool_mass_and_centre_of_gravity_come_from_the_urdf_inertials() -> None:
    expected_mass, expected_cog = _mass_and_com_from_xml(CABLE_FEEDER)
    assert expected_mass == pytest.approx(0.9)  # nine links of 0.1 kg
    mass, com = load_urdf(CABLE_FEEDER).mass_and_com()
    assert mass == pytest.approx(expected_mass, rel=1e-15)
    np.testing.assert_allclose(com, expected_cog, atol=1e-15)
    tool, _ = tool_data(load_plan(STATOR), STATOR.parent)  # 0.9 kg < 1 kg: mass is a placeholder
    np.testing.assert_allclose(tool.cog_m, expected_cog, atol=1e-15)


def test_open_cell_places_the_work_object_and_table() -> None:
    plan = load_plan(STATOR)
    with open_cell(plan, STATOR.parent) as cell:
        assert set(cell.fixtures) == {"table"}
        assert cell.work_object is not None
