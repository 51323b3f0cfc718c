"""Suggest a probe layout: the one entry point ``wobjcal suggest``, the UI and scripts share.

:func:`suggest_plan` takes a plan (its cell, part, sensor, noise figures, misplacement and
points of interest) and proposes the points:

1. candidates on the part's planar faces whose sensor footprint, grown by the in-plane shift
   the misplacement allows, lies on the face (:mod:`planner.faces.candidates`); approach
   searches started and run long enough for the misplacement
   (:class:`planner.export.safety.SafetySpec`, as the exported programs and the validation's
   preflight size them), so they still hit their face;
2. feasible in the cell: the probe pose (:meth:`planner.cell.cell.Cell.check_probes`, six
   spread samples per face first, a face whose samples all fail is dropped with the reason)
   and, for every point the design picks, the search path
   (:meth:`~planner.cell.cell.Cell.check_search`; a blocked one is dropped and the design redone);
3. chosen by :func:`calib.estimators.design.select` (greedy plus exchange on the information
   matrix, minimising the largest error over the points of interest), growing the number of
   points until the predicted error at every point of interest holds ``target_m`` at the
   confidence, or ``max_points`` is reached (3-2-1: six points, every ordered triple of faces);
4. the written plan's quality predicted exactly (:func:`planner.check.plan_quality`: the
   procedure linearised), which is what the result reports.

``add=N`` keeps the plan's points and adds the ``N`` best (best fit only).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec
import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError
from calib.estimators.design import Design, poi_jacobians, select
from calib.estimators.layout import constraint_jacobian, search_constraint_set
from calib.plan.file import Plan, PlanError, PlanPoint
from calib.plan.report_spec import PointOfInterest, ReportSpec
from calib.probing import ProbePoint, SearchCommand, SearchSpec
from calib.procedures import BestFit, ThreeTwoOne
from planner.check import plan_quality
from planner.export.safety import SafetySpec
from planner.faces.candidates import Candidates, FaceTried, face_candidates
from planner.faces.detection import find_planar_faces
from planner.plan_cell import nominal_T_base_wobj, open_cell
from planner.sim.report_points import poi_rows
from planner.sim.rows import RowSpec, predicted_sigma, z_values

if TYPE_CHECKING:
    from planner.cell.cell import Cell
    from planner.sim.quality import LayoutQuality

FloatArray = NDArray[np.float64]
#: progress(stage, done, total)
SuggestProgress = Callable[[str, int, int], None]
PROCEDURES = ("best_fit", "three_two_one")
#: Candidates per planar face (after thinning), and the samples tried first on each face.
PER_FACE = 40
PROBE_FIRST = 6


class SuggestError(PlanError):
    """No layout can be suggested: the message names the faces tried and what stopped them."""


@dataclass(frozen=True)
class SuggestResult:
    """A suggested layout.

    Attributes:
        plan: the plan with the suggested points (and procedure).
        quality: its predicted quality (the procedure linearised), or None.
        target_m: the target half-width at the points of interest, metres (None: none).
        confidence_percent: the level the target and ``worst_m`` are at, percent.
        worst_m: the largest predicted half-width over the points of interest, metres.
        met: the target holds (always True without a target).
        history: ``(points, worst half-width m)`` of the design at each size tried (the
            least-squares model of the searches, before the exact prediction).
        faces: every planar face tried and what its samples met.
        n_candidates: candidates whose grown footprint lies on their face.
        n_feasible: of those, feasible probe poses in the cell.
        rejected: why the others were dropped: ``{"reach": n, "collision": n, ...}``.
        message: one line for humans: met, or the best reached and why not better.
        elapsed_s: wall time, s.
        pool: the candidates with a feasible probe pose (search paths checked only for the
            ones a design picked).
    """

    plan: Plan
    quality: LayoutQuality | None
    target_m: float | None
    confidence_percent: float
    worst_m: float
    met: bool
    history: tuple[tuple[int, float], ...]
    faces: tuple[FaceTried, ...] = field(repr=False)
    n_candidates: int
    n_feasible: int
    rejected: dict[str, int]
    message: str
    elapsed_s: float
    pool: Candidates | None = field(default=None, repr=False)


def _why(reason: str) -> str:
    r = reason.lower()
    if "reach" in r or "no ik" in r:
        return "reach"
    if "limit" in r:
        return "joint limits"
    if "singular" in r:
        return "singularity"
    if "hit" in r or "clearance" in r or "collision" in r:
        return "collision"
    return "other"


def _pois(plan: Plan, mesh: object, at_m: FloatArray | None) -> list[RowSpec]:
    spec = plan.validation.report
    if at_m is not None:
        pts = [
            PointOfInterest(name=f"at{i + 1}", position_m=tuple(float(c) for c in p))  # type: ignore[arg-type]
            for i, p in enumerate(np.asarray(at_m, dtype=np.float64).reshape(-1, 3))
        ]
        spec = msgspec.structs.replace(spec, points_of_interest=pts)
    return poi_rows(spec, mesh)  # type: ignore[arg-type]


def suggest_plan(
    plan: Plan,
    plan_dir: Path | None = None,
    *,
    target_m: float | None = None,
    confidence_percent: float | None = None,
    at_m: FloatArray | None = None,
    max_points: int = 8,
    procedure: str = "best_fit",
    add: int = 0,
    progress: SuggestProgress | None = None,
    cell: Cell | None = None,
    per_face: int = PER_FACE,
) -> SuggestResult:
    """Suggest the probe points of ``plan`` (see the module docstring).

    Args:
        plan: the plan: cell, work object, validation models and report (its points are
            replaced, or kept with ``add``).
        plan_dir: folder the plan's files resolve against (default: the current folder).
        target_m: the largest predicted half-width at the points of interest, metres.
        confidence_percent: the level of the target (default: the first report level).
        at_m: ``(K, 3)`` points of interest, wobj frame, metres (default: the plan's).
        max_points: most points to suggest (best fit; 3-2-1 takes six).
        procedure: ``"best_fit"`` or ``"three_two_one"``.
        add: keep the plan's points and add this many (best fit only).
        progress: ``progress(stage, done, total)``.
        cell: the plan's open cell (the UI's); ``None`` opens one.
        per_face: candidates per planar face.

    Raises:
        SuggestError: no layout can be had (the message names faces and reasons).
        InputError: bad arguments, or a plan file that cannot load.
    """
    if procedure not in PROCEDURES:
        raise InputError(f"procedure: one of {', '.join(PROCEDURES)}, got {procedure!r}")
    if add and procedure != "best_fit":
        raise InputError("--add works with the best fit (3-2-1 takes exactly six points)")
    if add and plan.method not in ("best_fit",):
        raise InputError(
            f"--add: the plan's procedure is {plan.method}; added points need the best fit "
            "(suggest a new layout with --procedure best_fit instead)"
        )
    if target_m is not None and not (math.isfinite(target_m) and target_m > 0):
        raise InputError(f"target: a positive distance, got {target_m!r} m")
    if max_points < 6 and not add:
        raise InputError(f"max_points: a 6-DOF frame needs at least 6 searches, got {max_points}")
    if cell is None:
        with open_cell(plan, plan_dir or Path.cwd()) as own:
            return suggest_plan(
                plan,
                target_m=target_m,
                confidence_percent=confidence_percent,
                at_m=at_m,
                max_points=max_points,
                procedure=procedure,
                add=add,
                progress=progress,
                cell=own,
                per_face=per_face,
            )
    t0 = time.perf_counter()
    say = progress or (lambda stage, done, total: None)
    wo = cell.work_object
    if wo is None:
        raise InputError("the plan's cell has no work object")
    mesh = wo.mesh
    sensor = plan.validation.sensor
    r = max(float(sensor.footprint_radius_m), 1e-4)
    say("planar faces", 0, 1)
    faces = find_planar_faces(mesh, min_area_m2=math.pi * r**2, footprint_radius_m=r, name=wo.name)
    try:
        faces.require_any()
    except InputError as exc:
        raise SuggestError(f"no layout: {exc}") from None
    m = plan.validation.misplacement

    def shift(P: FloatArray) -> FloatArray:
        return np.full(len(P), m.max_translation_m)

    say("candidates", 0, len(faces.faces))
    cands = face_candidates(faces, r, per_face, shift)
    feasible, rejected = _feasible(cell, plan, cands, say)
    tried = cands.faces
    pool = cands.subset(feasible)
    if len(pool) == 0:
        raise SuggestError(_nothing_message(tried, rejected, len(cands)))
    pivot = pool.positions_m.mean(axis=0)  # the probed region: the misplacement's pivot
    safety = SafetySpec(
        max_translation_m=m.max_translation_m,
        max_angle_rad=m.max_angle_rad,
        pivot_wobj_m=(float(pivot[0]), float(pivot[1]), float(pivot[2])),
        sensing_distance_m=sensor.standoff_m,
    )
    rows_poi = _pois(plan, mesh, at_m)
    level = (
        float(confidence_percent)
        if confidence_percent is not None
        else float(rows_poi[0].levels_percent[0])
    )
    z = float(z_values((level,))[0])
    lo, hi = mesh.bounds
    corners = np.array(
        [[x, y, w] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for w in (lo[2], hi[2])]
    )
    ctx = _Context(cell, plan, pool, safety, rows_poi, z, r, corners)
    fixed = _fixed_rows(plan) if add else None
    if procedure == "three_two_one":
        design, history = _three_two_one(ctx, say)
    else:
        design, history = _best_fit(ctx, target_m, max_points, add, fixed, say)
    if design is None:
        raise SuggestError(
            "no layout fixes all 6 degrees of freedom with the feasible candidates (the "
            "footprint is grown by the misplacement's translation, "
            f"{plan.validation.misplacement.max_translation_m * 1e3:.1f} mm): "
            + _faces_text(tried, pool, ctx)
        )
    new_plan = _plan(plan, ctx, design, procedure, add, at_m)
    say("prediction", 0, 1)
    quality, note = plan_quality(new_plan, mesh)
    worst = quality.worst_poi_m(level) if quality is not None else math.nan
    met = target_m is None or (math.isfinite(worst) and worst <= target_m)
    n = len(new_plan.points)
    if met:
        msg = (
            f"{n} points: predicted error at the points of interest {worst * 1e3:.3f} mm "
            f"at {level:g} %"
        )
    else:
        msg = (
            f"target {(target_m or 0.0) * 1e3:.3f} mm at {level:g} % not reached: the best "
            "layout of "
            f"{n} points gives {worst * 1e3:.3f} mm (more points: --max-points; or a smaller "
            "noise or misplacement)"
        )
    if note:
        msg += f" ({note})"
    return SuggestResult(
        plan=new_plan,
        quality=quality,
        target_m=target_m,
        confidence_percent=level,
        worst_m=worst,
        met=met,
        history=tuple(history),
        faces=tried,
        n_candidates=len(cands),
        n_feasible=len(pool),
        rejected=rejected,
        message=msg,
        elapsed_s=time.perf_counter() - t0,
        pool=pool,
    )


@dataclass
class _Context:
    cell: Cell
    plan: Plan
    pool: Candidates
    safety: SafetySpec
    rows_poi: list[RowSpec]
    z: float
    radius_m: float
    corners: FloatArray | None = None
    path_ok: dict[int, bool] = field(default_factory=dict)
    path_why: dict[int, str] = field(default_factory=dict)

    @property
    def poi(self) -> list[FloatArray]:
        pts = np.concatenate([r.points_wobj for r in self.rows_poi if r.points_wobj is not None])
        return poi_jacobians(pts, [r.components for r in self.rows_poi])

    def rows(self) -> tuple[FloatArray, FloatArray]:
        A = constraint_jacobian(self.pool.normals, self.pool.positions_m)
        sensor = self.plan.validation.sensor
        s = sensor.search_noise("approach", 0.003).sensor_sigma_m
        var = s**2 + self.plan.validation.robot_error.repeatability_sigma_m**2
        return A, np.full(len(A), var)

    def probe(self, i: int, pid: str) -> ProbePoint:
        p = self.pool.positions_m[i]
        search = SearchSpec(
            "approach",
            start_offset_m=max(0.015, self.safety.start_clearance_m(p)),
            overtravel_m=max(0.010, self.safety.overtravel_m(p)),
        )
        return ProbePoint(pid, tuple(float(c) for c in p), tuple(self.pool.normals[i]), search)  # type: ignore[arg-type]

    def size_searches(self, chosen: tuple[int, ...]) -> bool:
        """Size the searches for the misplacement about the chosen points' centroid (the
        validation's pivot); re-check the paths whose start moved. False: one is blocked."""
        c = self.pool.positions_m[list(chosen)].mean(axis=0)
        pivot = (float(c[0]), float(c[1]), float(c[2]))
        if pivot == self.safety.pivot_wobj_m:
            return True
        old = {i: self.probe(i, "c").search for i in chosen}
        self.safety = dataclasses.replace(self.safety, pivot_wobj_m=pivot)
        for i in chosen:
            if self.probe(i, "c").search != old[i]:
                self.path_ok.pop(i, None)
        return self.paths_ok(chosen)

    def worst(self, cov: FloatArray) -> float:
        if not np.all(np.isfinite(cov)):
            return math.inf
        return max(self.z * predicted_sigma(r, cov) for r in self.rows_poi)

    def paths_ok(self, chosen: tuple[int, ...]) -> bool:
        """Check the search paths of the chosen candidates not yet checked."""
        T = nominal_T_base_wobj(self.plan)
        tcp = self.plan.cell.tool.tcp
        for i in chosen:
            if i in self.path_ok:
                continue
            pose = self.cell.check_probes(
                self.pool.positions_m[i : i + 1], self.pool.normals[i : i + 1], tcp=tcp
            )[0]
            path = self.cell.check_search(
                SearchCommand.from_point(self.probe(i, "c"), T), q_ref=pose.q
            )
            self.path_ok[i] = bool(pose.feasible and path.feasible)
            self.path_why[i] = str(path.reason or pose.reason)
        return all(self.path_ok[i] for i in chosen)


