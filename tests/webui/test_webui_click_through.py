"""A click whose ray meets the robot, its tool or a fixture before the part places nothing and
says what it met (issue 14); the robot is taken at the pose the clicking tab shows."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from calib.errors import InputError
from webui import click_place


def _axis_ray(app: Any, point_id: str) -> tuple[np.ndarray, np.ndarray]:
    """A ray down the sensor axis of ``point_id`` (its normal), from 1.5 m out: at the point's
    probe pose through the tool and sensor, then onto the point's marker on the part."""
    p = app.state.doc.get(point_id).probe
    T = app.view.T_world_wobj
    n = T[:3, :3] @ np.asarray(p.normal)
    target = T[:3, :3] @ np.asarray(p.position_m) + T[:3, 3]
    return target + 1.5 * n, -n


@pytest.mark.slow
def test_a_click_through_the_robot_places_nothing_and_names_the_link(demo_app: Any) -> None:
    app = demo_app
    app.select("A")
    app.robot_to_selected()  # every tab's robot at A's probe pose
    check = app.check_of("A")
    assert check is not None and check.q is not None
    origin, direction = _axis_ray(app, "A")
    hit = app.picker.pick(origin, direction)
    assert hit is not None, "the part lies behind the robot along this ray"
    assert click_place.marker_at_ray(app, origin, direction) == "A", "and A's marker"
    before = app.state.doc
    event = SimpleNamespace(ray_origin=origin, ray_direction=direction, client=None)
    with pytest.raises(InputError, match=r"nothing placed: clicked the (robot|tool) \(link "):
        click_place.click_place(app, event)
    assert app.state.doc is before, "no point placed behind the robot"
    said: list[str] = []
    app.notify = lambda title, body, client=None, error=True: said.append(f"{title}: {body}")
    try:
        app._on_scene_click(event)  # what viser calls: a notification, no exception
    finally:
        del app.notify
    assert said and said[0].startswith("Click not used: nothing placed: clicked the"), said
    assert ", not the part" in said[0]


def test_the_same_ray_reaches_the_part_when_the_robot_stands_elsewhere(demo_app: Any) -> None:
    app = demo_app
    check = app.check_of("A")
    assert check is not None and check.q is not None
    origin, direction = _axis_ray(app, "A")
    app.select("E")
    app.robot_to_selected()  # the robot at E's pose: nothing in front of the part along A's axis
    assert np.linalg.norm(app.robot.q - check.q) > 0.1
    obstacle = click_place.obstacle_on_ray(app, origin, direction, None)
    assert obstacle is None, obstacle
    before = app.state.doc
    event = SimpleNamespace(ray_origin=origin, ray_direction=direction, client=None)
    click_place.click_place(app, event)
    assert app.selected == "A", "A's marker, no longer behind the sensor, is selected"
    assert app.state.doc is before


@pytest.mark.parametrize("display", ["ghost", "hidden"])
def test_a_ghost_or_hidden_robot_lets_the_click_through(demo_app: Any, display: str) -> None:
    """The same click as above, with the robot drawn as a ghost or not at all: the robot no
    longer stops it, so it reaches A's marker behind it and selects A."""
    app = demo_app
    app.select("A")
    app.robot_to_selected()
    origin, direction = _axis_ray(app, "A")
    app.set_robot_display(display)
    try:
        assert app.robot.display == display
        app.select(None)
        event = SimpleNamespace(ray_origin=origin, ray_direction=direction, client=None)
        click_place.click_place(app, event)
        assert app.selected == "A"
    finally:
        app.set_robot_display("shown")
