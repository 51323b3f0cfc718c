"""Built-in assets by name: ``builtin:irb4400`` (robot), ``builtin:cable_feeder`` (tool), and
built-in work-object meshes that other modules register.

A string that starts with ``builtin:`` names an asset shipped in ``assets/`` or a mesh made by
a registered factory; any other string is a file path. Other parts extend the mesh registry
with :func:`register_builtin_mesh`, e.g. the stator module registers ``builtin:stator_section``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import trimesh

from planner.errors import UnknownFrameError

PREFIX = "builtin:"
ASSETS = Path(__file__).resolve().parent.parent / "assets"

#: Built-in robots: name -> URDF path.
BUILTIN_ROBOTS: dict[str, Path] = {
    "irb4400": ASSETS / "robots" / "irb4400" / "irb4400.urdf",
}

#: Built-in tools: name -> tool description JSON (see :mod:`planner.cell.tool`).
BUILTIN_TOOLS: dict[str, Path] = {
    "cable_feeder": ASSETS / "tools" / "cable_feeder" / "tool.json",
}

#: Built-in work-object meshes: name -> factory returning a mesh in metres (wobj frame).
_MESH_FACTORIES: dict[str, Callable[[], trimesh.Trimesh]] = {}


def is_builtin(name: object) -> bool:
    """True when ``name`` is a string of the form ``builtin:<name>``."""
    return isinstance(name, str) and name.startswith(PREFIX)


def _strip(name: str) -> str:
    return name[len(PREFIX) :] if name.startswith(PREFIX) else name


def _lookup(kind: str, name: str, table: dict[str, Path]) -> Path:
    key = _strip(name)
    if key not in table:
        valid = ", ".join(PREFIX + k for k in sorted(table)) or "(none)"
        raise UnknownFrameError(f"unknown built-in {kind} {name!r}; valid names: {valid}")
    return table[key]


def robot_urdf(name: str) -> Path:
    """Path of the URDF of the built-in robot ``name`` (e.g. ``"builtin:irb4400"``).

    Raises:
        UnknownFrameError: no such built-in robot (the message lists the valid names).
    """
    return _lookup("robot", name, BUILTIN_ROBOTS)


def tool_description(name: str) -> Path:
    """Path of the tool description JSON of the built-in tool ``name``.

    Raises:
        UnknownFrameError: no such built-in tool (the message lists the valid names).
    """
    return _lookup("tool", name, BUILTIN_TOOLS)


def register_builtin_mesh(name: str, factory: Callable[[], trimesh.Trimesh]) -> None:
    """Register a work-object mesh factory under ``builtin:<name>``.

    Args:
        name: the name without or with the ``builtin:`` prefix, e.g. ``"stator_section"``.
        factory: called with no arguments; returns a ``trimesh.Trimesh`` in metres, in the
            work object's own frame (wobj). Registering a name again replaces the factory.
    """
    key = _strip(name)
    if not key:
        raise UnknownFrameError("a built-in mesh needs a non-empty name")
    _MESH_FACTORIES[key] = factory


def builtin_mesh_names() -> list[str]:
    """Sorted names (with prefix) of the registered built-in meshes."""
    return [PREFIX + k for k in sorted(_MESH_FACTORIES)]


def builtin_mesh(name: str) -> trimesh.Trimesh:
    """A fresh mesh (metres, wobj frame) from the factory registered as ``name``.

    Raises:
        UnknownFrameError: no such built-in mesh (the message lists the valid names).
    """
    key = _strip(name)
    if key not in _MESH_FACTORIES:
        valid = ", ".join(builtin_mesh_names()) or "(none registered)"
        raise UnknownFrameError(f"unknown built-in mesh {name!r}; valid names: {valid}")
    return _MESH_FACTORIES[key]()
