"""The steps of :func:`planner.suggest.suggest_plan`: feasibility of the candidates in the
cell, the designs (a grown one, e.g. the best fit, growing to the target; a face one, e.g. the
3-2-1, over every ordered set of faces: the procedure's
:class:`~calib.procedures.base.LayoutDesign` says which), the suggested plan, and the refusals'
words.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import msgspec
import numpy as np
from numpy.typing import NDArray

from calib.estimators.design import Design, poi_jacobians, select
from calib.estimators.layout import (
    constraint_jacobian,
    point_motion_jacobian,
    search_constraint_set,
)
from calib.plan.file import Plan, PlanPoint
from calib.plan.report_spec import PointOfInterest, ReportSpec
from calib.probing import ProbePoint, SearchSpec
from calib.procedures import ProcedureKind
from planner.faces.candidates import Candidates, FaceTried
from planner.plan_cell import nominal_T_base_wobj
from planner.program.safety import SafetySpec
from planner.reasons import Reason
from planner.sim.rows import RowSpec, predicted_sigma
from planner.suggest.order import Ordered, Sequencer
from planner.suggest.search_sizing import MIN_OVERTRAVEL_M, MIN_START_M

if TYPE_CHECKING:
    from planner.cell.cell import Cell

FloatArray = NDArray[np.float64]
#: progress(stage, done, total)
SuggestProgress = Callable[[str, int, int], None]
#: Samples tried first on each face (a face whose samples all fail is dropped).
PROBE_FIRST = 6
#: Edge searches run this far inside the face along the sensor axis (as the simulation), m.
EDGE_INSET_M = 0.003


#: What :func:`feasible_poses` counts a dropped candidate under, by the kind of its pose's
#: reason (:class:`planner.reasons.Reason`); any other: ``"other"``.
REJECTED_AS: dict[str, str] = {
    "reach": "reach",
    "joint_limit": "joint limits",
    "singularity": "singularity",
    "collision": "collision",
}


def _why(cause: Reason | None) -> str:
    return "other" if cause is None else REJECTED_AS.get(cause.kind, "other")


@dataclass
class Context:
    cell: Cell
    plan: Plan
    pool: Candidates
    safety: SafetySpec
    rows_poi: list[RowSpec]
    z: float
    radius_m: float
    corners: FloatArray | None = None
    sequencer: Sequencer | None = None
    fixed_points: tuple[ProbePoint, ...] = ()
    path_ok: dict[int, bool] = field(default_factory=dict)
    path_why: dict[int, str] = field(default_factory=dict)
    #: candidates a design picked whose footprint left their face in every order tried
    off_face: set[int] = field(default_factory=set)
    #: edge searches: start inside the edge and travel past it, metres
    edge_start_m: float = 0.0
    edge_overtravel_m: float = 0.0
    #: why no edge search is among the candidates, when they were looked for ("; edge ...")
    edge_note: str = ""
    #: check the search paths of newly chosen candidates in the cell; ``False``: only the
    #: verdicts already cached count (what-if designs, e.g. at a smaller misplacement bound)
    check_paths: bool = True

    @property
    def poi(self) -> list[FloatArray]:
        """The design's points of interest; with edge candidates, also the height of each
        edge track scaled by the sensor's edge gain (an edge search is commanded at the
        height the approaches before it estimate, and its event moves by the gain times that
        height's error), so the approaches are spread to fix the height along every edge."""
        pts = np.concatenate([r.points_wobj for r in self.rows_poi if r.points_wobj is not None])
        out = poi_jacobians(pts, [r.components for r in self.rows_poi])
        edge = np.flatnonzero(self.pool.is_edge)
        if len(edge):
            sensor = self.plan.validation.sensor
            k = abs(sensor.search_noise("edge", EDGE_INSET_M).axis_gain)
            J = point_motion_jacobian(self.pool.positions_m[edge])  # (E, 3, 6)
            h = np.einsum("ek,ekj->ej", self.pool.normals[edge], J)
            rows = out[0].shape[0]  # the design stacks them: zero rows pad to the same shape
            out += [np.vstack([k * row, np.zeros((rows - 1, 6))]) for row in h]
        return out

    def rows(self) -> tuple[FloatArray, FloatArray]:
        """The design's rows: an approach constrains its face, an edge search only its edge
        coordinate (its edge direction, the square edge's other face normal)."""
        edge = self.pool.is_edge
        normals = self.pool.normals.copy()
        if edge.any():
            assert self.pool.edge_dirs is not None
            normals[edge] = self.pool.edge_dirs[edge]
        A = constraint_jacobian(normals, self.pool.positions_m)
        sensor = self.plan.validation.sensor
        rep2 = self.plan.validation.robot_error.repeatability_sigma_m**2
        var = np.full(len(A), sensor.search_noise("approach", 0.003).sensor_sigma_m ** 2 + rep2)
        if edge.any():
            var[edge] = sensor.search_noise("edge", EDGE_INSET_M).sensor_sigma_m ** 2 + rep2
        return A, var

    def probe(self, i: int, pid: str) -> ProbePoint:
        p = self.pool.positions_m[i]
        if self.pool.is_edge[i]:
            assert self.pool.edge_dirs is not None
            d = tuple(float(c) for c in self.pool.edge_dirs[i])
            edge = SearchSpec(
                "edge",
                start_offset_m=self.edge_start_m,
                overtravel_m=self.edge_overtravel_m,
                edge_direction=d,  # type: ignore[arg-type]
            )
            return ProbePoint(
                pid,
                tuple(float(c) for c in p),  # type: ignore[arg-type]
                tuple(float(c) for c in self.pool.normals[i]),  # type: ignore[arg-type]
                edge,
                edge_normal=d,  # type: ignore[arg-type]
            )
        search = SearchSpec(
            "approach",
            start_offset_m=max(MIN_START_M, self.safety.start_clearance_m(p)),
            overtravel_m=max(MIN_OVERTRAVEL_M, self.safety.overtravel_m(p)),
        )
        return ProbePoint(pid, tuple(float(c) for c in p), tuple(self.pool.normals[i]), search)  # type: ignore[arg-type]

    def size_searches(self, chosen: tuple[int, ...]) -> bool:
        """Size the searches for the misplacement about the centroid of the written plan's
        points (the plan's kept points with ``--add``, and the chosen ones: the pivot of the
        program's safe starts and of the validation); re-check the paths whose start moved.
        False: one is blocked."""
        kept = np.array([p.position_m for p in self.fixed_points], dtype=np.float64)
        every = np.concatenate([kept.reshape(-1, 3), self.pool.positions_m[list(chosen)]])
        c = every.mean(axis=0)
        pivot = (float(c[0]), float(c[1]), float(c[2]))
        if pivot == self.safety.pivot_wobj_m:
            return True
        old = {i: self.probe(i, "c").search for i in chosen}
        self.safety = dataclasses.replace(self.safety, pivot_wobj_m=pivot)
        for i in chosen:
            if self.probe(i, "c").search != old[i]:
                self.path_ok.pop(i, None)
        return self.paths_ok(chosen)

    def sequence(self, chosen: tuple[int, ...], quota: dict[int, int] | None) -> Ordered:
        """The measuring order of ``chosen`` (a face design: by face, in ``quota``'s order,
        the roles' measuring order) and the candidates whose footprint leaves their face in
        it."""
        if self.sequencer is None:
            return Ordered(chosen, ())
        if quota is None:
            return self.sequencer.order_progressive(chosen)
        face = self.pool.face
        groups = [[i for i in chosen if int(face[i]) == f] for f in quota]
        return self.sequencer.order_groups(groups)

    def weak(self, chosen: tuple[int, ...]) -> bool:
        """The layout (with the plan's points when adding) is rated weak by the check
        (noise gain above :data:`calib.estimators.observability.WEAK_NOISE_GAIN`)."""
        from calib.estimators.observability import WEAK_NOISE_GAIN, analyze_layout

        pts = [self.probe(i, f"c{i}") for i in chosen]
        if self.fixed_points:
            pts = list(self.fixed_points) + pts
        gain = analyze_layout(search_constraint_set(pts)).noise_gain
        return not gain <= WEAK_NOISE_GAIN

    def worst(self, cov: FloatArray) -> float:
        if not np.all(np.isfinite(cov)):
            return math.inf
        return max(self.z * predicted_sigma(r, cov) for r in self.rows_poi)

    def paths_ok(self, chosen: tuple[int, ...]) -> bool:
        """Check the search paths of the chosen candidates not yet checked."""
        from planner.check.paths import check_program_path

        if not self.check_paths:
            return all(self.path_ok.get(i, True) for i in chosen)
        T = nominal_T_base_wobj(self.plan)
        tcp = self.plan.cell.tool.tcp
        T_ft = self.cell.T_flange_tcp(tcp)
        for i in chosen:
            if i in self.path_ok:
                continue
            pose = self.cell.check_probes(
                self.pool.positions_m[i : i + 1], self.pool.normals[i : i + 1], tcp=tcp
            )[0]
            # the program's searches, as ``wobjcal check`` walks them
            path = check_program_path(
                self.cell, self.probe(i, "c"), pose, T, self.safety, T_ft, tcp
            )
            self.path_ok[i] = bool(pose.feasible and path.feasible)
            self.path_why[i] = str(path.reason or pose.reason)
        return all(self.path_ok[i] for i in chosen)


