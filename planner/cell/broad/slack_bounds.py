"""Upper bounds of probe candidates' slacks without Bullet: GJK on the exact shapes.

The search among a point's candidates (:mod:`planner.cell.probe.probe_choice`) needs Bullet's exact
slack only for candidates that can still win: the first that passes, or the least-bad one. A
candidate whose slack is surely below the margin cannot pass, and one whose slack is surely
more than the tie below the best exact slack found cannot be the least-bad one. The broad
phase shows the first for parts certified near; :class:`SlackBounds` gives a number: for the
parts left open against a box, cylinder or sphere body and for the open self pairs, GJK's upper
bound of the true distance (:func:`planner.cell.kernels.bound_kernels.slack_upper`) plus how far
Bullet's distance can exceed the true one (its rounded box and cylinder edges,
:data:`planner.cell.broad.link_geometry.BULLET_ROUNDING_M` per side, convex hulls and meshes are
only inflated) plus :data:`planner.cell.broad.broad_parts.SAFETY_M`. Parts against meshes get no
bound here (the least of the others still bounds the candidate's slack).

A bound never decides an answer: it only spares Bullet queries of candidates that cannot be
chosen, so the answers stay the exact check's (``tests/planner/cell/broad/test_slack_bounds.py``
compares every
bound with Bullet's slack).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from planner.cell.broad.broad_parts import SAFETY_M
from planner.cell.kernels import bound_kernels
from planner.cell.kernels.broad_kernels import FIELD

if TYPE_CHECKING:
    from planner.cell.broad.broad_arrays import EnvArrays, PartMap
    from planner.cell.broad.broad_phase import BroadPhase
    from planner.cell.scene import QueryPlan

FloatArray = NDArray[np.float64]

# numba dispatchers take any arguments (their stubs say otherwise)
_slack_upper: Any = bound_kernels.slack_upper


class SlackBounds:
    """Upper bounds of the slack of candidates in one query plan's terms.

    Args:
        broad: the cell's broad phase (its links and shapes).
        parts: the plan's parts on its links and bodies.
        env: the environment bodies now.
        plan: the query plan (look distances and required distances of the parts).
    """

    def __init__(self, broad: BroadPhase, parts: PartMap, env: EnvArrays, plan: QueryPlan):
        excess = np.array([b.excess_m for b in broad.links], dtype=float)
        kind = env.arrays[0]
        pe = parts.part_env
        primitive = np.array([kind[e] != FIELD for e in pe.tolist()], dtype=bool)
        self._use_p = parts.known & primitive
        self._part = (
            parts.part_link,
            pe,
            excess[parts.part_link] + env.excess_m[pe] + SAFETY_M,
            np.array([plan.parts[i].need_m for i in parts.part_index.tolist()], dtype=float),
            np.array([plan.parts[i].dist_m for i in parts.part_index.tolist()], dtype=float),
        )
        self_part = plan.parts[-1]
        S = parts.pair_a.size
        self._use_s = parts.pair_known & ~parts.pair_fixed_clear
        self._pair = (
            parts.pair_a,
            parts.pair_b,
            excess[parts.pair_a] + excess[parts.pair_b] + SAFETY_M,
            np.full(S, self_part.need_m),
            np.full(S, self_part.dist_m),
        )
        sh = broad.shape_arrays()
        # kind, T, dims, vstart, vcount, verts, link_start, link_count (no box centres)
        self._shapes = (sh[0], sh[1], sh[2], sh[5], sh[6], sh[7], sh[8], sh[9])
        self._env = (kind, env.arrays[2], env.arrays[3])

    def upper(
        self, T_links: FloatArray, part_states: NDArray[np.int8], pair_states: NDArray[np.int8]
    ) -> FloatArray:
        """``(M,)`` upper bounds of Bullet's slack of candidates with link poses ``T_links
        (M, L, 3, 4)`` and broad-phase states ``(M, P)``, ``(M, S)`` (only the parts and pairs
        not shown clear are bounded); ``inf`` where nothing is known, m."""
        M = T_links.shape[0]
        todo_p = (part_states != 1) & self._use_p
        todo_s = (pair_states != 1) & self._use_s
        if M == 0 or not (todo_p.any() or todo_s.any()):
            return np.full(M, np.inf)
        out: FloatArray = _slack_upper(
            np.ascontiguousarray(T_links), todo_p, *self._part, todo_s, *self._pair,
            *self._shapes, *self._env,
        )  # fmt: skip
        return out
