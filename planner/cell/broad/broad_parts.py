"""The parts of a clearance query on the broad phase's links and bodies: their thresholds.

For each part (a link against a body) and each self pair: the distance at which it is *clear*
(its look distance, plus Bullet's inflation of each side and :data:`SAFETY_M`) and the distance
below which its slack is surely *below the margin* (``need_m + margin_m`` minus Bullet's
rounding of each side and :data:`SAFETY_M`); see :mod:`planner.cell.broad.broad_phase`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from planner.cell.broad.broad_arrays import BroadLink, EnvArrays, PartMap
from planner.cell.scene import pb

if TYPE_CHECKING:
    from planner.cell.scene import CellScene, QueryPlan

BoolArray = NDArray[np.bool_]

#: Added to every part's look distance before a part is called clear, and taken off the
#: distance below which it is called below the margin, m (covers Bullet's single-precision
#: poses and the GJK tolerance with a wide margin).
SAFETY_M = 0.0005


def _known(links: list[BroadLink], k: int) -> bool:
    """Link ``k`` can be decided here: it has a sphere tree and a known pose."""
    b = links[k]
    return b.tree is not None and b.T_const is not None


def build_part_map(
    scene: CellScene,
    links: list[BroadLink],
    plan: QueryPlan,
    env: EnvArrays,
    fixed_cache: dict[float, BoolArray],
) -> PartMap:
    """The plan's parts on the broad-phase ``links`` and ``env``'s bodies: thresholds with
    Bullet's margins (see :mod:`planner.cell.broad.broad_phase`), and which self pairs never move
    (asked once, kept in ``fixed_cache`` by look distance)."""
    by_body_link = {(b.body, b.link): k for k, b in enumerate(links)}

    pl, pe, pt, pn, pk, pi = [], [], [], [], [], []
    margin = plan.margin_m
    for part in plan.parts:
        if part.kind == "self":
            continue
        k = by_body_link.get((part.body, part.link), -1)
        e = env.index.get(part.env, -1)
        known = k >= 0 and e >= 0 and _known(links, k)
        infl = (links[k].inflation_m if k >= 0 else 0.0) + (env.inflation_m[e] if e >= 0 else 0.0)
        excess = (links[k].excess_m if k >= 0 else 0.0) + (env.excess_m[e] if e >= 0 else 0.0)
        pl.append(max(k, 0))
        pe.append(max(e, 0))
        pt.append(part.dist_m + infl + SAFETY_M)
        pn.append(part.need_m + margin - excess - SAFETY_M)
        pk.append(known)
        pi.append(part.index)
    self_look = plan.parts[-1].dist_m
    bodies, link_idx, pa, pb_ = scene.checker._self_pair_table()
    ka = [by_body_link.get((bodies[a], link_idx[a]), -1) for a in pa.tolist()]
    kb = [by_body_link.get((bodies[b], link_idx[b]), -1) for b in pb_.tolist()]
    pair_known = [
        a >= 0 and b >= 0 and _known(links, a) and _known(links, b) for a, b in zip(ka, kb)
    ]
    pair_thr = [
        self_look + SAFETY_M + (links[a].inflation_m if a >= 0 else 0.0)
        + (links[b].inflation_m if b >= 0 else 0.0)
        for a, b in zip(ka, kb)
    ]  # fmt: skip
    self_need = plan.parts[-1].need_m
    pair_near = [
        self_need + margin - SAFETY_M - (links[a].excess_m if a >= 0 else 0.0)
        - (links[b].excess_m if b >= 0 else 0.0)
        for a, b in zip(ka, kb)
    ]  # fmt: skip
    fixed = _fixed_pairs_clear(scene, links, ka, kb, pair_known, self_look + SAFETY_M, fixed_cache)
    return PartMap(
        np.array(pl, dtype=np.int64),
        np.array(pe, dtype=np.int64),
        np.array(pt, dtype=float),
        np.array(pn, dtype=float),
        np.array(pk, dtype=bool),
        np.array(pi, dtype=np.int64),
        np.array([max(a, 0) for a in ka], dtype=np.int64),
        np.array([max(b, 0) for b in kb], dtype=np.int64),
        np.array(pair_thr, dtype=float),
        np.array(pair_near, dtype=float),
        np.array(pair_known, dtype=bool),
        fixed,
    )


def _fixed_pairs_clear(
    scene: CellScene,
    links: list[BroadLink],
    ka: list[int],
    kb: list[int],
    known: list[bool],
    look: float,
    cache: dict[float, BoolArray],
) -> BoolArray:
    """Pairs of links on the same joint (they never move against each other) that Bullet
    finds farther apart than ``look`` (asked once per look distance, at the home pose)."""
    key = round(look, 12)
    if key not in cache:
        n_last = scene.chain.n_joints - 1
        out = np.zeros(len(ka), dtype=bool)
        with scene.saved_state():
            scene.set_joint_positions(scene.home_q)
            for s_, (a, b) in enumerate(zip(ka, kb)):
                if not known[s_]:
                    continue
                la, lb_ = links[a], links[b]
                ja = n_last if la.joint is None else la.joint
                jb = n_last if lb_.joint is None else lb_.joint
                if ja != jb:
                    continue
                hits = pb.getClosestPoints(
                    la.body, lb_.body, look, linkIndexA=la.link, linkIndexB=lb_.link,
                    physicsClientId=scene.client,
                )  # fmt: skip
                out[s_] = not hits
        cache[key] = out
    return cache[key].copy()