def feasible_poses(
    cell: Cell, plan: Plan, cands: Candidates, say: SuggestProgress
) -> tuple[NDArray[np.bool_], dict[str, int]]:
    """Feasible probe poses: a few spread samples per face first, the rest of the faces
    where any of those passed."""
    ok = np.zeros(len(cands), dtype=bool)
    rejected: dict[str, int] = {}
    if len(cands) == 0:  # e.g. no edge track that keeps the footprint on its face
        return ok, rejected
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
                key = _why(x.cause)
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


def fixed_rows(plan: Plan) -> tuple[FloatArray, FloatArray]:
    cs = search_constraint_set([p.to_probe_point() for p in plan.points])
    A = constraint_jacobian(cs.normals, cs.nominal_m)
    s = plan.validation.sensor.search_noise("approach", 0.003).sensor_sigma_m
    var = s**2 + plan.validation.robot_error.repeatability_sigma_m**2
    return A, np.full(len(A), var)


def _design(
    ctx: Context, A: FloatArray, var: FloatArray, n: int, available: NDArray[np.bool_], **kw: object
) -> Design:
    """:func:`calib.estimators.design.select` of ``n`` of the ``available`` candidates (rows
    ``A``, variances ``var``) for the context's points of interest, footprint spacing and part
    corners; ``kw`` are more of its arguments (quota, start, fixed rows, ``follows``)."""
    return select(
        A,
        var,
        n,
        ctx.poi,
        positions_m=ctx.pool.positions_m,
        available=available,
        min_separation_m=max(2 * ctx.radius_m, 0.01),
        scale_m=1.0,
        background_m=ctx.corners,
        **kw,  # type: ignore[arg-type]
    )


