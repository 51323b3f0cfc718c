"""Joint limits, 2*pi variants and packing of the OPW branches into ``(N, K, 6)`` solutions.

Candidates arrive as rows ``(R, 6)`` ordered by pose, then OPW branch. A joint whose limits lie
within ``[-pi, pi]`` is checked as it is; any other joint with finite limits is moved to its
lowest value ``>= lower`` (modulo 2*pi) and ``m`` values ``+ 2*pi*i`` are tried (``m`` from
:attr:`OPWRobot.turn_counts`). Continuous joints keep their one value. Each pose's solutions
within the limits are packed first, by branch then by variant (the row-major order of the
variant indices), NaN after them.

Everything is element-wise over the batch; no mask over all ``8 * V`` candidate variants is
built: the variants within limits of a multi-turn joint are a prefix ``i < m_j``, so a row
has ``prod(m_j)`` solutions, and each solution's variant follows from its rank in the row.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Joint values this far (rad) outside a limit still count as within it.
LIMIT_TOL = 1e-12
TWO_PI = 2.0 * np.pi


@dataclass(frozen=True, eq=False)
class JointLimits:
    """Joint limits prepared once per robot for :func:`select_rows`.

    Attributes:
        simple: ``(joint, lower, upper)`` of joints checked as they are (limits within
            ``[-pi, pi]``), rad.
        multi: ``(joint, lower, upper, m)`` of joints tried at ``m`` values 2*pi apart, rad.
    """

    simple: tuple[tuple[int, float, float], ...]
    multi: tuple[tuple[int, float, float, int], ...]

    @classmethod
    def of(cls, lower: FloatArray, upper: FloatArray, turn_counts: tuple[int, ...]) -> JointLimits:
        """Sort the joints of limits ``lower``, ``upper`` ``(6,)`` rad into simple and multi.

        Raises:
            ValueError: 4096 or more variants per branch (joint ranges of many turns).
        """
        simple: list[tuple[int, float, float]] = []
        multi: list[tuple[int, float, float, int]] = []
        for j, (lo, hi) in enumerate(zip(lower, upper)):
            if not (np.isfinite(lo) and np.isfinite(hi)):
                continue
            if turn_counts[j] == 1 and lo >= -np.pi and hi <= np.pi:
                simple.append((j, float(lo), float(hi)))
            else:
                multi.append((j, float(lo), float(hi), int(turn_counts[j])))
        n_variants = int(np.prod([m for *_, m in multi], dtype=np.int64))
        if n_variants >= 2**12:
            raise ValueError(f"too many 2*pi variants per branch: {n_variants} (joint ranges)")
        return cls(tuple(simple), tuple(multi))


@dataclass(frozen=True)
class Selected:
    """The solutions within limits of a batch of ``n`` poses, not yet packed into ``(N, K)``.

    Attributes:
        per_pose: ``(n,)`` int, solutions of each pose.
        q: ``(M, 6)`` joint values, rad, ordered by pose, branch, variant.
        pose: ``(M,)`` int, the pose (within the batch) of each row.
        slot: ``(M,)`` int, the row's place among its pose's solutions.
        branch: ``(M,)`` int, the OPW branch index 0-7 of each row, or with ``config_codes``
            the configuration code ``(branch & 6) + (axis 5 < 0)``.
    """

    per_pose: NDArray[np.intp]
    q: FloatArray
    pose: NDArray[np.intp]
    slot: NDArray[np.intp]
    branch: NDArray[np.intp]


def select_rows(
    limits: JointLimits,
    q: FloatArray,
    inside: BoolArray,
    pose: NDArray[np.intp],
    branch: NDArray[np.intp],
    n: int,
    config_codes: bool = False,
    checked: tuple[int, ...] = (),
) -> Selected:
    """Apply the limits and 2*pi variants to candidate rows of ``n`` poses.

    Args:
        limits: the robot's prepared joint limits.
        q: ``(R, 6)`` candidate joint values, rad, ordered by pose, then branch (any value
            where ``inside`` is False). Overwritten: multi-turn joints are moved to their
            lowest value within the limits.
        inside: ``(R,)`` the candidate exists. Overwritten.
        pose: ``(R,)`` the pose (0 to ``n - 1``) of each row, non-decreasing.
        branch: ``(R,)`` the OPW branch index 0-7 of each row.
        n: the number of poses.
        config_codes: return configuration codes ``(branch & 6) + (axis 5 < 0)`` instead of
            OPW branch indices.
        checked: simple joints whose limits ``inside`` already includes.
    """
    R = q.shape[0]
    tmp = np.empty(R, dtype=bool)
    counts_m: list[tuple[int, FloatArray]] = []
    with np.errstate(invalid="ignore"):
        for j, lo, hi in limits.simple:
            if j in checked:
                continue
            np.greater_equal(q[:, j], lo - LIMIT_TOL, out=tmp)
            inside &= tmp
            np.less_equal(q[:, j], hi + LIMIT_TOL, out=tmp)
            inside &= tmp
        count = inside.astype(np.intp)
        for j, lo, hi, m in limits.multi:
            qj = q[:, j]
            q_lo = qj - lo
            q_lo += LIMIT_TOL
            q_lo *= 1.0 / TWO_PI
            np.floor(q_lo, out=q_lo)
            q_lo *= TWO_PI
            np.subtract(qj, q_lo, out=q_lo)  # the lowest representative >= lo
            qj[...] = q_lo
            m_j = np.zeros(R)  # variants within the limits: i < m_j
            for i in range(m):
                np.less_equal(q_lo + TWO_PI * i, hi + LIMIT_TOL, out=tmp)
                m_j += tmp
            count *= m_j.astype(np.intp)
            counts_m.append((j, m_j))
    per_pose = np.bincount(pose, weights=count, minlength=n).astype(np.intp)
    ends = np.cumsum(count)
    M = int(ends[-1]) if R else 0
    empty = np.zeros(0, dtype=np.intp)
    if not M:
        return Selected(per_pose, np.zeros((0, 6)), empty, empty, empty)
    starts = ends - count
    groups = np.flatnonzero(count)
    marks = np.zeros(M, dtype=np.intp)
    marks[starts[groups[1:]]] = 1
    src = groups[np.cumsum(marks)]  # (M,) the candidate row of every solution
    k = np.arange(M)
    out = q.take(src, axis=0)
    if counts_m:
        rank = (k - starts.take(src)).astype(np.float64)  # the variant's rank in its row
        for j, m_j in reversed(counts_m):  # variant index: last joint fastest
            m_at = m_j.take(src)
            above = rank / m_at
            np.floor(above, out=above)  # exact: small integers
            rank -= above * m_at  # now the variant index i of joint j
            rank *= TWO_PI
            out[:, j] += rank
            rank = above
    p = pose.take(src)
    first = np.cumsum(per_pose) - per_pose  # the first solution of each pose
    slot = k - first.take(p)
    b = branch.take(src)
    if config_codes:
        b &= 6
        b += out[:, 4] < 0
    return Selected(per_pose, out, p, slot, b)


def assemble(
    parts: list[Selected], min_k: int = 8
) -> tuple[FloatArray, BoolArray, NDArray[np.intp]]:
    """Pack consecutive batches of selected solutions into ``(N, K)`` arrays.

    Returns:
        ``q (N, K, 6)`` (each pose's solutions first, NaN after them), ``valid (N, K)`` and
        ``branch (N, K)`` (-1 where not valid), ``K = max(min_k, most solutions of any pose)``.
    """
    per_pose = np.concatenate([p.per_pose for p in parts]) if parts else np.zeros(0, np.intp)
    N = per_pose.size
    K = max(min_k, int(per_pose.max()) if N else 0)
    q = np.full((N * K, 6), np.nan)
    branch = np.full(N * K, -1, dtype=np.intp)
    q_items = _rows_as_items(q)
    first = 0
    for p in parts:
        if p.q.shape[0]:
            dest = p.pose + first
            dest *= K
            dest += p.slot
            np.put(q_items, dest, _rows_as_items(p.q))
            np.put(branch, dest, p.branch)
        first += p.per_pose.size
    valid = np.arange(K) < per_pose[:, None]
    return q.reshape(N, K, 6), valid, branch.reshape(N, K)


def _rows_as_items(a: FloatArray) -> NDArray[np.void]:
    """A C-contiguous ``(R, 6)`` float array as ``(R,)`` 48-byte items (fast row put/take)."""
    return a.view(np.dtype((np.void, 48))).reshape(-1)
