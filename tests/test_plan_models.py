"""The plan's validation models mirror the simulation's own models field by field.

``calib.plan.models`` cannot import ``planner`` (layer rule), so its defaults are a copy; this
test keeps the copy honest: a default changed on one side only fails here.
"""

from __future__ import annotations

import dataclasses

import msgspec
import pytest

from calib.plan.models import Misplacement, RobotErrorModel, SensorModel
from planner.sim import error_models
from planner.sim import proximity as sensor


@pytest.mark.parametrize(
    ("plan_model", "sim_model"),
    [
        (SensorModel, sensor.ProximitySensor),
        (RobotErrorModel, error_models.RobotErrorModel),
        (Misplacement, error_models.Misplacement),
    ],
)
def test_plan_defaults_equal_simulation_defaults(plan_model: type, sim_model: type) -> None:
    plan_fields = {f.name: f.default for f in msgspec.structs.fields(plan_model)}
    sim_fields = {f.name: f.default for f in dataclasses.fields(sim_model) if f.init}
    assert set(plan_fields) <= set(sim_fields), set(plan_fields) - set(sim_fields)
    for name, value in plan_fields.items():
        assert value == pytest.approx(sim_fields[name]), name