def _select_feasible(ctx: Context, n: int, **kw: object) -> Design | None:
    """The design of ``n`` points whose search paths are all feasible (blocked ones dropped)."""
    A, var = ctx.rows()
    stuck: set[int] = set()
    for _ in range(50):
        blocked = np.array([ctx.path_ok.get(i, True) is False or i in stuck for i in range(len(A))])
        if kw.get("quota") is not None:  # a face design takes approach searches only
            blocked |= ctx.pool.is_edge
        d = _design(ctx, A, var, n, ~blocked, **kw)
        if len(d.chosen) < n or not np.isfinite(d.score):
            return None
        ordered = ctx.sequence(d.chosen, kw.get("quota"))  # type: ignore[arg-type]
        if ordered.stuck:
            assert ctx.sequencer is not None  # stuck points come from it
            stuck.update(ordered.stuck)
            stuck.update(ctx.sequencer.alike(ordered.stuck))
            ctx.off_face.update(ordered.stuck)
            continue
        d = dataclasses.replace(d, chosen=ordered.order)
        if ctx.paths_ok(d.chosen) and ctx.size_searches(d.chosen):
            return d
    return None


def _select_in_order(ctx: Context, n: int, **kw: object) -> Design | None:
    """The design of ``n`` points grown in measuring order: each point the one that helps
    most among the candidates whose footprint stays on its face after the points before it
    (:meth:`Sequencer.fits_many`), so a measuring order exists by construction.

    The fallback of a best fit whose designs get stuck (:func:`_select_feasible`): a design
    chosen for its information alone may hold no point that can be measured first (each is
    grown by the whole misplacement), and banning its points then bans the faces' only
    candidates. The footprints are tested in the layout of the previous try (first: the
    design without the order); the result is ordered again in its own layout
    (:meth:`Context.sequence`), and its search paths checked, before it is returned.
    """
    seq = ctx.sequencer
    if seq is None:
        return None
    A, var = ctx.rows()
    edge = ctx.pool.is_edge
    approach = np.flatnonzero(~edge)
    blocked = np.array([ctx.path_ok.get(i, True) is False for i in range(len(A))])
    layout: list[int] = []

    def follows(chosen: Sequence[int]) -> NDArray[np.bool_]:
        earlier = [int(i) for i in chosen if not edge[i]]  # edge searches run last
        ok = np.ones(len(A), dtype=bool)
        ok[approach] = seq.fits_many([(int(i), earlier) for i in approach], layout)
        return ok

    def design(in_order: bool) -> Design:
        return _design(ctx, A, var, n, ~blocked, follows=follows if in_order else None, **kw)

    layout[:] = design(in_order=False).chosen
    for _ in range(10):
        d = design(in_order=True)
        if len(d.chosen) < n or not np.isfinite(d.score):
            return None
        ordered = ctx.sequence(d.chosen, None)
        if ordered.stuck and sorted(d.chosen) == sorted(layout):
            # the layout it was grown in: the order it was grown in holds there (the
            # sequencer's greedy order may miss it, a point after one other being grown more
            # than a first point), with the edge searches last as the program runs them
            grown = [i for i in d.chosen if not edge[i]] + [i for i in d.chosen if edge[i]]
            if not all(follows(grown[:k])[i] for k, i in enumerate(grown)):
                return None
            ordered = dataclasses.replace(ordered, order=tuple(grown), stuck=())
        if ordered.stuck:  # its own layout moved the pivot: grow it again in that layout
            layout[:] = d.chosen
            continue
        d = dataclasses.replace(d, chosen=ordered.order)
        if ctx.paths_ok(d.chosen) and ctx.size_searches(d.chosen):
            return d
        blocked |= np.array([ctx.path_ok.get(i, True) is False for i in range(len(A))])
    return None