def _feasible(
    cell: Cell, plan: Plan, cands: Candidates, say: SuggestProgress
) -> tuple[NDArray[np.bool_], dict[str, int]]:
    """Feasible probe poses: a few spread samples per face first, the rest of the faces
    where any of those passed."""
    ok = np.zeros(len(cands), dtype=bool)
    rejected: dict[str, int] = {}
    tcp = plan.cell.tool.tcp
    face_ids = sorted(set(cands.face.tolist()))
    first = np.concatenate([np.flatnonzero(cands.face == f)[:PROBE_FIRST] for f in face_ids])
    rest = []
    say("feasibility", 0, len(face_ids))

    def run(idx: list[int]) -> None:
        res = cell.check_probes(cands.positions_m[idx], cands.normals[idx], tcp=tcp)
        for i, x in zip(idx, res, strict=True):
            ok[i] = x.feasible
            if not x.feasible:
                key = _why(x.reason)
                rejected[key] = rejected.get(key, 0) + 1

    run(first.tolist())
    for f in face_ids:
        idx = np.flatnonzero(cands.face == f)
        if ok[idx[:PROBE_FIRST]].any():
            rest.extend(idx[PROBE_FIRST:].tolist())
        else:
            dropped = max(0, len(idx) - PROBE_FIRST)
            rejected["face dropped"] = rejected.get("face dropped", 0) + dropped
    if rest:
        run(rest)
    say("feasibility", len(face_ids), len(face_ids))
    return ok, {k: v for k, v in rejected.items() if v > 0}


