"""Via points that clear a joint move between two probe points: retract, swing, approach.

A joint move from one point's safe start to the next one's often drags the tool through the
part: both ends are a few centimetres off its surface, and the swing between two faces cuts
the corner. A robot programmer then teaches a retract: back away along the sensor axis,
swing, come in again. :func:`suggest_vias` tries exactly that, in order of least detour, for
every point a program may come from at once (a via belongs to the point it leads to):

1. one via, the start or the end retracted ``d`` along its sensor axis;
2. two vias, both retracted ``d``;
3. two vias, both retracted ``d`` and lifted ``h`` in the robot base's +z;
4. where a point is at the edge of the reach and cannot back away with its orientation: one
   via at the start or the end with the shoulder or the elbow (joints 2 and 3) turned by
   :data:`JOINT_STEPS_DEG`, then one at each end;

for ``d`` in :data:`RETRACTS_M` and ``h`` in :data:`LIFTS_M`, each via the IK solution nearest
its end's joint values (so the configuration stays), and returns the first set whose moves
:func:`planner.cell.moves.check_via_path` finds clear. No optimisation, no guarantee: ``None``
when none of these clears it, and the engineer teaches one in the Teach tab.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.frames import invert_transform
from planner.cell.moves.joint_moves import check_via_path

if TYPE_CHECKING:
    from planner.cell.scene import CellScene

FloatArray = NDArray[np.float64]

#: Retract distances tried, along the sensor axis, m.
RETRACTS_M = (0.1, 0.2, 0.3)
#: Lifts tried on top of a retract, base +z, m.
LIFTS_M = (0.2, 0.4)
#: Turns of joints 2 and 3 tried at a move's ends, degrees (smallest first).
JOINT_STEPS_DEG = (-10.0, 10.0, -20.0, 20.0, -30.0, 30.0)


def retracted(
    cell: CellScene, q: ArrayLike, tcp: str, back_m: float, lift_m: float = 0.0
) -> FloatArray | None:
    """Joint values (rad) with the ``tcp`` moved ``back_m`` against its sensor axis (its +z)
    and ``lift_m`` up the base's +z, orientation kept, nearest ``q``; ``None`` when
    unreachable."""
    qa = np.asarray(q, dtype=np.float64).reshape(-1)
    T_ft = cell.T_flange_tcp(tcp)
    T = np.asarray(cell.chain.fk(qa[None]))[0] @ T_ft
    T[:3, 3] += -back_m * T[:3, 2] + np.array([0.0, 0.0, lift_m])
    sol = cell.solver.solve((T @ invert_transform(T_ft))[None], seeds=qa[None])
    q_new, found = sol.nearest(qa)
    return q_new[0].copy() if bool(found[0]) else None


def suggest_vias(
    cell: CellScene, q_froms: Sequence[ArrayLike], q_to: ArrayLike, tcp: str
) -> list[FloatArray] | None:
    """Vias (joint values, rad, in order) that make the moves from every one of ``q_froms``
    (the points a program comes from) to ``q_to`` clear, or ``None`` (module docstring).
    ``[]`` when the direct moves are clear already."""
    froms = [np.asarray(q, dtype=np.float64).reshape(-1) for q in q_froms]
    b = np.asarray(q_to, dtype=np.float64).reshape(-1)

    def clear(candidate: list[FloatArray | None]) -> bool:
        vias = [v for v in candidate if v is not None]
        if len(vias) < len(candidate):  # a retract without an IK solution
            return False
        return all(not check_via_path(cell, a, vias, b, tcp).problem for a in froms)

    if clear([]):
        return []
    for candidate in _candidates(cell, froms, b, tcp):
        if clear(candidate):
            return [v for v in candidate if v is not None]
    return None


def _candidates(
    cell: CellScene, froms: list[FloatArray], b: FloatArray, tcp: str
) -> Iterator[list[FloatArray | None]]:
    """Via lists in order of least detour (module docstring)."""
    for d in RETRACTS_M:
        rb = retracted(cell, b, tcp, d)
        yield [rb]
        for a in froms:
            ra = retracted(cell, a, tcp, d)
            yield [ra]
            yield [ra, rb]
    for d, h in itertools.product(RETRACTS_M, LIFTS_M):
        rb = retracted(cell, b, tcp, d, h)
        for a in froms:
            yield [retracted(cell, a, tcp, d, h), rb]
    joints = [j for j in (1, 2) if j < b.size]
    turns = [(j, step) for step in JOINT_STEPS_DEG for j in joints]
    for j, step in turns:
        yield [_turned(b, j, step)]
        for a in froms:
            yield [_turned(a, j, step)]
    for j, step in turns:
        for a in froms:
            yield [_turned(a, j, step), _turned(b, j, step)]


def _turned(q: FloatArray, joint: int, step_deg: float) -> FloatArray:
    v = q.copy()
    v[joint] += np.radians(step_deg)
    return v
