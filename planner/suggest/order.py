"""The order a suggested layout is measured in, and its footprints checked for that order.

A search is commanded in the frame estimated from the searches before it
(:mod:`calib.estimators.steering`), so how far it lands from its nominal spot depends on what
was measured first: the first points land anywhere the whole misplacement allows, a point on a
side face measured after three points on the top is off in height only by noise, and so on.
:class:`Sequencer` orders a chosen set so that every point's footprint, grown by the in-plane
shift it will really have (the misplacement the earlier points leave times :data:`SAFETY`,
plus :data:`NOISE_SIGMAS` of what their noise leaves, plus :data:`FLOOR_M`; the whole
misplacement, plus the floor, for a point measured first), stays on its face
(:class:`planner.faces.outline.FaceOutlines`), and names the points that fit in no order.
That holds for an adaptive program; a nominal one (``steered=False``) commands every search in
the nominal frame, so every point is grown by the whole misplacement and the order is free.

Best fit (progressive, one point after another): greedy; of the points that fit now, the one
after which most of the others fit. 3-2-1: the order of the roles (primary, secondary,
tertiary), each group commanded in the estimate of the groups before it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from calib.estimators.layout import MIN_SCALE_M
from calib.estimators.steering import EarlierUpdate, earlier_update, plane_basis
from calib.estimators.steering_many import (
    ellipse_support_many,
    inplane_noise_cov_many,
    inplane_shift_maps_many,
    shift_outline_many,
)
from calib.models import Misplacement
from planner.faces.outline import FaceOutlines

FloatArray = NDArray[np.float64]

#: Factor on the in-plane shift left by earlier points (the first-order model, the noise).
SAFETY = 1.5
#: Added to every shift, metres: second-order terms of the rotation, model error.
FLOOR_M = 0.25e-3
#: Sigmas of the in-plane shift the earlier points' noise leaves (added to the outline).
NOISE_SIGMAS = 4.0
#: Candidates this close to a stuck one, and nearer the face's edges, are set aside with it.
NEIGHBOUR_M = 0.02


@dataclass(frozen=True)
class Ordered:
    """The order of a chosen set.

    Attributes:
        order: the chosen candidates in measuring order (all of them when ``stuck`` is empty).
        stuck: candidates whose footprint leaves its face in every order tried.
    """

    order: tuple[int, ...]
    stuck: tuple[int, ...]


class Sequencer:
    """Orders chosen candidates (indices into ``positions_m``) for the step-by-step procedure.

    Args:
        outlines: the part's face outlines with the sensor footprint.
        positions_m: ``(C, 3)`` candidate points, wobj frame, metres.
        normals: ``(C, 3)`` their faces' unit normals.
        faces: ``(C,)`` their planar face ids.
        misplacement: the plan's misplacement bound.
        var_m2: the event variance of one search, m^2 (sensor and robot repeatability).
        fixed_m: ``(F, 3)`` points measured before any candidate (``--add``), with
            ``fixed_normals`` ``(F, 3)``.
        edge: ``(C,)`` which candidates are edge searches.
        steered: the program commands each search in the frame estimated from the searches
            before it (an adaptive program); ``False``: every search in the nominal frame, so
            every point lands anywhere the whole misplacement allows, whatever the order.
    """

    def __init__(
        self,
        outlines: FaceOutlines,
        positions_m: FloatArray,
        normals: FloatArray,
        faces: NDArray[np.int64],
        misplacement: Misplacement,
        var_m2: float,
        fixed_m: FloatArray | None = None,
        fixed_normals: FloatArray | None = None,
        edge: NDArray[np.bool_] | None = None,
        steered: bool = True,
    ) -> None:
        self.steered = steered
        self.edge = np.zeros(len(positions_m), dtype=bool) if edge is None else edge
        self.outlines = outlines
        self.P = positions_m
        self.N = normals
        self.face = faces
        self.a = float(misplacement.max_translation_m)
        self.b = float(misplacement.max_angle_rad)
        self.var = float(var_m2)
        self.fixed_m = np.zeros((0, 3)) if fixed_m is None else np.reshape(fixed_m, (-1, 3))
        self.fixed_n = (
            np.zeros((0, 3)) if fixed_normals is None else np.reshape(fixed_normals, (-1, 3))
        )
        # remembered answers (shared by shallow copies: keyed by everything they may change)
        self._known: dict[tuple[object, ...], dict[tuple[int, tuple[int, ...]], bool]] = {}
        self._updates: dict[tuple[tuple[int, ...], tuple[int, ...], bool], EarlierUpdate] = {}
        self._bases: dict[int, FloatArray] = {}

    def fits(self, i: int, earlier: Sequence[int], layout: Sequence[int]) -> bool:
        """Candidate ``i``'s footprint stays on its face when measured after the fixed points
        and ``earlier``, in a layout of the fixed points and ``layout`` (its centroid is the
        misplacement's pivot and the update's centre)."""
        return self.fits_many([(i, earlier)], layout)[0]

    def fits_many(
        self, queries: Sequence[tuple[int, Sequence[int]]], layout: Sequence[int]
    ) -> list[bool]:
        """:meth:`fits` of each ``(i, earlier)`` in ``queries``, in one layout.

        Each answer is computed once per sequencer and bound (remembered by candidate, the
        order of ``earlier`` and of ``layout``, the bound and ``steered``); the update of each
        distinct ``earlier`` is computed once and its candidates' shifts stacked
        (:mod:`calib.estimators.steering_many`, the same numbers as one at a time), and every
        footprint of the call is tested in one batch (:meth:`FaceOutlines.holds_many`).
        """
        lay = tuple(int(j) for j in layout)
        keys = [(int(i), tuple(int(j) for j in e)) for i, e in queries]
        known = self._known.setdefault((self.a, self.b, self.var, self.steered, lay), {})
        todo = list(dict.fromkeys(k for k in keys if k not in known))
        if todo:
            groups: dict[tuple[int, ...], list[int]] = {}
            for i, e in todo:
                groups.setdefault(e, []).append(i)
            judged = iter(self._judge(groups, lay))
            for e, cands in groups.items():
                known.update(((i, e), bool(next(judged))) for i in cands)
        return [known[k] for k in keys]

    def _judge(
        self, groups: dict[tuple[int, ...], list[int]], layout: tuple[int, ...]
    ) -> NDArray[np.bool_]:
        """Whether each candidate of ``groups`` (earlier points -> candidates) stays on its
        face, in the groups' order."""
        shifts: list[FloatArray] = []
        for earlier, cands in groups.items():
            u = self._update(earlier, layout)
            idx = np.asarray(cands, dtype=np.int64)
            B = np.stack([self._basis(i) for i in cands])
            G_t, G_w = inplane_shift_maps_many(self.P[idx], B, u)
            factor = SAFETY if u.count else 1.0
            cov = inplane_noise_cov_many(self.P[idx], B, u, np.full(u.count, self.var))
            shifts.append(
                factor * shift_outline_many(G_t, G_w, self.a, self.b)
                + ellipse_support_many(cov, NOISE_SIGMAS)
            )
        idx = np.asarray([i for cands in groups.values() for i in cands], dtype=np.int64)
        return self.outlines.holds_many(
            self.face[idx], self.P[idx], np.concatenate(shifts), FLOOR_M
        )

    def _update(self, earlier: tuple[int, ...], layout: tuple[int, ...]) -> EarlierUpdate:
        """The update after the fixed points and ``earlier`` (none for a nominal program),
        about the centroid of the fixed points and ``layout`` (also the pivot); remembered."""
        key = (earlier, layout, self.steered)
        if key not in self._updates:
            allp = np.concatenate([self.fixed_m, self.P[list(layout)]])
            c = allp.mean(axis=0)
            L = max(float(np.sqrt(np.mean(np.sum((allp - c) ** 2, axis=1)))), MIN_SCALE_M)
            X = np.concatenate([self.fixed_m, self.P[list(earlier)]])
            Nn = np.concatenate([self.fixed_n, self.N[list(earlier)]])
            if not self.steered:  # a nominal program: nothing measured before steers the search
                X, Nn = X[:0], Nn[:0]
            self._updates[key] = earlier_update(X, Nn, c, L, c)
        return self._updates[key]

    def _basis(self, i: int) -> FloatArray:
        """``(3, 2)`` the in-plane basis of candidate ``i``'s normal; remembered."""
        if i not in self._bases:
            self._bases[i] = plane_basis(self.N[i])
        return self._bases[i]

    def alike(self, stuck: Sequence[int], radius_m: float = NEIGHBOUR_M) -> list[int]:
        """Candidates as stuck as ``stuck``: on the same face, within ``radius_m`` of one,
        and no farther from the face's edges and holes (what a design would pick next)."""
        out: list[int] = []
        for i in stuck:
            f = int(self.face[i])
            ci = self.outlines.clearance_m(f, self.P[i])
            near = np.flatnonzero(
                (self.face == f) & (np.linalg.norm(self.P - self.P[i], axis=1) <= radius_m)
            )
            out += [int(j) for j in near if self.outlines.clearance_m(f, self.P[j]) <= ci]
        return out

    def order_progressive(self, chosen: Sequence[int]) -> Ordered:
        """Best fit: one point after another (see the module docstring); edge searches
        last, once the approaches have fixed the height and tilts their tracks run at (their
        tracks are checked on the face with the start the searches are sized for)."""
        edges = [i for i in chosen if self.edge[i]]
        layout = list(chosen)
        left = [i for i in chosen if not self.edge[i]]
        done: list[int] = []
        while left:
            flags = self.fits_many([(i, done) for i in left], layout)
            now = [i for i, ok in zip(left, flags, strict=True) if ok]
            if not now:
                return Ordered(tuple(done + edges), tuple(left))
            best = now[0]
            if len(now) > 1:  # how many of the others fit after each (all in one batch)
                others = [(i, [j for j in left if j != i]) for i in now]
                after = iter(
                    self.fits_many([(j, [*done, i]) for i, js in others for j in js], layout)
                )
                count = {i: sum(next(after) for _ in js) for i, js in others}
                best = max(now, key=count.__getitem__)
            done.append(best)
            left.remove(best)
        return Ordered(tuple(done + edges), ())

    def order_groups(self, groups: Sequence[Sequence[int]]) -> Ordered:
        """3-2-1: groups measured one after the other, each in the estimate of the ones
        before it."""
        layout = [i for g in groups for i in g]
        done: list[int] = []
        stuck: list[int] = []
        for g in groups:
            flags = self.fits_many([(i, done) for i in g], layout)
            stuck += [i for i, ok in zip(g, flags, strict=True) if not ok]
            done += list(g)
        return Ordered(tuple(layout), tuple(stuck))