def _fixed_rows(plan: Plan) -> tuple[FloatArray, FloatArray]:
    cs = search_constraint_set([p.to_probe_point() for p in plan.points])
    A = constraint_jacobian(cs.normals, cs.nominal_m)
    s = plan.validation.sensor.search_noise("approach", 0.003).sensor_sigma_m
    var = s**2 + plan.validation.robot_error.repeatability_sigma_m**2
    return A, np.full(len(A), var)


def _select_feasible(ctx: _Context, n: int, **kw: object) -> Design | None:
    """The design of ``n`` points whose search paths are all feasible (blocked ones dropped)."""
    A, var = ctx.rows()
    for _ in range(50):
        blocked = np.array([ctx.path_ok.get(i, True) is False for i in range(len(A))])
        d = select(
            A,
            var,
            n,
            ctx.poi,
            positions_m=ctx.pool.positions_m,
            available=~blocked,
            min_separation_m=max(2 * ctx.radius_m, 0.01),
            scale_m=1.0,
            background_m=ctx.corners,
            **kw,  # type: ignore[arg-type]
        )
        if len(d.chosen) < n or not np.isfinite(d.score):
            return None
        if ctx.paths_ok(d.chosen) and ctx.size_searches(d.chosen):
            return d
    return None


def _best_fit(
    ctx: _Context,
    target_m: float | None,
    max_points: int,
    add: int,
    fixed: tuple[FloatArray, FloatArray] | None,
    say: SuggestProgress,
) -> tuple[Design | None, list[tuple[int, float]]]:
    history: list[tuple[int, float]] = []
    best: Design | None = None
    sizes = [add] if add else list(range(6, max_points + 1))
    if target_m is None and not add:
        sizes = [max_points]
    start: tuple[int, ...] = ()
    for k, n in enumerate(sizes):
        say("design", k, len(sizes))
        kw: dict[str, object] = {"start": start}
        if fixed is not None:
            kw.update(fixed_rows=fixed[0], fixed_var=fixed[1])
        d = _select_feasible(ctx, n, **kw)
        if d is None:
            continue
        worst = ctx.worst(d.covariance)
        history.append((n + (len(fixed[0]) if fixed is not None else 0), worst))
        best, start = d, d.chosen
        if target_m is not None and worst <= target_m:
            break
    return best, history


