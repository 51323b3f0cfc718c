"""The measuring order's batched footprint test (:meth:`Sequencer.fits_many`, remembered
answers, one update per earlier set) gives the answers of the naive one-at-a-time test it
replaced, on a box whose faces are small enough for some footprints to leave them."""

from __future__ import annotations

import copy
from collections.abc import Sequence

import numpy as np
import pytest
import trimesh

from calib.estimators.layout import MIN_SCALE_M
from calib.estimators.steering import (
    ellipse_support,
    inplane_noise_cov,
    inplane_shift_maps,
    shift_outline,
)
from calib.models import Misplacement
from planner.faces.detection import find_planar_faces
from planner.faces.outline import FaceOutlines
from planner.suggest.order import FLOOR_M, NOISE_SIGMAS, SAFETY, Sequencer

RADIUS_M = 0.009


def naive_fits(s: Sequencer, i: int, earlier: Sequence[int], layout: Sequence[int]) -> bool:
    """The test as it was before the batch: every map rebuilt for the one candidate."""
    allp = np.concatenate([s.fixed_m, s.P[list(layout)]])
    c = allp.mean(axis=0)
    L = max(float(np.sqrt(np.mean(np.sum((allp - c) ** 2, axis=1)))), MIN_SCALE_M)
    X = np.concatenate([s.fixed_m, s.P[list(earlier)]])
    Nn = np.concatenate([s.fixed_n, s.N[list(earlier)]])
    if not s.steered:
        X, Nn = X[:0], Nn[:0]
    G_t, G_w = inplane_shift_maps(s.P[i], s.N[i], X, Nn, c, L, c)
    factor = SAFETY if len(X) else 1.0
    cov = inplane_noise_cov(s.P[i], s.N[i], X, Nn, c, L, np.full(len(X), s.var))
    shifts = factor * shift_outline(G_t, G_w, s.a, s.b) + ellipse_support(cov, NOISE_SIGMAS)
    return s.outlines.holds(int(s.face[i]), s.P[i], shifts, FLOOR_M)


def naive_order(s: Sequencer, chosen: Sequence[int]) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """The greedy best-fit order of :meth:`Sequencer.order_progressive`, naively."""
    layout, left, done = list(chosen), list(chosen), []
    while left:
        now = [i for i in left if naive_fits(s, i, done, layout)]
        if not now:
            return tuple(done), tuple(left)
        best = max(
            now, key=lambda i: sum(naive_fits(s, j, [*done, i], layout) for j in left if j != i)
        )
        done.append(best)
        left.remove(best)
    return tuple(done), ()


@pytest.fixture(scope="module")
def box() -> Sequencer:
    mesh = trimesh.creation.box((0.12, 0.08, 0.03))
    faces = find_planar_faces(mesh, footprint_radius_m=RADIUS_M)
    rng = np.random.default_rng(3)
    pts, _ = trimesh.sample.sample_surface(mesh, 160, seed=3)
    pts = np.asarray(pts, dtype=np.float64)
    fid = faces.face_at(pts)
    keep = fid >= 0
    pts, fid = pts[keep], fid[keep]
    normals = np.array([faces.faces[f].normal for f in fid], dtype=np.float64)
    rng.shuffle(order := np.arange(len(pts)))
    return Sequencer(
        FaceOutlines(faces, RADIUS_M),
        pts[order],
        normals[order],
        fid[order].astype(np.int64),
        Misplacement(max_translation_m=0.004, max_angle_rad=np.radians(1.5)),
        (20e-6) ** 2,
    )


def test_batched_answers_are_the_naive_ones(box: Sequencer) -> None:
    rng = np.random.default_rng(0)
    n = len(box.P)
    seen = {True: 0, False: 0}
    for _ in range(30):
        layout = [int(i) for i in rng.choice(n, size=8, replace=False)]
        earlier = layout[: int(rng.integers(0, 6))]
        queries = [(i, earlier) for i in layout] + [(i, earlier[:1]) for i in layout]
        got = box.fits_many(queries, layout)
        want = [naive_fits(box, i, e, layout) for i, e in queries]
        assert got == want
        assert [box.fits(i, e, layout) for i, e in queries] == want  # remembered: the same
        for w in want:
            seen[w] += 1
    assert seen[True] and seen[False]  # the box tests both outcomes


def test_the_order_is_the_naive_one(box: Sequencer) -> None:
    rng = np.random.default_rng(1)
    for _ in range(4):
        chosen = [int(i) for i in rng.choice(len(box.P), size=7, replace=False)]
        got = box.order_progressive(chosen)
        assert (got.order, got.stuck) == naive_order(box, chosen)


def test_a_copy_at_another_bound_does_not_read_stale_answers(box: Sequencer) -> None:
    """``suggest`` judges smaller bounds on shallow copies (``job._scaled``): they share the
    remembered answers, which must be keyed by the bound and the program's kind."""
    layout = list(range(10))
    box.fits_many([(i, layout[:2]) for i in layout], layout)
    for f, steered in ((0.2, True), (3.0, True), (1.0, False)):
        other = copy.copy(box)
        other.a, other.b, other.steered = box.a * f, box.b * f, steered
        for i in layout:
            assert other.fits(i, layout[:2], layout) == naive_fits(other, i, layout[:2], layout)
