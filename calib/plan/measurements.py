"""Points measured on the real robot: the file format ``wobjcal.measurements/1``.

Example::

    {"schema": "wobjcal.measurements/1", "frame": "base", "units": "mm",
     "points": {"A": [1510.2, -402.7, 731.9], "B": [1511.0, 297.1, 732.4]}}

``frame`` is ``base`` (the robot controller's base, as read from a ``robtarget``/``pos`` in
RAPID without a work object: on a robot whose URDF hangs a turned ROS-Industrial ``base`` link
from its base link, a UR arm's Base, that frame; ``planner.robot.controller_base``) or
``world`` (the cell frame; converted with the plan's ``T_world_base``).
``units`` is ``m`` or ``mm``. ``retakes`` optionally holds later measurements of the same point
(the A-H procedure measures C and D twice), in the order they were taken. ``failed`` names points
whose search failed on the robot, with the reason. Inside the code everything is metres.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Final, Literal

import msgspec
import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.atomic_io import write_text_atomic
from calib.errors import InputError
from calib.frames import transform_points
from calib.plan.json_io import (
    canonical_json,
    check_schema_tag,
    convert_strict,
    parse_json_text,
    read_text_file,
)
from calib.tolerances import COORDINATE_LIMIT_M

MEASUREMENTS_SCHEMA: Final = "wobjcal.measurements/1"
SUPPORTED_MEASUREMENTS_SCHEMAS = (MEASUREMENTS_SCHEMA,)
_SCALE = {"m": 1.0, "mm": 1e-3}
Vec3 = tuple[float, float, float]


class MeasurementsError(InputError):
    """A measurements file is malformed; the message names the file and the JSON path."""


class Measurements(msgspec.Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """Measured sensor-TCP positions at the switching events, one per probe point id.

    Attributes:
        schema: ``"wobjcal.measurements/1"``.
        frame: ``base`` or ``world``: the frame the coordinates are given in.
        units: ``m`` or ``mm``: the unit of the coordinates.
        points: ``{id: (x, y, z)}`` first measurement of each point, in ``frame`` and ``units``.
        retakes: ``{id: [(x, y, z), ...]}`` later measurements of a point, in order.
        failed: ``{id: reason}`` points whose search failed on the robot.
        comment: free text (robot, date, operator).
        plan_digest: :func:`calib.plan.file.plan_digest` of the plan whose program measured
            the points (the RAPID program writes it; ``""``: not given, e.g. written by hand).
    """

    schema: Literal["wobjcal.measurements/1"] = MEASUREMENTS_SCHEMA
    frame: Literal["base", "world"] = "base"
    units: Literal["m", "mm"] = "m"
    points: dict[str, Vec3] = {}
    retakes: dict[str, list[Vec3]] = {}
    failed: dict[str, str] = {}
    comment: str = ""
    plan_digest: str = ""

    def __post_init__(self) -> None:
        for pid in self.retakes:
            if pid not in self.points:
                raise MeasurementsError(f"retakes.{pid}: no first measurement in points")
        both = sorted(set(self.points) & set(self.failed))
        if both:
            raise MeasurementsError(f"failed: {both} are also listed in points")

    @property
    def scale(self) -> float:
        """Metres per file unit."""
        return _SCALE[self.units]

    def sequence_m(self, point_id: str, T_base_frame: ArrayLike | None = None) -> NDArray:
        """All measurements of ``point_id`` in order, ``(k, 3)`` metres, in the ``base`` frame
        (the controller's base for a ``base`` file; a ``world`` file turned into the robot's
        base link with ``T_base_frame``).

        Args:
            point_id: the point id.
            T_base_frame: ``(4, 4)`` pose of ``frame`` in the base frame; required when
                ``frame`` is ``world`` (it is ``inv(T_world_base)``), ignored for ``base``.
        """
        if point_id not in self.points:
            why = (
                f" (failed on the robot: {self.failed[point_id]})"
                if point_id in self.failed
                else ""
            )
            raise MeasurementsError(
                f"points.{point_id}: not measured{why}; measured: {sorted(self.points)}"
            )
        rows = [self.points[point_id], *self.retakes.get(point_id, [])]
        pts = np.asarray(rows, dtype=np.float64) * self.scale
        if self.frame == "world":
            if T_base_frame is None:
                raise MeasurementsError("frame: 'world' needs T_base_world to convert to base")
            pts = transform_points(T_base_frame, pts)
        return pts

    def points_m(self, T_base_frame: ArrayLike | None = None) -> dict[str, NDArray]:
        """First measurement of every point, ``{id: (3,)}`` metres, base frame."""
        return {pid: self.sequence_m(pid, T_base_frame)[0] for pid in self.points}

    @classmethod
    def from_points_m(
        cls, points_m: dict[str, ArrayLike], units: Literal["m", "mm"] = "m", comment: str = ""
    ) -> Measurements:
        """Measurements in the base frame from ``{id: (3,)}`` metres, written in ``units``."""
        s = 1.0 / _SCALE[units]
        pts = {}
        for pid, p in points_m.items():
            a = np.asarray(p, dtype=float) * s
            pts[pid] = (float(a[0]), float(a[1]), float(a[2]))
        return cls(frame="base", units=units, points=pts, comment=comment)


_CHOICES = {"frame": ("base", "world"), "units": ("m", "mm")}


def _check_xyz(value: object, where: str, source: str, unit: str) -> None:
    """msgspec does not name dict keys in its paths, so check ``{id: [x, y, z]}`` here; a
    coordinate beyond :data:`calib.tolerances.COORDINATE_LIMIT_M` (1e308, a typo) is refused
    naming the point, before any arithmetic."""
    if not isinstance(value, list):
        raise MeasurementsError(f"{source}: {where}: must be a list [x, y, z]")
    if len(value) != 3:
        raise MeasurementsError(f"{source}: {where}: must have length 3, got {len(value)}")
    limit = COORDINATE_LIMIT_M / _SCALE.get(unit, 1.0)
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise MeasurementsError(
                f"{source}: {where}[{i}]: must be a number, got {type(v).__name__}"
            )
        if not math.isfinite(v) or abs(v) > limit:
            raise MeasurementsError(
                f"{source}: {where}[{i}]: {v:g} {unit} is not a plausible coordinate "
                f"(limit +-{limit:g} {unit})"
            )


#: How to convert a length unit people use into mm, for the message refusing it.
_TO_MM = {"cm": "multiply by 10", "dm": "multiply by 100", "in": "multiply by 25.4"}
_TO_MM |= {"inch": _TO_MM["in"], "um": "divide by 1000", "µm": "divide by 1000"}


def _check_point_maps(raw: dict[str, object], source: str) -> None:
    unit = raw.get("units", "m")
    if not (isinstance(unit, str) and unit in _SCALE):  # named before any coordinate is judged
        how = _TO_MM.get(unit.strip().lower(), "") if isinstance(unit, str) else ""
        raise MeasurementsError(
            f"{source}: units: {unit!r} is not a unit of this format (m or mm); convert to mm"
            + (f" ({how})" if how else "")
        )
    points = raw.get("points")
    if isinstance(points, dict):
        for pid, xyz in points.items():
            _check_xyz(xyz, f"points.{pid}", source, unit)
    retakes = raw.get("retakes")
    if isinstance(retakes, dict):
        for pid, rows in retakes.items():
            if not isinstance(rows, list):
                raise MeasurementsError(f"{source}: retakes.{pid}: must be a list of [x, y, z]")
            for k, xyz in enumerate(rows):
                _check_xyz(xyz, f"retakes.{pid}[{k}]", source, unit)


def measurements_from_json(text: str, source: str = "measurements") -> Measurements:
    """Parse and validate measurements JSON text; errors name ``source`` and the JSON path."""
    raw = parse_json_text(text, MeasurementsError, source)
    check_schema_tag(raw, SUPPORTED_MEASUREMENTS_SCHEMAS, MeasurementsError, source)
    _check_point_maps(raw, source)
    return convert_strict(raw, Measurements, MeasurementsError, source, _CHOICES)


def load_measurements(path: str | Path) -> Measurements:
    """Read a measurements file strictly (see :func:`measurements_from_json`)."""
    p = Path(path)
    return measurements_from_json(
        read_text_file(p, MeasurementsError, "measurements file"), source=str(p)
    )


def save_measurements(measurements: Measurements, path: str | Path) -> Path:
    """Write ``measurements`` atomically as canonical JSON."""
    return write_text_atomic(path, canonical_json(measurements))