def _three_two_one(
    ctx: _Context, say: SuggestProgress
) -> tuple[Design | None, list[tuple[int, float]]]:
    face = ctx.pool.face
    count = {f: int(np.sum(face == f)) for f in set(face.tolist())}
    normals = {f: ctx.pool.normals[np.flatnonzero(face == f)[0]] for f in count}
    best: Design | None = None
    best_worst = math.inf
    triples = [
        t
        for t in itertools.permutations(sorted(count), 3)
        if count[t[0]] >= 3
        and count[t[1]] >= 2
        and all(abs(float(normals[a] @ normals[b])) < 0.5 for a, b in itertools.combinations(t, 2))
    ]
    for k, (p, s, t) in enumerate(triples):
        say("design", k, len(triples))
        d = _select_feasible(ctx, 6, groups=face, quota={p: 3, s: 2, t: 1})
        if d is None:
            continue
        worst = ctx.worst(d.covariance)
        if worst < best_worst:
            best, best_worst = d, worst
    return best, ([(6, best_worst)] if best is not None else [])


def _plan(
    plan: Plan, ctx: _Context, d: Design, procedure: str, add: int, at_m: FloatArray | None
) -> Plan:
    roles = ["fit"] * len(d.chosen)
    if procedure == "three_two_one":  # the face with three points is primary, two secondary
        face = ctx.pool.face
        counts = {
            int(f): sum(int(face[i]) == int(f) for i in d.chosen) for f in face[list(d.chosen)]
        }
        name = {3: "primary", 2: "secondary", 1: "tertiary"}
        chosen = sorted(d.chosen, key=lambda i: -counts[int(face[i])])
        roles = [name[counts[int(face[i])]] for i in chosen]
    else:
        chosen = list(d.chosen)
    taken = {p.id for p in plan.points} if add else set()
    ids: list[str] = []
    k = 1
    while len(ids) < len(chosen):
        if f"S{k}" not in taken:
            ids.append(f"S{k}")
        k += 1
    new = [
        PlanPoint.from_probe_point(ctx.probe(i, pid), role)
        for i, pid, role in zip(chosen, ids, roles, strict=True)
    ]
    points = list(plan.points) + new if add else new
    offset = getattr(plan.procedure, "edge_event_offset_m", None)
    proc = (
        plan.procedure
        if add
        else (
            ThreeTwoOne(edge_event_offset_m=offset)
            if procedure == "three_two_one"
            else BestFit(edge_event_offset_m=offset)
        )
    )
    report: ReportSpec = plan.validation.report
    if at_m is not None:
        pts = [
            PointOfInterest(
                name=r.key.split("_", 1)[1],
                position_m=_vec3(r.points_wobj),
                components=r.components,  # type: ignore[arg-type]
            )
            for r in ctx.rows_poi
        ]
        report = msgspec.structs.replace(report, points_of_interest=pts)
    validation = msgspec.structs.replace(plan.validation, report=report)
    return msgspec.structs.replace(plan, points=points, procedure=proc, validation=validation)


