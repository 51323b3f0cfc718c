"""Built-in assets by name: robots, tools and work-object parts, in static tables.

A string that starts with ``builtin:`` names a built-in; any other string is a file path.

- robots (:data:`BUILTIN_ROBOTS`): name -> URDF shipped in ``assets/robots``;
- tools (:data:`BUILTIN_TOOLS`): name -> tool description JSON in ``assets/tools``
  (see :mod:`planner.cell.scene.tool`);
- parts (:data:`BUILTIN_PARTS`): name -> :class:`BuiltinPart`, the ``"module:function"`` of a
  factory that returns the part's mesh in metres, in its own (wobj) frame, and, for a part the
  validation simulates from its geometry (the stators' slot holes and bulge), the
  ``"module:function"`` of that geometry. Both are loaded when first asked for
  (:func:`calib.registry.load`), so listing the parts costs nothing and this module imports no
  part. This is the one table of built-in parts: the work object, the validation's true part
  and the x-offset run all read it.

Adding a built-in part is one module with a factory plus one entry here::

    BUILTIN_PARTS["bracket"] = BuiltinPart("planner.parts.bracket:bracket_mesh")
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from calib.registry import load, lookup
from planner.errors import UnknownBuiltinError

if TYPE_CHECKING:
    import trimesh

T = TypeVar("T")

PREFIX = "builtin:"
#: The repository's data folder (robots, tools, plans, schemas).
ASSETS = Path(__file__).resolve().parent.parent / "assets"

#: Built-in robots: name -> URDF path.
BUILTIN_ROBOTS: dict[str, Path] = {
    "irb4400": ASSETS / "robots" / "irb4400" / "irb4400.urdf",
}

#: Built-in tools: name -> tool description JSON (see :mod:`planner.cell.scene.tool`).
BUILTIN_TOOLS: dict[str, Path] = {
    "cable_feeder": ASSETS / "tools" / "cable_feeder" / "tool.json",
}


@dataclass(frozen=True)
class BuiltinPart:
    """A built-in work-object part.

    Attributes:
        mesh: ``"module:function"`` of a factory returning a fresh ``trimesh.Trimesh`` of the
            part, metres, wobj frame.
        geometry: ``"module:function"`` of a factory returning the part's exact geometry
            (a :class:`planner.parts.stator.StatorGeometry`: slot holes, bulge) that the
            validation builds the true part and the x-offset run from, for a part in its own
            frame; ``""``: none (the validation uses the mesh).
    """

    mesh: str
    geometry: str = ""


#: Built-in work-object parts by name (without the prefix).
BUILTIN_PARTS: dict[str, BuiltinPart] = {
    "stator_section": BuiltinPart(
        "planner.parts.stator_mesh:full_section_mesh",
        "planner.parts.stator:StatorGeometry.full_section",
    ),
    "stator_prototype": BuiltinPart(
        "planner.parts.stator_mesh:prototype_mesh",
        "planner.parts.stator:StatorGeometry.prototype",
    ),
}


def is_builtin(name: object) -> bool:
    """True when ``name`` is a string of the form ``builtin:<name>``."""
    return isinstance(name, str) and name.startswith(PREFIX)


def _strip(name: str) -> str:
    return name[len(PREFIX) :] if name.startswith(PREFIX) else name


def _find(table: dict[str, T], kind: str, name: str) -> T:
    """``table``'s entry for ``name`` (with or without the prefix), or the one error naming the
    built-in ``kind`` and every valid name (with the prefix)."""
    named = {PREFIX + k: v for k, v in table.items()}
    return lookup(named, PREFIX + _strip(name), f"built-in {kind}", UnknownBuiltinError)


def robot_urdf(name: str) -> Path:
    """Path of the URDF of the built-in robot ``name`` (e.g. ``"builtin:irb4400"``).

    Raises:
        UnknownBuiltinError: no such built-in robot (the message lists the valid names).
    """
    return _find(BUILTIN_ROBOTS, "robot", name)


def tool_description(name: str) -> Path:
    """Path of the tool description JSON of the built-in tool ``name``.

    Raises:
        UnknownBuiltinError: no such built-in tool (the message lists the valid names).
    """
    return _find(BUILTIN_TOOLS, "tool", name)


def builtin_part_names() -> list[str]:
    """Sorted names (with prefix) of the built-in parts."""
    return [PREFIX + k for k in sorted(BUILTIN_PARTS)]


def builtin_part(name: str) -> BuiltinPart:
    """The entry of the built-in part ``name`` (e.g. ``"builtin:stator_section"``).

    Raises:
        UnknownBuiltinError: no such built-in part (the message lists the valid names).
    """
    return _find(BUILTIN_PARTS, "part", name)


def builtin_mesh(name: str) -> trimesh.Trimesh:
    """A fresh mesh (metres, wobj frame) of the built-in part ``name``.

    Raises:
        UnknownBuiltinError: no such built-in part (the message lists the valid names).
    """
    mesh: trimesh.Trimesh = load(builtin_part(name).mesh)()
    return mesh


def builtin_geometry(name: str) -> object | None:
    """The exact geometry of the built-in part ``name`` (:attr:`BuiltinPart.geometry`, e.g. a
    :class:`planner.parts.stator.StatorGeometry`), or ``None`` when it has none or ``name`` is
    no built-in part (a file, an unknown name: the work object's own loading names those)."""
    key = _strip(name) if is_builtin(name) else None
    part = BUILTIN_PARTS.get(key) if key is not None else None
    if part is None or not part.geometry:
        return None
    geometry: object = load(part.geometry)()
    return geometry
