"""Length units of mesh files: the one table the plan (``calib``) and the loaders (``planner``) use.

A plan's ``work_object.units`` and ``cell.fixtures[i].units`` take a canonical name from
:data:`MESH_UNITS`; :func:`planner.cell.scene.load_work_object` also accepts the spellings in
:data:`ALIASES` (e.g. ``"inch"``) for scripts, and ``"auto"``, which guesses metres or
millimetres from the mesh size.
"""

from __future__ import annotations

from calib.errors import InputError

#: Canonical unit name -> metres per unit.
METRES_PER_UNIT: dict[str, float] = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "in": 0.0254}
#: Let the loader guess metres or millimetres from the mesh's extent.
AUTO = "auto"
#: What a plan's ``units`` fields accept, in this order (the JSON Schema's ``enum``).
MESH_UNITS: tuple[str, ...] = (*METRES_PER_UNIT, AUTO)
#: Other accepted spellings -> canonical name (loaders only; plans hold canonical names).
ALIASES: dict[str, str] = {
    "inch": "in",
    "inches": "in",
    "meter": "m",
    "metre": "m",
    "millimeter": "mm",
    "millimetre": "mm",
    "centimeter": "cm",
    "centimetre": "cm",
}


def canonical_unit(name: str, field: str = "units") -> str:
    """The canonical name of the mesh unit ``name`` (``"auto"`` stays ``"auto"``).

    Args:
        name: a name of :data:`MESH_UNITS` or :data:`ALIASES`.
        field: what to call the value in the error message (e.g. ``work_object.units``).

    Raises:
        InputError: ``name`` is not a known unit; the message lists the valid names.
    """
    if name in MESH_UNITS:
        return name
    if name in ALIASES:
        return ALIASES[name]
    valid = ", ".join(repr(u) for u in (*MESH_UNITS, *ALIASES))
    raise InputError(f"{field}: unknown length unit {name!r} (valid: {valid})")


def metres_per_unit(name: str, field: str = "units") -> float:
    """Metres per unit of ``name`` (a canonical name or alias, not ``"auto"``).

    Raises:
        InputError: ``name`` is unknown or ``"auto"``.
    """
    unit = canonical_unit(name, field)
    if unit == AUTO:
        raise InputError(f"{field}: 'auto' has no fixed scale; resolve it from the mesh first")
    return METRES_PER_UNIT[unit]


__all__ = ["ALIASES", "AUTO", "MESH_UNITS", "METRES_PER_UNIT", "canonical_unit", "metres_per_unit"]
