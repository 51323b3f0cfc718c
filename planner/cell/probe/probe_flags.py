"""What the broad phase and the slack bounds know of one probe point's candidates.

:class:`CandidateFlags` holds, per candidate row of a point's checking order, the broad
phase's part and pair states (:meth:`planner.cell.broad.BroadPhase.states`) and an upper
bound of its slack (:class:`planner.cell.broad.SlackBounds`), computed in blocks: the
first with the batch, the next ones when the search reaches them, each as large as all before
it (or all the rest at once, batched over points, with :meth:`CandidateFlags.missing`).
:func:`clear_ahead` picks the candidate the search would choose first when the broad phase
alone decides it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

BoolArray = NDArray[np.bool_]
FloatArray = NDArray[np.float64]
#: ``(part states (M, P), pair states (M, S), opened (M,), slack upper bounds (M,))`` of
#: candidates ``cs`` of one point.
Block = tuple[NDArray[np.int8], NDArray[np.int8], NDArray[np.int64], FloatArray]


def clear_ahead(
    near: BoolArray, head: NDArray[np.int_], pc: NDArray[np.int8], sc: NDArray[np.int8]
) -> int:
    """The candidate the search would choose first when the broad phase alone decides it: the
    first of ``head`` (the point's leading candidates, their part and pair states ``pc``,
    ``sc``) not shown below the margin, when nothing of it is near (its clearance is the look
    distance, which passes) and its joints are not near a limit; else -1."""
    for j, c in enumerate(head.tolist()):
        if near[c]:
            return -1
        if (pc[j] == -1).any() or (sc[j] == -1).any():
            continue
        return c if (pc[j] == 1).all() and (sc[j] == 1).all() else -1
    return -1


class CandidateFlags:
    """Broad-phase states and slack bounds of one point's candidates in checking order.

    Args:
        order: the point's candidates in checking order.
        compute: the :data:`Block` of candidates ``cs`` (a slice of ``order``).
    """

    def __init__(
        self, order: NDArray[np.int_], compute: Callable[[NDArray[np.int_]], Block]
    ) -> None:
        self._order = order
        self._compute = compute
        self._pc: list[NDArray[np.int8]] = []
        self._sc: list[NDArray[np.int8]] = []
        self._opened: list[int] = []
        self._upper: list[float] = []
        self._all_clear: list[bool] = []
        self._fails: list[bool] = []

    def put(self, block: Block) -> None:
        """Append the next rows' states and bounds."""
        pc, sc, opened, upper = block
        self._pc.extend(pc)
        self._sc.extend(sc)
        self._opened.extend(opened.tolist())
        self._upper.extend(upper.tolist())
        self._all_clear.extend(((pc == 1).all(axis=1) & (sc == 1).all(axis=1)).tolist())
        self._fails.extend(((pc == -1).any(axis=1) | (sc == -1).any(axis=1)).tolist())

    @property
    def rows(self) -> int:
        """How many leading rows of the order are known."""
        return len(self._pc)

    def missing(self) -> NDArray[np.int_]:
        """The candidates of the order not known yet (for one batched :meth:`put`)."""
        return self._order[len(self._pc) :]

    def _get(self, j: int) -> tuple[NDArray[np.int8], NDArray[np.int8]]:
        while j >= len(self._pc):  # the next block, twice as many as computed so far
            n = len(self._pc)
            self.put(self._compute(self._order[n : max(j + 1, 2 * n)]))
        return self._pc[j], self._sc[j]

    def opened(self, j: int) -> int:
        """Sphere-tree leaves of candidate row ``j`` near the environment."""
        self._get(j)
        return self._opened[j]

    def upper(self, j: int) -> float:
        """An upper bound of candidate row ``j``'s slack in Bullet's query, m (inf: none)."""
        self._get(j)
        return self._upper[j]

    def clear(self, j: int) -> tuple[BoolArray, BoolArray]:
        """``(parts clear (P,), pairs clear (S,))`` of candidate row ``j``."""
        pc, sc = self._get(j)
        return pc == 1, sc == 1

    def all_clear(self, j: int) -> bool:
        """Nothing of candidate row ``j`` is near: its clearance is the look distance."""
        self._get(j)
        return self._all_clear[j]

    def fails(self, j: int) -> bool:
        """A part of candidate row ``j`` is shown below the margin."""
        self._get(j)
        return self._fails[j]