def best_fit_design(
    ctx: Context,
    target_m: float | None,
    max_points: int,
    add: int,
    fixed: tuple[FloatArray, FloatArray] | None,
    say: SuggestProgress,
    collect: list[tuple[int, Design]] | None = None,
) -> tuple[Design | None, list[tuple[int, float]]]:
    """The best-fit design: grown from 6 points (or ``add`` more) until the target holds, or up
    to ``max_points`` (without a target, every size up to it is designed on the way; each
    size's design, in its landing order, is appended to ``collect`` when given).

    Each size keeps the best (smallest worst half-width) of three designs: one from scratch,
    the smaller size's design grown by one point and exchanged, and that design grown by the
    one best point without exchange. Adding a search only adds information, so the last never
    predicts a larger error than the smaller design: the error never grows with the number of
    points (designed from scratch, 11 points once predicted 0.114 mm against 0.099 mm at 10).
    """
    history: list[tuple[int, float]] = []
    best: Design | None = None
    sizes = [add] if add else list(range(6, max_points + 1))
    extra: dict[str, object] = {}
    if fixed is not None:
        extra.update(fixed_rows=fixed[0], fixed_var=fixed[1])
    for k, n in enumerate(sizes):
        say("design", k, len(sizes))
        tries = [_select_feasible(ctx, n, **extra)]
        if best is not None:
            tries.append(_select_feasible(ctx, n, start=best.chosen, **extra))
            tries.append(_select_feasible(ctx, n, start=best.chosen, max_passes=0, **extra))
        if all(d is None for d in tries):  # every design got stuck: grow one in order
            tries.append(_select_in_order(ctx, n, **extra))
        found = [(ctx.worst(d.covariance), i, d) for i, d in enumerate(tries) if d is not None]
        # the searches are sized about the chosen points' centroid: size them for the one kept
        kept = next(
            (
                f
                for f in sorted(found, key=lambda f: (f[0], f[1]))
                if ctx.size_searches(f[2].chosen)
            ),
            None,
        )
        if kept is None:
            continue
        worst, _, d = kept
        history.append((n + (len(fixed[0]) if fixed is not None else 0), worst))
        best = d
        if collect is not None:
            collect.append((n, d))
        if target_m is not None and worst <= target_m and not ctx.weak(d.chosen):
            break  # a layout the check would call weak grows on
    return best, history