def _vec3(p: FloatArray | None) -> tuple[float, float, float]:
    q = np.asarray(p, dtype=np.float64).reshape(-1, 3)[0]
    return float(q[0]), float(q[1]), float(q[2])


#: Faces named one by one in a refusal (the largest); the rest are counted.
MAX_FACES_NAMED = 8


def _largest(tried: tuple[FaceTried, ...]) -> tuple[list[FaceTried], str]:
    faces = sorted(tried, key=lambda f: -f.area_m2)
    rest = faces[MAX_FACES_NAMED:]
    more = ""
    if rest:
        stopped = sum(f.kept == 0 for f in rest)
        more = (
            f"; and {len(rest)} smaller faces (up to {rest[0].area_m2 * 1e6:.0f} mm^2), "
            f"{stopped} of them too small for the grown footprint"
        )
    return faces[:MAX_FACES_NAMED], more


def _faces_text(tried: tuple[FaceTried, ...], pool: Candidates, ctx: _Context) -> str:
    parts = []
    named, more = _largest(tried)
    for f in named:
        idx = np.flatnonzero(pool.face == f.face_id)
        n = len(idx)
        blocked = [ctx.path_why[int(i)] for i in idx if ctx.path_ok.get(int(i)) is False]
        if n and len(blocked) == n:
            parts.append(f"{f.name}: every search path blocked (e.g. {blocked[0]})")
        elif n:
            parts.append(
                f"{f.name}: {n} feasible poses"
                + (f", {len(blocked)} search paths blocked" if blocked else "")
            )
        elif f.kept == 0:
            parts.append(f"{f.name}: footprint ({f.footprint_reason})")
        else:
            parts.append(f"{f.name}: no feasible pose (reach or collision)")
    return "; ".join(parts) + more


