"""Landing risk: how often each search of a program misses, starts too close, or lands off its
face, under the plan's misplacement.

The program (:mod:`planner.program`) is executed against the ideal part (its faces' planes,
:class:`calib.plane_probe.PlaneProbe`) misplaced as the validation misplaces it,
:data:`TRIALS` seeded times; no noise (micrometres against millimetres of misplacement). For every
search it records the travel to its event against the search's length, and for every approach
where it lands on the true part: the centre of the sensor's footprint must lie on the planar
face the point is on (:class:`planner.faces.outline.FaceOutlines`; the footprint partly over a
hole or past an edge is counted and shown, not failed: the reading is biased, not wrong).
A nominal program lands every search anywhere the whole misplacement allows; an adaptive one
lands a search near its nominal spot once the points before it have fixed its face.

This is the same program ``wobjcal validate --format`` simulates on the real mesh (where the
footprint's rays see holes and edges); here it is cheap enough for ``wobjcal check`` and export,
which fail a plan whose searches go wrong in more than :data:`RISK_LIMIT` of calibrations.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import NDArray

from calib.errors import InputError, ProbeFailedError
from calib.frames import invert_transform, transform_points
from calib.models import Misplacement
from calib.plane_probe import PlaneProbe
from calib.probing import ProbeResult, SearchCommand
from calib.procedures.base import edge_offset_of
from planner.faces.outline import FaceOutlines
from planner.program.execute import execute
from planner.program.model import FACE_APPROACH, MeasuringProgram, search_keys
from planner.reasons import Reason
from planner.sim.raycast import MeshRayCaster

FloatArray = NDArray[np.float64]

#: A plan fails when its searches go wrong in more than this share of calibrations.
RISK_LIMIT = 0.01
#: Misplaced calibrations executed (seeded).
TRIALS = 128


@dataclass(frozen=True)
class SearchRisk:
    """How often one search of the program goes wrong (shares of calibrations, 0 to 1).

    Attributes:
        key: the search's key (``"P1"``, ``"C2"``, ``"F@face"``).
        point_id: the plan's point id.
        miss: the search ends before it meets its face or edge.
        start_inside: it starts at or past its face or edge (already detecting).
        off_face: the centre of the sensor's footprint where it lands is off the point's planar
            face (over a hole, past an edge: approach searches); the search measures another
            surface.
        partly_off: the footprint lies partly over a hole or past an edge (its centre on the
            face): the reading is biased, not wrong (the paper's stator teeth are narrower
            than its sensor), so it is shown, not failed.
        other_surface: the sensor's face meets another surface of the part before its own
            face (or starts inside the part): it switches early, or runs into it (approach
            searches, judged on the part's mesh).
    """

    key: str
    point_id: str
    miss: float
    start_inside: float
    off_face: float
    partly_off: float = 0.0
    other_surface: float = 0.0

    @property
    def worst(self) -> float:
        """The largest share of the failures (misses, starts inside, off its face, another
        surface first)."""
        return max(self.miss, self.start_inside, self.off_face, self.other_surface)


@dataclass(frozen=True)
class LandingRisk:
    """The landing risk of a program.

    Attributes:
        program: the program's name.
        trials: misplaced calibrations executed.
        searches: per search, in program order.
        failed: the share of calibrations in which at least one search goes wrong.
    """

    program: str
    trials: int
    searches: tuple[SearchRisk, ...]
    failed: float

    def point_problems(self, limit: float = RISK_LIMIT) -> dict[str, Reason]:
        """``{point id: why, and what to change}`` for the points whose searches go wrong in
        more than ``limit`` of calibrations: a ``search`` reason each."""
        out: dict[str, list[str]] = {}
        for s in self.searches:
            if s.worst <= limit:
                continue
            what = s.key if s.key != s.point_id else "the search"
            if s.key.endswith(FACE_APPROACH):
                what = "the approach to its face"
            parts = []
            if s.off_face > limit:
                parts.append(
                    f"{what} lands off its face (over a hole or past an edge) in "
                    f"{s.off_face:.0%} of calibrations: move the point inward, away from its "
                    "face's edges and holes, measure it after points that fix its face (an "
                    "adaptive program), or give a smaller misplacement bound"
                )
            if s.miss > limit:
                parts.append(
                    f"{what} ends before it meets its face or edge in {s.miss:.0%} of "
                    "calibrations: a longer search (overtravel), or a smaller misplacement bound"
                )
            if s.other_surface > limit:
                parts.append(
                    f"{what} meets another surface of the part before its face (or starts "
                    f"inside it) in {s.other_surface:.0%} of calibrations: move the point away "
                    "from the walls beside it, start it from another side, or give a smaller "
                    "misplacement bound"
                )
            if s.start_inside > limit:
                parts.append(
                    f"{what} starts at or past its face or edge in {s.start_inside:.0%} of "
                    "calibrations: start it farther out, or a smaller misplacement bound"
                )
            out.setdefault(s.point_id, []).extend(parts)
        return {
            pid: Reason("search", f"{self.program}: " + "; ".join(parts))
            for pid, parts in out.items()
            if parts
        }

    def to_json(self) -> dict[str, object]:
        """JSON-ready: shares per search."""
        return {
            "program": self.program,
            "trials": self.trials,
            "failed": self.failed,
            "limit": RISK_LIMIT,
            "searches": [
                {
                    "key": s.key,
                    "point": s.point_id,
                    "miss": s.miss,
                    "start_inside": s.start_inside,
                    "off_face": s.off_face,
                    "partly_off": s.partly_off,
                    "other_surface": s.other_surface,
                }
                for s in self.searches
            ],
        }


@dataclass
class _Recorder:
    """The ideal part at one pose; records each search's command, travel and landing."""

    ideal: PlaneProbe
    rows: list[tuple[SearchCommand, float, FloatArray]]

    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        res = self.ideal(cmd)
        travel = float(res.travel_m) if res.point_m is not None else float("nan")
        hit = np.asarray(res.point_m if res.point_m is not None else cmd.start_m, float)
        self.rows.append((cmd, travel, hit))
        return res


#: Rays of the sensor face's bundle: its centre and this many around its rim.
RIM_RAYS = 8
#: A surface met this much before the search's own face counts as another surface, m.
OTHER_SURFACE_TOL_M = 1e-3


#: The rim's directions around the sensor axis (cosine and sine of each rim ray's angle).
_RIM_ANGLES = np.linspace(0.0, 2.0 * np.pi, RIM_RAYS, endpoint=False)
_RIM_COS, _RIM_SIN = np.cos(_RIM_ANGLES), np.sin(_RIM_ANGLES)


def _face_rays(
    start_wobj: FloatArray, axis_wobj: FloatArray, standoff_m: float, radius_m: float
) -> FloatArray:
    """``(N, 1 + RIM_RAYS, 3)`` origins on the sensor's face of ``N`` searches (``standoff_m``
    behind the TCP at ``start_wobj`` ``(N, 3)``, along ``axis_wobj`` ``(N, 3)``; wobj frame,
    m): its centre and its rim (``radius_m``)."""
    a = axis_wobj / np.linalg.norm(axis_wobj, axis=1, keepdims=True)
    helper = np.eye(3)[np.argmin(np.abs(a), axis=1)]
    u = np.cross(a, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(a, u)
    rim = radius_m * (
        _RIM_COS[None, :, None] * u[:, None, :] + _RIM_SIN[None, :, None] * v[:, None, :]
    )
    centre = start_wobj - standoff_m * a
    return np.concatenate([centre[:, None, :], centre[:, None, :] + rim], axis=1)


def landing_risk(
    program: MeasuringProgram,
    T_base_wobj_nominal: FloatArray,
    misplacement: Misplacement,
    pivot_wobj_m: FloatArray,
    outlines: FaceOutlines,
    face_of: Mapping[str, int],
    trials: int = TRIALS,
    seed: int = 0,
    caster: MeshRayCaster | None = None,
    standoff_m: float = 0.0,
    footprint_radius_m: float = 0.0,
    triangle_face: NDArray[np.int64] | None = None,
) -> LandingRisk:
    """The landing risk of ``program`` (see the module docstring).

    Args:
        program: the program.
        T_base_wobj_nominal: ``(4, 4)`` the nominal part, base frame.
        misplacement: the plan's misplacement bound (drawn as the validation draws it).
        pivot_wobj_m: ``(3,)`` the misplacement's pivot, wobj frame, m.
        outlines: the part's planar faces with the sensor's footprint.
        face_of: ``{point id: planar face id}`` (``-1`` or missing: not judged).
        trials: misplaced calibrations to execute.
        seed: seed of the misplacements.
        caster: the part's mesh (wobj frame), to find the approaches whose sensor face meets
            another surface before their own face; ``None``: not judged.
        standoff_m: the sensor's sensing distance (its face lies that far behind the TCP), m.
        footprint_radius_m: the sensor face's radius, m.
        triangle_face: ``(T,)`` the planar face of each mesh triangle (``-1``: none), so a
            ray that meets the point's own face (tilted, off its plane by the rim's lever)
            does not count as another surface; ``None``: every early hit counts.
    """
    rng = np.random.default_rng(seed)
    keys = search_keys(program.points)
    edge_ids = {rp.point.id for rp in program.points if rp.point.search.kind == "edge"}
    edge_offset = edge_offset_of(program.settings)
    runs: dict[str, list[tuple[int, bool, bool]]] = {}  # key -> (trial, miss, inside)
    landed: dict[str, list[tuple[int, FloatArray]]] = {}  # key -> (trial, wobj point)
    # key -> (trial, start (3,), sensor axis (3,), direction (3,), distance to the own face),
    # wobj; the sensor face's rays are made from them per key, in one batch
    rays: dict[str, list[tuple[int, FloatArray, FloatArray, FloatArray, float]]] = {}
    for trial in range(trials):
        T_true = T_base_wobj_nominal @ misplacement.sample(rng, pivot_wobj_m)
        rec = _Recorder(PlaneProbe(T_true, edge_offset), [])
        # an update that fails on the way: the searches so far count
        with contextlib.suppress(ProbeFailedError, InputError):
            execute(program, T_base_wobj_nominal, rec)
        T_wobj_base = invert_transform(T_true)
        for cmd, travel, hit in rec.rows:
            key, length = cmd.point_id, float(cmd.length_m)
            miss = not travel <= length  # NaN: no event at all
            runs.setdefault(key, []).append((trial, miss, travel < 0.0))
            judged = key.endswith(FACE_APPROACH) or keys.get(key) not in edge_ids
            if judged:  # an approach: where its footprint lands
                landed.setdefault(key, []).append((trial, transform_points(T_wobj_base, hit)))
            if judged and caster is not None and np.isfinite(travel):
                R = T_wobj_base[:3, :3]
                start = transform_points(T_wobj_base, np.asarray(cmd.start_m, float))
                axis = R @ np.asarray(cmd.sensor_axis, float)
                d = R @ np.asarray(cmd.direction, float)
                rays.setdefault(key, []).append((trial, start, axis, d, travel + standoff_m))
    bad_trials: set[int] = set()
    off_of: dict[str, int] = {}
    partly_of: dict[str, int] = {}
    for key, at in landed.items():
        face = face_of.get(keys.get(key, key), -1)
        if face < 0:
            continue
        uv = np.array([q for _, q in at]) @ outlines.basis(face)
        off = ~shapely.contains_xy(outlines.face(face), uv[:, 0], uv[:, 1])
        partly = ~shapely.contains_xy(outlines.free(face), uv[:, 0], uv[:, 1]) & ~off
        off_of[key], partly_of[key] = int(np.sum(off)), int(np.sum(partly))
        bad_trials |= {trial for (trial, _), o in zip(at, off, strict=True) if o}
    other_of: dict[str, int] = {}
    if caster is not None:
        for key, items in rays.items():
            starts = np.array([it[1] for it in items])
            axes = np.array([it[2] for it in items])
            o = _face_rays(starts, axes, standoff_m, footprint_radius_m).reshape(-1, 3)
            d = np.repeat(np.array([it[3] for it in items]), 1 + RIM_RAYS, axis=0)
            dist, tri = caster.first_hits_ids(o, d)
            dist = dist.reshape(len(items), 1 + RIM_RAYS)
            own = np.array([it[4] for it in items])
            hit_early = dist < own[:, None] - OTHER_SURFACE_TOL_M
            if triangle_face is not None:  # the point's own planar face is not another surface
                face = face_of.get(keys.get(key, key), -1)
                same = (tri >= 0) & (triangle_face[np.maximum(tri, 0)] == face) & (face >= 0)
                hit_early &= ~(same.reshape(hit_early.shape) & (dist > 0.0))
            early = np.any(hit_early, axis=1)
            other_of[key] = int(np.sum(early))
            bad_trials |= {it[0] for it, e in zip(items, early, strict=True) if e}
    searches = []
    for key, rows in runs.items():
        n = len(rows)
        n_miss = sum(row[1] for row in rows)
        n_inside = sum(row[2] for row in rows)
        bad_trials |= {trial for trial, m, i in rows if m or i}
        pid = keys.get(key, key)
        off, partly = off_of.get(key, 0) / n, partly_of.get(key, 0) / n
        other = other_of.get(key, 0) / n
        searches.append(SearchRisk(key, pid, n_miss / n, n_inside / n, off, partly, other))
    return LandingRisk(program.name, trials, tuple(searches), len(bad_trials) / max(trials, 1))
