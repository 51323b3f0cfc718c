"""What the validation report gives besides the frame: points of interest, regions, levels.

The plan's ``validation.report`` (:class:`ReportSpec`). Every row of the report (origin x/y/z,
rotations about x/y/z, the error at each point of interest, the pooled error over each region)
is given at the confidence levels listed here, simulated and predicted side by side
(``docs/simulation.md``). The error of a point is ``T_true^-1 T_calibrated p - p`` in the true
work-object axes; ``components`` says which of its components count:

- one axis (``"x"``, ``"y"``, ``"z"``): that signed component;
- a plane (``"yz"``, ``"xz"``, ``"xy"``): its length in that plane, signed by the remaining
  component (the paper's yz-plane error, "positive if the displacement is positive in the
  x-axis", section 4);
- ``"xyz"``: the length of the whole vector, signed by its x component (the paper's xyz-space
  error).
"""

from __future__ import annotations

from typing import Literal, get_args

from calib.errors import PlanError
from calib.limits import MAX_REGION_POINTS, MAX_REPORT_LEVELS, MAX_REPORT_ROWS
from calib.structs import Strict, Vec3, check_count, check_finite, check_length

Components = Literal["xyz", "yz", "xz", "xy", "x", "y", "z"]
#: The valid ``components`` values.
COMPONENTS: tuple[str, ...] = get_args(Components)
#: Region point sets: the whole surface, one planar face, the stator's slot-hole centres.
RegionPoints = Literal["part", "face", "slot_holes"]
#: Highest confidence level a row may ask for, percent (the paper's Table 1 goes this far).
MAX_LEVEL_PERCENT = 99.9999


def check_levels(levels: tuple[float, ...] | None, field: str) -> None:
    """Raise :class:`PlanError` unless every level lies in (0, 99.9999] percent (or None)."""
    if levels is None:
        return
    if not levels:
        raise PlanError(f"{field}: needs at least one confidence level")
    check_length(levels, field, MAX_REPORT_LEVELS, "levels", "each is a row of every report")
    check_finite(levels, field)
    for lv in levels:
        if not 0.0 < lv <= MAX_LEVEL_PERCENT:
            raise PlanError(
                f"{field}: confidence levels are percent in (0, {MAX_LEVEL_PERCENT}], got {lv}"
            )


def _check_name(name: str) -> None:
    if not name or not name.replace("_", "").isalnum():
        raise PlanError(f"name: must be letters, digits or '_', got {name!r}")


class PointOfInterest(Strict, frozen=True, kw_only=True):
    """A point fixed on the part whose error the report gives.

    Attributes:
        name: short name, letters, digits and ``_`` (the row key is ``<components>_<name>``).
        position_m: ``(3,)`` the point, wobj frame, metres (e.g. the paper's epsilon).
        components: which components of the error count (see the module docstring).
        label: the row's label (default ``"<components> error at <name>"``).
        levels_percent: the row's confidence levels, percent (default: the report's).
    """

    name: str
    position_m: Vec3
    components: Components = "xyz"
    label: str = ""
    levels_percent: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        _check_name(self.name)
        check_finite(self.position_m, "position_m")
        check_levels(self.levels_percent, "levels_percent")


class RegionSpec(Strict, frozen=True, kw_only=True):
    """A set of points on the part whose errors the report pools into one row.

    Attributes:
        name: short name (the row key is ``<components>_<name>``).
        points: ``"part"`` the whole surface, ``"face"`` the planar face through
            ``face_point_m``, ``"slot_holes"`` the slot-hole centres of a built-in stator
            within the robot's reach (the paper's "stator side").
        face_point_m: ``(3,)`` a point on the face, wobj frame, metres (``"face"`` only).
        components: which components of each point's error count.
        label: the row's label (default ``"<components> error over <name>"``).
        levels_percent: the row's confidence levels, percent (default: the report's).
        max_points: at most this many surface points are used (area-weighted, fixed seed).
    """

    name: str
    points: RegionPoints = "part"
    face_point_m: Vec3 | None = None
    components: Components = "xyz"
    label: str = ""
    levels_percent: tuple[float, ...] | None = None
    max_points: int = 2000

    def __post_init__(self) -> None:
        _check_name(self.name)
        check_levels(self.levels_percent, "levels_percent")
        check_count(
            self.max_points,
            "max_points",
            maximum=MAX_REGION_POINTS,
            why="validate keeps 2 samples per trial and point: 20,000 points x 400 trials are "
            "128 MB",
        )
        if (self.points == "face") != (self.face_point_m is not None):
            raise PlanError("face_point_m: give it for points 'face', and only then")
        check_finite(self.face_point_m, "face_point_m")


class ReportSpec(Strict, frozen=True, kw_only=True):
    """What the validation report gives.

    Attributes:
        levels_percent: confidence levels of every row without its own, percent (at most
            99.9999, the paper's last level).
        points_of_interest: points whose error is reported; ``None``: the surface point
            farthest from the work-object origin.
        regions: point sets whose pooled error is reported; ``None``: the whole part.
    """

    levels_percent: tuple[float, ...] = (95.5, 99.99)
    points_of_interest: list[PointOfInterest] | None = None
    regions: list[RegionSpec] | None = None

    def __post_init__(self) -> None:
        check_levels(self.levels_percent, "levels_percent")
        for field, group in (
            ("points_of_interest", self.points_of_interest or []),
            ("regions", self.regions or []),
        ):
            check_length(group, field, MAX_REPORT_ROWS, "rows", "each is a row of every report")
        for group in (self.points_of_interest or [], self.regions or []):
            names = [g.name for g in group]
            if len(set(names)) != len(names):
                raise PlanError(f"names must be unique, got {names}")