def _nothing_message(tried: tuple[FaceTried, ...], rejected: dict[str, int], n: int) -> str:
    named, more = _largest(tried)
    faces = (
        "; ".join(
            f"{f.name}: {f.kept} of {f.sampled} samples hold the footprint"
            + (f" ({f.footprint_reason})" if f.kept == 0 else "")
            for f in named
        )
        + more
    )
    why = ", ".join(f"{k} {v}" for k, v in sorted(rejected.items())) or "none checked"
    return (
        f"no feasible candidate: {n} candidates on {len(tried)} planar faces, none with a "
        f"feasible probe pose (dropped: {why}). Faces tried: {faces}. The footprint is grown "
        "by the in-plane shift the plan's misplacement allows."
    )


def moved_plan(plan: Plan, from_dir: Path, to_dir: Path) -> Plan:
    """``plan`` with its file references (robot, tool, work object, fixture meshes) made
    relative to ``to_dir`` instead of ``from_dir`` (``builtin:`` references unchanged), so a
    plan written into another folder still finds its files."""
    import os

    from calib.plan.base import BUILTIN_PREFIX

    def ref(r: str | None) -> str | None:
        if not r or r.startswith(BUILTIN_PREFIX) or Path(r).is_absolute():
            return r
        return os.path.relpath((from_dir / r).resolve(), to_dir.resolve())

    rep = msgspec.structs.replace
    c = plan.cell
    cell = rep(
        c,
        robot=rep(c.robot, urdf=ref(c.robot.urdf)),
        tool=rep(c.tool, name=ref(c.tool.name)),
        fixtures=[rep(f, mesh=ref(f.mesh)) for f in c.fixtures],
    )
    return rep(plan, cell=cell, work_object=rep(plan.work_object, mesh=ref(plan.work_object.mesh)))
