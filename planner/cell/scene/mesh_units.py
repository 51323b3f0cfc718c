"""Which unit a mesh file is in, when the plan says ``auto``, and whether given units make sense.

The ``auto`` rule (:func:`auto_units`) weighs the file's own unit hints (:func:`unit_hint`) and
the cell's scale; :func:`implausible_units_warning` checks explicit units the same way. The
rule, and why, is in :mod:`planner.cell.scene.workobject`'s docstring and ``docs/cell.md``.
"""

from __future__ import annotations

import re
from pathlib import Path

import trimesh

from calib.units import METRES_PER_UNIT

#: A work object is at least this large (largest extent), m: about the sensor face.
MIN_PART_M = 0.010
#: The reach used by ``auto`` without a cell (a large industrial arm), m.
DEFAULT_REACH_M = 3.0
#: The order ``auto`` tries units in when the file names none.
AUTO_ORDER = ("m", "mm", "in", "cm")
#: Words of a file name or header that name a unit.
_HINT_WORDS = {
    "m": "m",
    "meter": "m",
    "meters": "m",
    "metre": "m",
    "metres": "m",
    "mm": "mm",
    "millimeter": "mm",
    "millimeters": "mm",
    "millimetre": "mm",
    "millimetres": "mm",
    "cm": "cm",
    "centimeter": "cm",
    "centimeters": "cm",
    "inch": "in",
    "inches": "in",
}
_TRIMESH_UNITS = {"meters": "m", "millimeters": "mm", "centimeters": "cm", "inches": "in"}


def unit_hint(mesh: trimesh.Trimesh, source: str) -> str | None:
    """The unit the file itself names, or ``None``: the loader's ``units`` (formats that carry
    them), else a word of the STL header or of the file name (``plate_mm.stl``, ``inch``)."""
    loaded = getattr(mesh, "units", None)
    if isinstance(loaded, str) and loaded in _TRIMESH_UNITS:
        return _TRIMESH_UNITS[loaded]
    meta = mesh.metadata or {}
    texts = [str(meta.get("header", "")), Path(str(source)).stem]
    for text in texts:
        words = re.split(r"[^a-z]+", text.lower().replace("units", " "))
        for word in words:
            if word in _HINT_WORDS and word != "m":  # a lone "m" in a name is rarely a unit
                return _HINT_WORDS[word]
    return None


def _plausible(size_m: float, reach_m: float) -> bool:
    return MIN_PART_M <= size_m <= 2.0 * reach_m


def auto_units(extent: float, hint: str | None, reach_m: float) -> tuple[str, str]:
    """The unit ``auto`` takes for a mesh whose largest extent is ``extent`` (file units), and
    why (see the module docstring).

    Args:
        extent: largest bounding-box extent in file units.
        hint: the unit the file names (:func:`unit_hint`), or ``None``.
        reach_m: the robot's reach, m (what a work object may span at most).
    """
    limits = f"a part of {MIN_PART_M * 1e3:g} mm to twice the robot's reach {reach_m:.2f} m"
    if hint is not None:
        if _plausible(extent * METRES_PER_UNIT[hint], reach_m):
            return hint, f"the file names {hint!r}"
        why = f"the file names {hint!r}, but that gives {extent * METRES_PER_UNIT[hint]:.4g} m; "
    else:
        why = "the file names no unit; "
    for unit in AUTO_ORDER:
        if _plausible(extent * METRES_PER_UNIT[unit], reach_m):
            return unit, why + f"{unit!r} is the first of {list(AUTO_ORDER)} that gives {limits}"
    return "m", why + f"no unit gives {limits}: metres"


def implausible_units_warning(src: str, extent: float, units: str, reach_m: float) -> str:
    """A warning when explicit ``units`` make a part of largest extent ``extent`` (file units)
    implausible for the cell, naming the unit that would fit; ``""`` when plausible."""
    size = extent * METRES_PER_UNIT[units]
    if _plausible(size, reach_m):
        return ""
    fits = [u for u in AUTO_ORDER if _plausible(extent * METRES_PER_UNIT[u], reach_m)]
    other = ""
    if fits:
        other = f"; {fits[0]!r} would make it {extent * METRES_PER_UNIT[fits[0]]:.3g} m"
    what = (
        f"larger than twice the robot's reach {reach_m:.2f} m"
        if size > reach_m
        else f"smaller than {MIN_PART_M * 1e3:g} mm"
    )
    return f"{src}: read in {units!r} the part is {size:.4g} m across, {what}: wrong units?{other}"
