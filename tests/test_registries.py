"""Every registry answers an unknown name the same way (:func:`calib.registry.lookup`):
``unknown <what> '<name>'; known: a, b``, naming the field or option, and every entry of every
registry is reachable by its own name."""

from __future__ import annotations

import re

import pytest

from calib.errors import InputError
from calib.procedures import PROCEDURES, procedure_kind
from calib.registry import lookup
from planner.builtins import (
    BUILTIN_PARTS,
    BUILTIN_ROBOTS,
    BUILTIN_TOOLS,
    robot_urdf,
    tool_description,
)
from planner.errors import UnknownBuiltinError
from planner.export import FORMATS
from planner.program.controllers import CONTROLLERS, controller
from planner.sim.sensors import SENSORS

ONE_ERROR = re.compile(r"^unknown [\w\- ]+( \([\w.\-]+\))? '(builtin:)?nope'; known: [\w:, ]+$")


@pytest.mark.parametrize(
    ("ask", "error"),
    [
        (lambda: procedure_kind("nope"), InputError),
        (lambda: controller("nope"), InputError),
        (lambda: lookup(FORMATS, "nope", "export format (--format)"), InputError),
        (lambda: lookup(SENSORS, "nope", "sensor simulator (validation.sensor.kind)"), InputError),
        (lambda: robot_urdf("builtin:nope"), UnknownBuiltinError),
        (lambda: tool_description("builtin:nope"), UnknownBuiltinError),
    ],
    ids=["procedure", "controller", "format", "sensor", "robot", "tool"],
)
def test_an_unknown_name_gets_the_one_error(ask: object, error: type[Exception]) -> None:
    with pytest.raises(error) as info:
        ask()  # type: ignore[operator]
    assert ONE_ERROR.match(str(info.value)), str(info.value)


def test_every_entry_is_found_by_its_name() -> None:
    for registry in (PROCEDURES, CONTROLLERS, FORMATS, SENSORS):
        for name, entry in registry.items():
            assert lookup(registry, name, "entry") is entry
    assert {n for n in PROCEDURES} == {procedure_kind(n).method for n in PROCEDURES}
    assert {controller(n).name for n in CONTROLLERS} == set(CONTROLLERS)
    for name in BUILTIN_ROBOTS:
        assert robot_urdf(f"builtin:{name}").is_file()
    for name in BUILTIN_TOOLS:
        assert tool_description(f"builtin:{name}").is_file()
    assert BUILTIN_PARTS
