"""Gross measurement errors: which measured point does not fit, and which one to re-measure.

A calibration procedure turns any set of measurements into a frame; one point measured 10 mm
off (a burr, a chip, the wrong spot) turns into a frame tilted by degrees, silently. This module
screens the measurements against the noise the plan expects:

1. all measured points are fitted by least squares (:func:`calib.estimators.best_fit.best_fit`,
   started from the nominal frame), whatever the procedure, because only a fit of every point
   spreads a gross error over the residuals where it can be seen (the A-H procedure, for
   instance, puts C, D, F and H exactly on their faces by construction); an edge search's
   point counts as the procedure counts it (``edge_rows``: its edge coordinate only where the
   program commands the track's height, which is no measurement to screen);
2. a point is *flagged* when one of its point-to-face residuals exceeds ``k_sigma * sigma_m``;
3. with redundant points (more constraints than the 6 degrees of freedom), every point is left
   out in turn (leave-one-out): the point whose removal lets all the others fit within the limit
   is the one to re-measure. When no single point does, more than one point is off (or the part
   is not the part of the plan) and the screen says so.

Without redundancy (exactly 6 constraints, a plain 3-2-1) nothing can be screened; the result
says so instead of passing silently.

Before anything is measured, :func:`detectability` says which points' gross errors the screen
cannot see at all, and how many more points would let it see one in every point: a gross error
in a point shows in the residuals only when the other points fix, without it, everything it
fixes (its redundancy number, the diagonal of ``I - J (J^T J)^-1 J^T``, is above zero). In a
plain 3-2-1 no point has one: each fixes something no other point does.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_points, check_positive
from calib.errors import DegenerateGeometryError
from calib.estimators.best_fit import BestFitResult, best_fit
from calib.estimators.layout import ConstraintSet, constraint_set
from calib.estimators.observability import analyze_layout, scaled_jacobian
from calib.probing import ProbePoint

FloatArray = NDArray[np.float64]

#: Default limit on a residual, in units of the expected noise.
K_SIGMA = 5.0


@dataclass(frozen=True)
class LeaveOneOut:
    """The fit of all measured points but one.

    Attributes:
        point_id: the point left out.
        worst_m: largest absolute residual of the remaining points, metres.
        left_out_m: largest absolute distance of the left-out point from its face(s) of that
            fit, metres (how far off it is).
    """

    point_id: str
    worst_m: float
    left_out_m: float


@dataclass(frozen=True)
class GrossErrorScreen:
    """The screen of one set of measurements.

    Attributes:
        sigma_m: expected noise of a measured point along its face normal, metres.
        k_sigma: a residual beyond ``k_sigma * sigma_m`` flags its point.
        redundancy: constraints beyond the 6 degrees of freedom (0: nothing can be screened).
        residuals_m: ``{id: (r1[, r2])}`` least-squares point-to-face residuals, metres.
        flagged: the points with a residual beyond the limit, worst first.
        remeasure: the point(s) whose removal makes all others fit (leave-one-out); one id
            when the screen can name the point, several when any of them explains the misfit,
            none when no single point does (or nothing is flagged).
        leave_one_out: the fit without each point, for the points that could be left out.
        fit: the least-squares fit of all points (``None`` when the points fix no frame).
        note: why the screen could not run, or ``""``.
    """

    sigma_m: float
    k_sigma: float
    redundancy: int
    residuals_m: dict[str, tuple[float, ...]]
    flagged: tuple[str, ...]
    remeasure: tuple[str, ...]
    leave_one_out: tuple[LeaveOneOut, ...] = ()
    fit: BestFitResult | None = field(default=None, repr=False)
    note: str = ""

    @property
    def limit_m(self) -> float:
        """Largest residual accepted, metres."""
        return self.k_sigma * self.sigma_m

    @property
    def ok(self) -> bool:
        """No point is flagged."""
        return not self.flagged

    def worst_m(self, point_id: str) -> float:
        """Largest absolute residual of ``point_id``, metres (0 when not screened)."""
        return max((abs(r) for r in self.residuals_m.get(point_id, ())), default=0.0)

    def messages(self) -> list[str]:
        """What is wrong, in words, with the numbers (empty when nothing is flagged)."""
        if not self.flagged:
            return []
        mm = self.limit_m * 1e3
        worst = ", ".join(f"{p} {self.worst_m(p) * 1e3:.3f} mm" for p in self.flagged)
        out = [
            f"measured points off their faces beyond {self.k_sigma:g} sigma "
            f"({mm:.3f} mm; expected noise {self.sigma_m * 1e3:.3f} mm): {worst}"
        ]
        if len(self.remeasure) == 1:
            pid = self.remeasure[0]
            loo = next(x for x in self.leave_one_out if x.point_id == pid)
            out.append(
                f"re-measure {pid}: without it every other point fits within "
                f"{loo.worst_m * 1e3:.3f} mm, and {pid} lies {loo.left_out_m * 1e3:.3f} mm "
                "off its face (leave-one-out)"
            )
        elif self.remeasure:
            out.append(
                f"re-measure one of {', '.join(self.remeasure)}: leaving out any one of them "
                "makes the others fit (leave-one-out cannot tell which)"
            )
        elif not self.leave_one_out:
            out.append(
                f"only {self.redundancy} redundant constraint(s): the misfit shows, but no point "
                "can be left out to find which one is off; re-measure them all"
            )
        else:
            out.append(
                "no single point explains the misfit: more than one point is off, or the part "
                "is not shaped or placed as the plan says; re-measure them all"
            )
        return out


def screen_measurements(
    points: Sequence[ProbePoint],
    measured_base: ArrayLike,
    T_base_wobj_nominal: ArrayLike,
    sigma_m: float,
    k_sigma: float = K_SIGMA,
    edge_rows: Literal["both", "edge"] = "both",
) -> GrossErrorScreen:
    """Screen measured points for gross errors (see the module docstring).

    Args:
        points: the nominal probe points that were measured, wobj frame.
        measured_base: ``(N, 3)`` their measurements in the same order, base frame, metres
            (known sensor offsets already removed, e.g. an edge search's event offset).
        T_base_wobj_nominal: ``(4, 4)`` the nominal frame the fits start from.
        sigma_m: expected noise of one measured point along its face normal, metres (> 0).
        k_sigma: a residual beyond ``k_sigma * sigma_m`` flags its point.
        edge_rows: what an edge search's point counts for, as in the procedure's fit
            (:attr:`calib.procedures.base.ProcedureKind.edge_rows`): ``"edge"``, only its edge
            coordinate (a coordinate the program commanded is no measurement to screen).

    Raises:
        ShapeError, NonFiniteError: malformed measurements (the argument is named).
    """
    sigma = check_positive(sigma_m, "sigma_m")
    k = check_positive(k_sigma, "k_sigma")
    pts = tuple(points)
    q = check_points(measured_base, "measured_base")
    cs = constraint_set(pts, "measured points", edge_rows=edge_rows)
    redundancy = cs.n_constraints - 6
    report = analyze_layout(cs)
    if not report.observable:
        note = "the measured points do not fix all 6 degrees of freedom: " + "; ".join(
            report.messages
        )
        return GrossErrorScreen(sigma, k, redundancy, {}, (), (), note=note)
    fit = best_fit(cs, q, T_base_wobj_nominal, sigma_m=sigma)
    residuals = _by_point(fit)
    limit = k * sigma
    worst = {pid: max(abs(r) for r in rs) for pid, rs in residuals.items()}
    flagged = tuple(sorted((p for p, w in worst.items() if w > limit), key=lambda p: -worst[p]))
    if redundancy <= 0:
        note = (
            f"{cs.n_constraints} constraints for 6 degrees of freedom: no redundancy, so a "
            "gross error in one point cannot be seen in the residuals"
        )
        return GrossErrorScreen(sigma, k, redundancy, residuals, (), (), (), fit, note)
    loo = _leave_one_out(pts, q, T_base_wobj_nominal, sigma, edge_rows) if flagged else ()
    remeasure = tuple(x.point_id for x in loo if x.worst_m <= limit and x.left_out_m > limit)
    return GrossErrorScreen(sigma, k, redundancy, residuals, flagged, remeasure, loo, fit)


#: A point whose redundancy number (the share of its gross error that shows in its own
#: residual) is below this cannot be seen: the other points fit it exactly.
SEEN_TOL = 1e-6
#: :func:`detectability` counts at most this many points to add.
MAX_ADDED = 12
#: Two constraints lie on one face when their normals are this close (cosine) ...
_SAME_NORMAL_COS = math.cos(math.radians(1.0))
#: ... and their points this close to one plane, metres.
_SAME_PLANE_M = 5e-4


@dataclass(frozen=True)
class Detectability:
    """Which gross errors a point layout lets the screen see, before anything is measured.

    Attributes:
        n_constraints: face constraints of the points (an edge point has two).
        redundancy: constraints beyond the 6 degrees of freedom.
        unseen: the points whose gross error cannot show in the residuals, in the order given:
            nothing else fixes what each of them fixes, so the fit absorbs its error whole.
        edge_only: of those, the edge points whose error is unseen only along their edge
            (the position the search finds the face's end at).
        add: how many more points would let a gross error in every point show (0 when none is
            unseen, ``None`` when more than :data:`MAX_ADDED` or the layout fixes no frame).
        faces: for each point to add, the face it was counted on, named by a point on it
            (``"F's face"``, or ``"F's edge face"``: the face whose end an edge point finds).
        fixed: why no point can be added to this plan without giving up part of its procedure
            (e.g. the A-H procedure's x-offset run, which a best fit has not), or ``""``.
    """

    n_constraints: int
    redundancy: int
    unseen: tuple[str, ...]
    add: int | None
    faces: tuple[str, ...] = ()
    edge_only: tuple[str, ...] = ()
    fixed: str = ""

    @property
    def ok(self) -> bool:
        """A gross error in any one point shows in the residuals."""
        return not self.unseen

    def message(self, plan: str = "PLAN", how: str = "") -> str:
        """What the user should know, in one line (``""`` when every point is seen).

        Args:
            plan: the plan file's name for the ``wobjcal suggest`` command shown.
            how: how to add the points, instead of that command (e.g. a button of the UI).
        """
        if not self.unseen:
            return ""
        if self.redundancy <= 0:
            head = (
                f"{self.n_constraints} constraints for 6 degrees of freedom: no redundancy, so "
                "a gross error in any point (a burr, a chip, the wrong spot) cannot be detected: "
                "the frame fits it exactly"
            )
        else:
            which = ", ".join(
                p + (" (its edge)" if p in self.edge_only else "") for p in self.unseen
            )
            head = (
                f"a gross error in {which} cannot be detected: no other point fixes what it "
                f"fixes ({self.redundancy} redundant constraint(s) elsewhere), so the frame fits "
                "it exactly"
            )
        if self.fixed:
            return f"{head}; {self.fixed}"
        if not self.add:
            return head + "; measure more points on the faces of those points"
        counts: dict[str, int] = {}
        for f in self.faces:
            counts[f] = counts.get(f, 0) + 1
        where = ", ".join(f"{f} ({n})" if n > 1 else f for f, n in counts.items())
        each = "one on each of" if len(counts) > 1 else "on"
        how = how or f"`wobjcal suggest {plan} --add {self.add} -o OUT`"
        return f"{head}; add {self.add} point(s) to make it detectable, e.g. {each} {where} ({how})"


def detectability(
    points: Sequence[ProbePoint], edge_rows: Literal["both", "edge"] = "both"
) -> Detectability:
    """Which points' gross errors the screen can see, and how many points to add for all.

    A gross error in point ``i`` shows in the least-squares residuals by its redundancy number
    (the block of ``I - J (J^T J)^-1 J^T`` on its rows; ``J`` the constraint Jacobian of
    :func:`screen_measurements`' fit); zero means the other points do not fix what it fixes.
    Points to add are counted greedily: each is a point at a generic place among the points of
    an unseen point's face (inside their hull, where the sensor already fits; on a face of one
    point, a point beside it), on the face that leaves the fewest unseen. Pure
    geometry: where the points really go is :mod:`planner.suggest`'s.

    ``edge_rows``: what an edge search's point counts for (:func:`screen_measurements`).

    Raises:
        ShapeError, DegenerateGeometryError: bad points (see
            :func:`calib.estimators.layout.constraint_set`).
    """
    cs = constraint_set(tuple(points), "points", edge_rows=edge_rows)
    n = cs.n_constraints
    if not analyze_layout(cs).observable:
        return Detectability(n, n - 6, (), None)
    J = scaled_jacobian(cs)
    owner = [int(i) for i in cs.point_index]
    ids = cs.point_ids
    unseen, edge_only = _unseen(J, owner)
    row_face, new_rows, names = _faces(cs)
    added: list[str] = []
    left = unseen
    while left and len(added) < MAX_ADDED:
        candidates = dict.fromkeys(row_face[k] for k, o in enumerate(owner) if o in left)
        best: tuple[int, list[int]] | None = None
        for f in candidates:
            trial, _ = _unseen(np.vstack([J, new_rows[f]]), [*owner, -1 - len(added)])
            if best is None or len(trial) < len(best[1]):
                best = (f, trial)
        if best is None or len(best[1]) >= len(left):
            break
        f, left = best
        J = np.vstack([J, new_rows[f]])
        owner.append(-1 - len(added))
        row_face.append(f)
        added.append(names[f])
    return Detectability(
        n,
        n - 6,
        tuple(ids[i] for i in unseen),
        None if left else len(added),
        () if left else tuple(added),
        tuple(ids[i] for i in edge_only),
    )


def _unseen(J: FloatArray, owner: Sequence[int]) -> tuple[list[int], list[int]]:
    """The owners (point indices; added points negative) of rows whose gross error the
    least-squares fit of ``J`` can absorb whole, in order of first row; and those of them
    with two rows (an edge point) where that error lies along the second (the edge)."""
    R = np.eye(len(J)) - J @ np.linalg.solve(J.T @ J, J.T)
    out: list[int] = []
    edge: list[int] = []
    for i in dict.fromkeys(owner):
        rows = [k for k, o in enumerate(owner) if o == i]
        w, v = np.linalg.eigh(R[np.ix_(rows, rows)])
        if float(w[0]) < SEEN_TOL:
            out.append(i)
            if len(rows) == 2 and abs(float(v[1, 0])) > 0.99:
                edge.append(i)
    return out, edge


def _faces(cs: ConstraintSet) -> tuple[list[int], list[FloatArray], list[str]]:
    """The faces of the constraint rows: ``(face of each row, the scaled Jacobian row of a
    point at a generic place among each face's points, each face named by its first point)``."""
    row_face: list[int] = []
    planes: list[tuple[FloatArray, FloatArray]] = []  # (normal, a point on it)
    members: list[list[FloatArray]] = []
    names: list[str] = []
    for k, (nk, pk) in enumerate(zip(cs.normals, cs.nominal_m, strict=True)):
        for f, (nf, pf) in enumerate(planes):
            if float(nf @ nk) > _SAME_NORMAL_COS and abs(float(nf @ (pk - pf))) < _SAME_PLANE_M:
                row_face.append(f)
                members[f].append(pk)
                break
        else:
            row_face.append(len(planes))
            planes.append((nk, pk))
            members.append([pk])
            i = int(cs.point_index[k])
            second = k > 0 and int(cs.point_index[k - 1]) == i  # an edge point's edge face
            names.append(cs.point_ids[i] + ("'s edge face" if second else "'s face"))
    rows = []
    for (nf, _), pts in zip(planes, members, strict=True):
        # a generic place among the face's points (inside their hull: where the sensor already
        # fits); on a face of one point, a point beside it: to first order the same constraint
        w = 1.0 / (np.arange(len(pts)) + 1.618)
        p = (w / w.sum()) @ np.asarray(pts)
        lever = np.cross(p - cs.centroid_m, nf) / cs.scale_m
        rows.append(np.concatenate([nf, lever])[None, :])
    return row_face, rows, names


def _by_point(fit: BestFitResult) -> dict[str, tuple[float, ...]]:
    out: dict[str, list[float]] = {pid: [] for pid in fit.point_ids}
    for pid, r in zip(fit.residual_ids, fit.residuals_m.tolist(), strict=True):
        out[pid].append(float(r))
    return {pid: tuple(rs) for pid, rs in out.items()}


def _leave_one_out(
    points: tuple[ProbePoint, ...],
    q: FloatArray,
    T_nominal: ArrayLike,
    sigma: float,
    edge_rows: Literal["both", "edge"] = "both",
) -> tuple[LeaveOneOut, ...]:
    """The fit without each point that leaves a redundant, observable layout."""
    out = []
    for j, left in enumerate(points):
        keep = [i for i in range(len(points)) if i != j]
        sub = constraint_set([points[i] for i in keep], "measured points", edge_rows=edge_rows)
        if sub.n_constraints - 6 < 1 or not analyze_layout(sub).observable:
            continue
        try:
            fit = best_fit(sub, q[keep], T_nominal, sigma_m=sigma)
        except DegenerateGeometryError:
            continue
        T_wobj_base = np.linalg.inv(fit.T_base_wobj)
        x = T_wobj_base[:3, :3] @ q[j] + T_wobj_base[:3, 3] - np.asarray(left.position_m)
        off = float(np.max(np.abs(left.constraint_normals @ x)))
        out.append(LeaveOneOut(left.id, float(np.max(np.abs(fit.residuals_m))), off))
    return tuple(out)


__all__ = [
    "K_SIGMA",
    "Detectability",
    "GrossErrorScreen",
    "LeaveOneOut",
    "detectability",
    "screen_measurements",
]
