"""The measuring order that shortens the program's moves, within the order the landing allows.

A chosen layout's points can be measured in many orders; the program's joint moves between
them are most of its cycle time (the plate's best fit: 52 of 72 s). :func:`shortest_order`
finds the order of least total move time whose every point still lands on its face when
measured after the points before it (the predicate ``fits`` of
:meth:`planner.suggest.order.Sequencer.fits`: a footprint depends on *which* points came
before, not on their order). Exact for up to :data:`EXACT_MAX` points (Held-Karp over the
subsets, only the subsets ``fits`` allows); beyond, nearest-neighbour among the points that
fit, then segment reversals (2-opt) kept while every point still fits. The path is open: the
move into the first point is not counted, as the cycle time does not count it.

Pure: indices ``0..n-1`` into a cost matrix of seconds; the caller maps them to candidates.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
#: ``fits(i, earlier)``: point ``i`` lands on its face when measured after the set ``earlier``.
Fits = Callable[[int, frozenset[int]], bool]
#: Most points ordered exactly (``n * 2**n`` states).
EXACT_MAX = 11
#: Rounds of 2-opt improvement, at most (each an ``O(n^2)`` sweep).
TWO_OPT_ROUNDS = 20


def path_cost(order: Sequence[int], cost: FloatArray) -> float:
    """Total of ``cost[a, b]`` over consecutive points of ``order``, s."""
    return float(sum(cost[a, b] for a, b in itertools.pairwise(order)))


def valid(order: Sequence[int], fits: Fits) -> bool:
    """Every point of ``order`` fits after the ones before it."""
    return all(fits(i, frozenset(order[:k])) for k, i in enumerate(order))


def shortest_order(
    cost: FloatArray, fits: Fits, fallback: Sequence[int] | None = None
) -> tuple[int, ...] | None:
    """The order of ``0..n-1`` of least :func:`path_cost` that :func:`valid` accepts.

    Args:
        cost: ``(n, n)`` seconds from point ``a`` to point ``b`` (need not be symmetric;
            finite, non-negative).
        fits: the landing predicate (see the module docstring).
        fallback: a valid order to start the heuristic from when the greedy one gets stuck
            (the landing order); ignored for exact sizes.

    Returns:
        The order, or ``None`` when no order is valid (exact sizes) or neither the greedy
        order nor ``fallback`` is.
    """
    C = np.asarray(cost, dtype=np.float64)
    n = len(C)
    if C.shape != (n, n) or not np.all(np.isfinite(C)) or np.any(C < 0):
        raise ValueError(f"cost: a finite non-negative (n, n) matrix, got shape {C.shape}")
    if n == 0:
        return ()
    if n <= EXACT_MAX:
        return _held_karp(C, fits)
    start = _greedy(C, fits)
    if start is None:
        if fallback is None or not valid(fallback, fits):
            return None
        start = tuple(fallback)
    return _two_opt(start, C, fits)


def _held_karp(C: FloatArray, fits: Fits) -> tuple[int, ...] | None:
    """Exact: ``best[S][j]`` the least cost of a valid order of the set ``S`` ending in ``j``."""
    n = len(C)
    full = (1 << n) - 1
    memo: dict[tuple[int, int], bool] = {}

    def ok(j: int, mask: int) -> bool:
        key = (j, mask)
        if key not in memo:
            memo[key] = fits(j, frozenset(k for k in range(n) if mask >> k & 1))
        return memo[key]

    inf = float("inf")
    best: dict[int, dict[int, float]] = {}
    back: dict[tuple[int, int], int] = {}
    for j in range(n):
        if ok(j, 0):
            best.setdefault(1 << j, {})[j] = 0.0
    # masks in increasing popcount order: every subset is finished before its supersets
    for mask in sorted(range(1, full + 1), key=lambda m: (m.bit_count(), m)):
        ends = best.get(mask)
        if not ends:
            continue
        for k in range(n):
            if mask >> k & 1 or not ok(k, mask):
                continue
            nxt = mask | 1 << k
            row = best.setdefault(nxt, {})
            for j, c in ends.items():
                v = c + float(C[j, k])
                if v < row.get(k, inf) or (v == row.get(k, inf) and j < back[(nxt, k)]):
                    row[k] = v
                    back[(nxt, k)] = j
    last = best.get(full)
    if not last:
        return None
    j = min(last, key=lambda e: (last[e], e))
    order = [j]
    mask = full
    while mask.bit_count() > 1:
        prev = back[(mask, j)]
        mask &= ~(1 << j)
        order.append(prev)
        j = prev
    return tuple(reversed(order))


def _greedy(C: FloatArray, fits: Fits) -> tuple[int, ...] | None:
    """Nearest-neighbour among the points that fit, from every start; the cheapest valid one."""
    n = len(C)
    found: tuple[float, tuple[int, ...]] | None = None
    for s in range(n):
        if not fits(s, frozenset()):
            continue
        order = [s]
        left = set(range(n)) - {s}
        while left:
            done = frozenset(order)
            now = [k for k in left if fits(k, done)]
            if not now:
                break
            k = min(now, key=lambda k: (C[order[-1], k], k))
            order.append(k)
            left.discard(k)
        if left:
            continue
        c = path_cost(order, C)
        if found is None or c < found[0]:
            found = (c, tuple(order))
    return None if found is None else found[1]


def _two_opt(order: tuple[int, ...], C: FloatArray, fits: Fits) -> tuple[int, ...]:
    """Reverse segments while that shortens the path and keeps it valid."""
    best = list(order)
    cost = path_cost(best, C)
    for _ in range(TWO_OPT_ROUNDS):
        improved = False
        for a in range(len(best) - 1):
            for b in range(a + 1, len(best)):
                trial = best[:a] + best[a : b + 1][::-1] + best[b + 1 :]
                c = path_cost(trial, C)
                if c < cost - 1e-12 and valid(trial, fits):
                    best, cost, improved = trial, c, True
        if not improved:
            break
    return tuple(best)
