"""Built-in assets by name: robots, tools and work-object parts, in static tables.

A string that starts with ``builtin:`` names a built-in; any other string is a file path.

- robots (:data:`BUILTIN_ROBOTS`): name -> URDF shipped in ``assets/robots``;
- tools (:data:`BUILTIN_TOOLS`): name -> tool description JSON in ``assets/tools``
  (see :mod:`planner.cell.tool`);
- parts (:data:`BUILTIN_PARTS`): name -> ``"module:function"`` of a factory that returns the
  part's mesh in metres, in its own (wobj) frame. The module is imported when the part is first
  asked for, so listing the parts costs nothing and this module imports no part.

Adding a built-in part is one module with a factory plus one entry here::

    BUILTIN_PARTS["bracket"] = "planner.parts.bracket:bracket_mesh"
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import TYPE_CHECKING

from calib.registry import unknown_name
from planner.errors import UnknownBuiltinError

if TYPE_CHECKING:
    import trimesh

PREFIX = "builtin:"
#: The repository's data folder (robots, tools, plans, schemas).
ASSETS = Path(__file__).resolve().parent.parent / "assets"

#: Built-in robots: name -> URDF path.
BUILTIN_ROBOTS: dict[str, Path] = {
    "irb4400": ASSETS / "robots" / "irb4400" / "irb4400.urdf",
}

#: Built-in tools: name -> tool description JSON (see :mod:`planner.cell.tool`).
BUILTIN_TOOLS: dict[str, Path] = {
    "cable_feeder": ASSETS / "tools" / "cable_feeder" / "tool.json",
}

#: Built-in work-object parts: name -> ``"module:function"`` returning a ``trimesh.Trimesh``
#: in metres, wobj frame.
BUILTIN_PARTS: dict[str, str] = {
    "stator_section": "planner.parts.stator_mesh:full_section_mesh",
    "stator_prototype": "planner.parts.stator_mesh:prototype_mesh",
}


def is_builtin(name: object) -> bool:
    """True when ``name`` is a string of the form ``builtin:<name>``."""
    return isinstance(name, str) and name.startswith(PREFIX)


def _strip(name: str) -> str:
    return name[len(PREFIX) :] if name.startswith(PREFIX) else name


def _unknown(kind: str, name: str, names: list[str]) -> UnknownBuiltinError:
    return unknown_name(f"built-in {kind}", name, [PREFIX + k for k in names], UnknownBuiltinError)


def robot_urdf(name: str) -> Path:
    """Path of the URDF of the built-in robot ``name`` (e.g. ``"builtin:irb4400"``).

    Raises:
        UnknownBuiltinError: no such built-in robot (the message lists the valid names).
    """
    key = _strip(name)
    if key not in BUILTIN_ROBOTS:
        raise _unknown("robot", name, list(BUILTIN_ROBOTS))
    return BUILTIN_ROBOTS[key]


def tool_description(name: str) -> Path:
    """Path of the tool description JSON of the built-in tool ``name``.

    Raises:
        UnknownBuiltinError: no such built-in tool (the message lists the valid names).
    """
    key = _strip(name)
    if key not in BUILTIN_TOOLS:
        raise _unknown("tool", name, list(BUILTIN_TOOLS))
    return BUILTIN_TOOLS[key]


def builtin_part_names() -> list[str]:
    """Sorted names (with prefix) of the built-in parts."""
    return [PREFIX + k for k in sorted(BUILTIN_PARTS)]


def builtin_mesh(name: str) -> trimesh.Trimesh:
    """A fresh mesh (metres, wobj frame) of the built-in part ``name``.

    Raises:
        UnknownBuiltinError: no such built-in part (the message lists the valid names).
    """
    key = _strip(name)
    if key not in BUILTIN_PARTS:
        raise _unknown("part", name, list(BUILTIN_PARTS))
    module, _, function = BUILTIN_PARTS[key].partition(":")
    factory = getattr(importlib.import_module(module), function)
    mesh: trimesh.Trimesh = factory()
    return mesh
