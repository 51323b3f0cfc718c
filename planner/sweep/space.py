"""The placements of a sweep (``wobjcal sweep``): where the robot base and the part are put.

A placement moves the robot base and the part (the work object together with the cell's
fixtures, the table it lies on) away from the plan's own poses by offsets drawn uniformly from
ranges given in millimetres and degrees (humans' units; SI inside the plan):

- ``base_dx_mm``, ``base_dy_mm``: the base origin shifted along the world x and y axes;
- ``base_dyaw_deg``: the base turned about the world z axis through its own origin;
- ``part_dx_mm``, ``part_dy_mm``, ``part_dz_mm``: the work-object origin (and the fixtures with
  it) shifted along the world axes;
- ``part_dyaw_deg``: the part and its fixtures turned about the world z axis through the
  work-object origin.

Placement ``i`` of seed ``s`` is drawn from ``numpy.random.default_rng([s, i])`` alone, so it is
the same whatever the number of samples, the order the placements run in or the machine; its
values are rounded to 1 um and 1e-4 deg, so the CSV row names the placement exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import msgspec
import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError
from calib.frames import make_transform, matrix_from_tait_bryan_zyx
from calib.limits import MAX_SWEEP_OFFSET_MM, MAX_SWEEP_YAW_DEG
from calib.plan.cell import Pose
from calib.plan.file import Plan

FloatArray = NDArray[np.float64]

#: The swept quantities in the order they are drawn, with their unit.
AXES: tuple[tuple[str, str], ...] = (
    ("base_dx_mm", "mm"),
    ("base_dy_mm", "mm"),
    ("base_dyaw_deg", "deg"),
    ("part_dx_mm", "mm"),
    ("part_dy_mm", "mm"),
    ("part_dz_mm", "mm"),
    ("part_dyaw_deg", "deg"),
)
#: Default half range of each axis (a sensible neighbourhood of the plan's poses): 200 mm and
#: 15 deg, except the part's height, which a table fixes (0).
DEFAULT_HALF: dict[str, float] = {
    "base_dx_mm": 200.0,
    "base_dy_mm": 200.0,
    "base_dyaw_deg": 15.0,
    "part_dx_mm": 200.0,
    "part_dy_mm": 200.0,
    "part_dz_mm": 0.0,
    "part_dyaw_deg": 15.0,
}


def flag_of(axis: str) -> str:
    """The command-line flag of an axis: ``base_dx_mm`` -> ``--base-x``."""
    who, what, _unit = axis.split("_")
    return f"--{who}-{what[1:]}"


def parse_range(text: str, axis: str) -> tuple[float, float]:
    """A range ``MIN:MAX`` or a half width ``H`` (meaning ``-H:H``) of one axis.

    Args:
        text: the flag's value, millimetres or degrees as the axis says.
        axis: one of :data:`AXES`' names (for the message and the bound).

    Raises:
        InputError: not a number, not finite, ``MIN > MAX``, a negative half width, or beyond
            :data:`~calib.limits.MAX_SWEEP_OFFSET_MM` / :data:`~calib.limits.MAX_SWEEP_YAW_DEG`.
    """
    flag = flag_of(axis)
    unit = axis.rsplit("_", 1)[1]
    parts = text.split(":")
    try:
        values = [float(v) for v in parts]
    except ValueError:
        raise InputError(
            f"{flag}: expected MIN:MAX or a half width, {unit}, got {text!r}"
        ) from None
    if len(values) > 2 or not all(math.isfinite(v) for v in values):
        raise InputError(f"{flag}: expected MIN:MAX or a half width, {unit}, got {text!r}")
    if len(values) == 1:
        if values[0] < 0:
            raise InputError(
                f"{flag}: a half width must be >= 0, got {text!r} "
                f"(a range with a negative end is written {flag}=MIN:MAX)"
            )
        lo, hi = -values[0], values[0]
    else:
        lo, hi = values
    if lo > hi:
        raise InputError(f"{flag}: MIN must be <= MAX, got {text!r}")
    bound = MAX_SWEEP_YAW_DEG if unit == "deg" else MAX_SWEEP_OFFSET_MM
    if max(abs(lo), abs(hi)) > bound:
        raise InputError(f"{flag}: must lie within +-{bound:g} {unit}, got {text!r}")
    return (lo + 0.0, hi + 0.0)


@dataclass(frozen=True)
class SweepSpace:
    """The range of every swept axis.

    Attributes:
        ranges: ``{axis: (min, max)}`` for every name of :data:`AXES`, mm or deg.
    """

    ranges: dict[str, tuple[float, float]]

    @classmethod
    def default(cls, **overrides: tuple[float, float]) -> SweepSpace:
        """The default ranges (:data:`DEFAULT_HALF`) with ``overrides`` by axis name."""
        unknown = set(overrides) - set(DEFAULT_HALF)
        if unknown:
            raise InputError(f"unknown sweep axes {sorted(unknown)}; axes: {list(DEFAULT_HALF)}")
        ranges = {a: (-h + 0.0, h) for a, h in DEFAULT_HALF.items()}
        return cls(ranges | overrides)

    def to_json(self) -> dict[str, list[float]]:
        """``{axis: [min, max]}`` in :data:`AXES` order."""
        return {a: list(self.ranges[a]) for a, _ in AXES}


@dataclass(frozen=True)
class Placement:
    """One placement: offsets of the base and the part from the plan's poses.

    Attributes:
        index: the placement's index in the sweep.
        base_dx_mm, base_dy_mm: base origin shift along world x, y, mm.
        base_dyaw_deg: base turn about world z through its origin, deg.
        part_dx_mm, part_dy_mm, part_dz_mm: work-object (and fixtures) shift, world, mm.
        part_dyaw_deg: part and fixtures turned about world z through the wobj origin, deg.
    """

    index: int
    base_dx_mm: float
    base_dy_mm: float
    base_dyaw_deg: float
    part_dx_mm: float
    part_dy_mm: float
    part_dz_mm: float
    part_dyaw_deg: float

    def values(self) -> tuple[float, ...]:
        """The offsets in :data:`AXES` order."""
        return tuple(getattr(self, f.name) for f in fields(self) if f.name != "index")


def placement(space: SweepSpace, seed: int, index: int) -> Placement:
    """Placement ``index`` of the sweep seeded ``seed``: uniform in each range, from
    ``default_rng([seed, index])`` (see the module docstring); offsets in mm and deg."""
    rng = np.random.default_rng([seed, index])
    u = rng.random(len(AXES))
    values = []
    for (axis, unit), ui in zip(AXES, u, strict=True):
        lo, hi = space.ranges[axis]
        v = lo + (hi - lo) * float(ui)
        values.append(round(v, 4 if unit == "deg" else 3) + 0.0)
    return Placement(index, *values)


def _moved(T_world_x: FloatArray, shift_m: FloatArray, yaw_rad: float, pivot_m: FloatArray) -> Pose:
    """``T_world_x`` turned by ``yaw_rad`` about world z through ``pivot_m`` and shifted by
    ``shift_m`` (world, m)."""
    Rz = matrix_from_tait_bryan_zyx(yaw_rad, 0.0, 0.0)
    T_move = make_transform(Rz, pivot_m + shift_m - Rz @ pivot_m)
    return Pose.from_matrix(T_move @ T_world_x)


def placed_plan(plan: Plan, where: Placement) -> Plan:
    """``plan`` with its robot base, work object and fixtures moved as ``where`` says (see the
    module docstring); the points stay in the work-object frame, so they move with the part."""
    T_world_base = plan.cell.robot.T_world_base.matrix()
    base = _moved(
        T_world_base,
        np.array([where.base_dx_mm, where.base_dy_mm, 0.0]) * 1e-3,
        math.radians(where.base_dyaw_deg),
        T_world_base[:3, 3],
    )
    T_world_wobj = plan.work_object.T_world_wobj.matrix()
    shift = np.array([where.part_dx_mm, where.part_dy_mm, where.part_dz_mm]) * 1e-3
    yaw = math.radians(where.part_dyaw_deg)
    pivot = T_world_wobj[:3, 3]
    fixtures = [
        msgspec.structs.replace(
            f, T_world_fixture=_moved(f.T_world_fixture.matrix(), shift, yaw, pivot)
        )
        for f in plan.cell.fixtures
    ]
    cell = msgspec.structs.replace(
        plan.cell,
        robot=msgspec.structs.replace(plan.cell.robot, T_world_base=base),
        fixtures=fixtures,
    )
    work_object = msgspec.structs.replace(
        plan.work_object, T_world_wobj=_moved(T_world_wobj, shift, yaw, pivot)
    )
    return msgspec.structs.replace(plan, cell=cell, work_object=work_object)