def face_design(
    ctx: Context, face_roles: tuple[tuple[str, int], ...], say: SuggestProgress
) -> tuple[Design | None, list[tuple[int, float]]]:
    """A face design (:attr:`calib.procedures.base.LayoutDesign.face_roles`; the 3-2-1's
    3, 2, 1): the best over every ordered set of planar faces, pairwise far from parallel, that
    hold enough candidates, each face given its role's number of points."""
    face = ctx.pool.face
    count = {f: int(np.sum(face == f)) for f in set(face.tolist())}
    normals = {f: ctx.pool.normals[np.flatnonzero(face == f)[0]] for f in count}
    need = [n for _, n in face_roles]
    best: Design | None = None
    best_worst = math.inf
    sets = [
        t
        for t in itertools.permutations(sorted(count), len(need))
        if all(count[f] >= n for f, n in zip(t, need, strict=True))
        and all(abs(float(normals[a] @ normals[b])) < 0.5 for a, b in itertools.combinations(t, 2))
    ]
    for k, faces in enumerate(sets):
        say("design", k, len(sets))
        quota = dict(zip(faces, need, strict=True))
        d = _select_feasible(ctx, sum(need), groups=face, quota=quota)
        if d is None:
            continue
        worst = ctx.worst(d.covariance)
        if worst < best_worst:
            best, best_worst = d, worst
    return best, ([(sum(need), best_worst)] if best is not None else [])


def suggested_plan(
    plan: Plan,
    ctx: Context,
    d: Design,
    procedure: ProcedureKind,
    add: int,
    at_m: FloatArray | None,
) -> Plan:
    """The plan of design ``d`` for ``procedure`` (its points with the roles of its layout
    design; with ``add``, the plan's points and procedure kept, the new points added)."""
    design = procedure.design
    assert design is not None  # suggest designs only procedures with a layout design
    face = ctx.pool.face
    on_face = {int(f): sum(int(face[i]) == int(f) for i in d.chosen) for f in face[list(d.chosen)]}
    chosen = list(d.chosen)
    if not design.grows:  # the roles in their measuring order, each face's points together
        rank = {n: k for k, (_, n) in enumerate(design.face_roles)}
        chosen.sort(key=lambda i: rank[on_face[int(face[i])]])
    roles = design.roles_of([on_face[int(face[i])] for i in chosen])
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
    proc = plan.procedure if add else procedure.settings_type(edge_event_offset_m=offset)
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
    return msgspec.structs.replace(  # searches sized whole: steered_plan sizes them after
        plan,
        points=points,
        procedure=proc,
        validation=validation,
        search_sizing=msgspec.UNSET,
    )


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


def faces_text(tried: tuple[FaceTried, ...], pool: Candidates, ctx: Context) -> str:
    parts = []
    named, more = _largest(tried)
    for f in named:
        idx = np.flatnonzero(pool.face == f.face_id)
        n = len(idx)
        blocked = [ctx.path_why[int(i)] for i in idx if ctx.path_ok.get(int(i)) is False]
        off = sum(int(i) in ctx.off_face for i in idx)
        aside = (
            f", {off} set aside (footprint off the face in every measuring order)" if off else ""
        )
        if n and len(blocked) == n:
            parts.append(f"{f.name}: every search path blocked (e.g. {blocked[0]})")
        elif n:
            parts.append(
                f"{f.name}: {n} feasible poses"
                + (f", {len(blocked)} search paths blocked" if blocked else "")
                + aside
            )
        elif f.kept == 0:
            parts.append(f"{f.name}: footprint ({f.footprint_reason})")
        else:
            parts.append(f"{f.name}: no feasible pose (reach or collision)")
    return "; ".join(parts) + more


def nothing_message(tried: tuple[FaceTried, ...], rejected: dict[str, int], n: int) -> str:
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
        f"feasible probe pose (dropped: {why}). Faces tried: {faces}."
    )
