"""Choosing probe points: a design that minimises the predicted error at points of interest.

Each candidate search ``c`` measures one face constraint: the row ``a_c (6,)`` of
:func:`calib.estimators.layout.constraint_jacobian` (the point-to-plane residual's derivative
with respect to a small frame motion) with event variance ``var_c``. A set ``S`` of searches
fitted by least squares has the information matrix ``M = sum a_c a_c^T / var_c`` and the frame
covariance ``Sigma = M^-1`` (what :func:`calib.procedures.linearize.linearize` gives for the
best fit of approach searches, and for any procedure that uses exactly six constraints).

The criterion is not ``det M`` (D-optimality, Xiong, Wang & Li 2004) but the error where the
robot works (Jost et al. 2017): ``f(S) = max_p trace(P_p J_p Sigma J_p^T P_p)``, the largest
mean squared error over the points of interest ``p`` (``J_p`` of
:func:`calib.estimators.layout.point_motion_jacobian`, ``P_p`` the components that count).

:func:`select` builds the set greedily (each step adds the candidate that lowers ``f`` most,
by a rank-one update of ``Sigma`` for all candidates at once) from a weak prior, then improves
it by exchange (Fedorov / DETMAX: swap a chosen search for a candidate while ``f`` drops).
Candidates may be grouped with a quota per group (3-2-1: three on the primary face, two on
the secondary, one on the tertiary), and chosen points keep a minimum distance apart.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from calib.errors import ShapeError

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Prior standard deviations of the greedy start: 1 m and 1 rad (vanishing information).
PRIOR_SIGMA = 1.0
#: Weight of the mean squared error over the ``background`` points (e.g. the part's corners)
#: added to the criterion: a motion the points of interest do not see (a rotation about the
#: only one) must still be fixed, and this keeps it so without competing with them.
BACKGROUND_WEIGHT = 1e-3
_AXIS = {"x": 0, "y": 1, "z": 2}


def poi_jacobians(points_m: FloatArray, components: Sequence[str]) -> list[FloatArray]:
    """Per point of interest, ``(k, 6)`` rows of the components that count (``"yz"``: 2)."""
    from calib.estimators.layout import point_motion_jacobian

    J = point_motion_jacobian(np.asarray(points_m, dtype=np.float64).reshape(-1, 3))
    return [J[i][[_AXIS[c] for c in comp]] for i, comp in enumerate(components)]


def criterion(
    cov: FloatArray, poi: Sequence[FloatArray], background: FloatArray | None = None
) -> float:
    """``max_p trace(J_p cov J_p^T)``: the largest mean squared error at a point, m^2, plus
    :data:`BACKGROUND_WEIGHT` times the mean over ``background`` ``(B, 3, 6)`` rows."""
    out = max(float(np.trace(J @ cov @ J.T)) for J in poi)
    if background is not None and len(background):
        tr = np.einsum("bkj,jl,bkl->b", background, cov, background)
        out += BACKGROUND_WEIGHT * float(np.mean(tr))
    return out


@dataclass(frozen=True)
class Design:
    """A chosen set of searches.

    Attributes:
        chosen: indices into the candidates, in the order they were added.
        covariance: ``(6, 6)`` least-squares covariance of the set with the fixed rows
            (m, rad), without the prior.
        score: :func:`criterion` of ``covariance``, m^2.
        greedy_score: the score after the greedy steps, before the exchange, m^2.
        swaps: how many exchanges improved the set.
    """

    chosen: tuple[int, ...]
    covariance: FloatArray = field(repr=False)
    score: float
    greedy_score: float
    swaps: int


def _inverse(M: FloatArray) -> FloatArray:
    cov = np.linalg.inv(M)
    return 0.5 * (cov + cov.T)


def _best_addition(
    cov: FloatArray,
    rows: FloatArray,
    var: FloatArray,
    poi: FloatArray,
    allowed: NDArray[np.bool_],
    background: FloatArray | None,
) -> tuple[int, float]:
    """The allowed candidate whose addition lowers the criterion most, and the new score."""
    idx = np.flatnonzero(allowed)
    if len(idx) == 0:
        return -1, float("inf")
    U = rows[idx] @ cov  # (C, 6)
    den = var[idx] + np.einsum("ij,ij->i", U, rows[idx])
    base = np.einsum("pkj,jl,pkl->p", poi, cov, poi)  # (P,)
    JU = np.einsum("pkj,cj->cpk", poi, U)  # (C, P, k)
    new = base[None, :] - np.einsum("cpk,cpk->cp", JU, JU) / den[:, None]
    worst = new.max(axis=1)
    if background is not None and len(background):
        tr = np.einsum("bkj,jl,bkl->b", background, cov, background)
        JB = np.einsum("bkj,cj->cbk", background, U)
        drop = np.einsum("cbk,cbk->cb", JB, JB) / den[:, None]
        worst = worst + BACKGROUND_WEIGHT * (tr[None, :] - drop).mean(axis=1)
    k = int(np.argmin(worst))
    return int(idx[k]), float(worst[k])


def select(
    rows: FloatArray,
    var: FloatArray,
    n: int,
    poi: Sequence[FloatArray],
    *,
    positions_m: FloatArray | None = None,
    min_separation_m: float = 0.0,
    groups: IntArray | None = None,
    quota: Mapping[int, int] | None = None,
    fixed_rows: FloatArray | None = None,
    fixed_var: FloatArray | None = None,
    start: Sequence[int] = (),
    scale_m: float = 1.0,
    max_passes: int = 10,
    available: NDArray[np.bool_] | None = None,
    background_m: FloatArray | None = None,
    follows: Callable[[Sequence[int]], NDArray[np.bool_]] | None = None,
) -> Design:
    """Choose ``n`` candidate searches minimising :func:`criterion` (greedy, then exchange).

    Args:
        rows: ``(C, 6)`` constraint row of each candidate.
        var: ``(C,)`` event variance of each candidate, m^2.
        n: how many to choose (besides ``fixed_rows``).
        poi: per point of interest ``(k, 6)`` rows (:func:`poi_jacobians`); all of one ``k``.
        positions_m: ``(C, 3)`` candidate positions, for ``min_separation_m``.
        min_separation_m: two chosen candidates lie at least this far apart.
        groups: ``(C,)`` group of each candidate, with ``quota``: how many from each group
            (their sum must be ``n``); ``None``: any candidate.
        quota: ``{group: count}``.
        fixed_rows: ``(F, 6)`` rows already in the layout (``--add``), kept.
        fixed_var: ``(F,)`` their variances.
        start: candidate indices to start the greedy from (a previous, smaller design).
        scale_m: the part's size; the prior is ``PRIOR_SIGMA`` m and rad / ``scale_m``.
        max_passes: largest number of exchange passes.
        available: ``(C,)`` candidates that may be chosen (default all).
        background_m: ``(B, 3)`` points whose mean error is added with a small weight
            (:data:`BACKGROUND_WEIGHT`), so every degree of freedom gets fixed.
        follows: ``follows(chosen) -> (C,)``: the candidates that may be measured after
            ``chosen`` (in the order chosen). With it the set is grown in measuring order, each
            step among those, and an exchange puts a candidate in a search's place only when
            it may follow the searches before that place and every later one may still follow
            (the best candidate for the place; none when it breaks the order): ``chosen`` of
            the result is a measuring order when the ``start`` searches are one (they are
            taken as given, first).

    Raises:
        ShapeError: inconsistent shapes, or a quota that does not add up to ``n``.
    """
    A = np.asarray(rows, dtype=np.float64)
    v = np.asarray(var, dtype=np.float64)
    if A.ndim != 2 or A.shape[1] != 6 or v.shape != (A.shape[0],):
        raise ShapeError(f"rows must be (C, 6) and var (C,), got {A.shape} and {v.shape}")
    if quota is not None and sum(quota.values()) != n:
        raise ShapeError(f"the quota {dict(quota)} does not add up to {n} points")
    P = np.stack([np.asarray(J, dtype=np.float64) for J in poi])  # (P, k, 6)
    from calib.estimators.layout import point_motion_jacobian

    B = None if background_m is None else point_motion_jacobian(np.reshape(background_m, (-1, 3)))
    C = A.shape[0]
    g = np.zeros(C, dtype=np.int64) if groups is None else np.asarray(groups, dtype=np.int64)
    left = {0: n} if quota is None else dict(quota)
    pos = None if positions_m is None else np.asarray(positions_m, dtype=np.float64)
    # information, not covariance, is updated: a downdate of the only search that holds a
    # degree of freedom would cancel catastrophically (prior 1 m^2 against noise 1e-9 m^2)
    M = np.diag([PRIOR_SIGMA**-2] * 3 + [(scale_m / PRIOR_SIGMA) ** 2] * 3)
    if fixed_rows is not None and fixed_var is not None:
        F = np.asarray(fixed_rows, dtype=np.float64).reshape(-1, 6)
        M = M + (F / np.asarray(fixed_var, dtype=np.float64).ravel()[:, None]).T @ F
    cov = _inverse(M)
    chosen: list[int] = []

    far: dict[int, NDArray[np.bool_]] = {}  # per chosen candidate: the ones far enough away

    def apart(c: int) -> NDArray[np.bool_]:
        if c not in far:
            assert pos is not None
            far[c] = np.linalg.norm(pos - pos[c], axis=1) >= min_separation_m
        return far[c]

    def allowed(exclude: int = -1) -> NDArray[np.bool_]:
        if quota is not None:
            ok = np.isin(g, [k for k, count in left.items() if count > 0])
        else:
            ok = np.full(C, left[0] > 0)
        if available is not None:
            ok &= available
        for c in chosen:
            if c == exclude:
                continue
            ok[c] = False
            if pos is not None and min_separation_m > 0:
                ok &= apart(c)
        return ok

    def info(c: int) -> FloatArray:
        return np.outer(A[c], A[c]) / float(v[c])

    def take(c: int) -> None:
        nonlocal cov, M
        chosen.append(c)
        left[int(g[c]) if quota is not None else 0] -= 1
        M = M + info(c)
        cov = _inverse(M)

    for c in start:
        take(int(c))
    score = criterion(cov, list(P), B)
    while len(chosen) < n:
        mask = allowed() if follows is None else allowed() & follows(tuple(chosen))
        c, new = _best_addition(cov, A, v, P, mask, B)
        if c < 0:
            break
        take(c)
        score = new
    greedy = score
    swaps = 0

    def keeps_order(i: int, c: int) -> bool:
        """With ``follows``: every search after position ``i`` may still follow the ones
        before it when ``c`` takes that position."""
        if follows is None:
            return True
        new = [*chosen[:i], c, *chosen[i + 1 :]]
        return all(follows(tuple(new[:j]))[new[j]] for j in range(i + 1, len(new)))

    for _ in range(max_passes):
        improved = False
        for i in range(len(chosen)):
            out = chosen[i]
            M_out = M - info(out)
            reduced = _inverse(M_out)
            key = int(g[out]) if quota is not None else 0
            left[key] += 1
            mask = allowed(exclude=out)
            mask[out] = False
            if quota is not None:
                mask &= g == key
            if follows is not None:
                mask &= follows(tuple(chosen[:i]))
            c, new = _best_addition(reduced, A, v, P, mask, B)
            left[key] -= 1
            if c >= 0 and new < score * (1.0 - 1e-9) and keeps_order(i, c):
                chosen[i] = c
                M = M_out + info(c)
                cov = _inverse(M)
                score = new
                swaps += 1
                improved = True
        if not improved:
            break
    exact = exact_covariance(A[chosen], v[chosen], fixed_rows, fixed_var)
    final = criterion(exact, list(P), B) if np.all(np.isfinite(exact)) else float("inf")
    return Design(tuple(chosen), exact, final, greedy, swaps)


def exact_covariance(
    rows: FloatArray,
    var: FloatArray,
    fixed_rows: FloatArray | None = None,
    fixed_var: FloatArray | None = None,
) -> FloatArray:
    """``(6, 6)`` least-squares covariance ``(sum a a^T / var)^-1`` of the rows (no prior);
    infinite when they do not fix all six degrees of freedom."""
    A = np.asarray(rows, dtype=np.float64).reshape(-1, 6)
    v = np.asarray(var, dtype=np.float64).ravel()
    if fixed_rows is not None and fixed_var is not None:
        A = np.concatenate([np.asarray(fixed_rows).reshape(-1, 6), A])
        v = np.concatenate([np.asarray(fixed_var).ravel(), v])
    M = (A / v[:, None]).T @ A
    s = np.linalg.svd(M, compute_uv=False)
    if len(A) < 6 or s[-1] <= 1e-12 * s[0]:
        return np.full((6, 6), np.inf)
    cov = np.linalg.inv(M)
    return 0.5 * (cov + cov.T)
