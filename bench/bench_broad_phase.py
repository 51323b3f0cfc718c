"""How to decide clearance parts fast: the libraries measured for the broad phase.

On the benchmark cell (:mod:`bench.feasibility_cell`: 114,688-triangle box on a table) every
point's first candidate pose is taken (``--n`` points), and each clearance part (a robot or
tool link against the part or the table; self pairs aside) is asked "is anything within the
part's look distance?" five ways, in the same run:

1. ``numba``: the shipped kernel (:func:`planner.cell.kernels.broad_kernels.parts_state`:
   sphere trees against the distance field, GJK on the triangles near the open leaves);
2. ``numpy``: the same sphere leaves against the same field, flat and vectorized (no tree,
   no exact step), what plain numpy gives;
3. ``coal``: ``coal.collide`` with a security margin, one call per part (a BVH of the part's
   triangles, the link's primitive), when coal is installed (``pip install coal``);
4. ``bullet``: the product's exact query, one ``getClosestPoints`` per part (robot placed by
   its joints, tool at the flange);
5. ``trimesh``: exact point-to-mesh distance of the leaf centres (``trimesh.proximity``, rtree);
   embree (trimesh's ray engine) has no distance query.

Reported: microseconds per candidate (all parts), and the share of parts each leaves open.
Run: ``python -m bench.bench_broad_phase [--n 1000]``; writes ``bench/results/broad_phase.json``.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import trimesh
from rich.console import Console
from rich.table import Table

from bench.feasibility_cell import bench_cell, work_object
from calib.atomic_io import write_text_atomic
from planner.cell.broad.broad_phase import broad_phase_of
from planner.cell.probe.probe_candidates import probe_candidates
from planner.cell.probe.reachability import sample_surface
from planner.cell.scene.collision import DEFAULT_MARGIN_M

RESULTS = Path(__file__).resolve().parent / "results" / "broad_phase.json"


def _numpy_states(bp, parts, env, T_links):  # type: ignore[no-untyped-def]
    """Flat numpy version: every leaf of every link against the field / the box."""
    node_c, node_r, node_child, root, _ = bp.tree_arrays()
    kind, Tinv, _, dims, fidx = env.arrays
    f_origin, f_h, f_n, f_off, f_val, f_lo, f_hi = env.fields[:7]
    leaf_of = {}
    for k, b in enumerate(bp.links):
        if b.tree is None:
            continue
        lo = root[k]
        hi = root[k + 1] if k + 1 < len(root) and root[k + 1] > lo else len(node_r)
        leaf_of[k] = np.arange(lo, hi)[node_child[lo:hi] < 0]
    M, P = T_links.shape[0], parts.part_link.size
    out = np.zeros((M, P), dtype=bool)
    for p in range(P):
        link, e, thr = parts.part_link[p], parts.part_env[p], parts.part_thr[p]
        leaves = leaf_of.get(int(link))
        if leaves is None:
            continue
        c = (
            np.einsum("mij,lj->mli", T_links[:, link, :, :3], node_c[leaves])
            + T_links[:, link, None, :, 3]
        )
        x = np.einsum("ij,mlj->mli", Tinv[e, :, :3], c) + Tinv[e, :, 3]
        if kind[e] == 0:
            lb = np.linalg.norm(np.maximum(np.abs(x) - dims[e], 0.0), axis=-1)
        else:
            f = fidx[e]
            box = np.linalg.norm(np.maximum(np.maximum(f_lo[f] - x, x - f_hi[f]), 0.0), axis=-1)
            g = (x - f_origin[f]) / f_h[f]
            i = np.floor(g).astype(int)
            inside = np.all((i >= 0) & (i < f_n[f] - 1), axis=-1)
            i = np.clip(i, 0, f_n[f] - 2)
            t = g - i
            ny, nz = f_n[f, 1], f_n[f, 2]
            base = f_off[f] + (i[..., 0] * ny + i[..., 1]) * nz + i[..., 2]
            val = np.zeros(base.shape)
            for dx in (0, 1):
                for dy in (0, 1):
                    for dz in (0, 1):
                        w = (
                            (t[..., 0] if dx else 1 - t[..., 0])
                            * (t[..., 1] if dy else 1 - t[..., 1])
                            * (t[..., 2] if dz else 1 - t[..., 2])
                        )
                        val += w * f_val[base + (dx * ny + dy) * nz + dz]
            err = f_h[f] * np.sqrt(np.maximum(np.sum(t * (1 - t), axis=-1), 0.0))
            lb = np.where(inside, np.maximum(box, val - err), box)
        out[:, p] = np.all(lb - node_r[leaves] >= thr, axis=1)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    mesh = work_object()
    pts, nrm, _ = sample_surface(mesh, args.n, np.random.default_rng(args.seed))
    rows: dict[str, dict[str, float]] = {}
    with bench_cell(mesh) as cell:
        cands = probe_candidates(
            cell, pts, nrm, cell.T_flange_tcp("sensor"), np.radians(np.arange(0, 360, 15)),
            cell.home_q,
        )  # fmt: skip
        first = cands.first()
        idx = np.flatnonzero(first >= 0)
        c0 = first[idx]
        K = cands.per_rotation
        q, T_bf = cands.q[idx, c0], cands.T_base_flange[idx, c0 // K]
        bp = broad_phase_of(cell)
        plan = cell.checker.plan(DEFAULT_MARGIN_M, cell.self_margin_m, None, True, False)
        env = bp.environment(cell)
        parts = bp.part_map(cell, plan, env)
        T_links = bp.link_poses(cell, q, T_bf)
        M, P = len(idx), parts.part_link.size
        bp.states(parts, env, T_links)  # compiled
        t0 = time.perf_counter()
        states = bp.states(parts, env, T_links)[0]
        rows["numba (shipped)"] = _row(time.perf_counter() - t0, M, states != 1)
        t0 = time.perf_counter()
        flat = _numpy_states(bp, parts, env, T_links)
        rows["numpy (flat leaves)"] = _row(time.perf_counter() - t0, M, ~flat)
        env_parts = [plan.parts[int(i)] for i in parts.part_index]
        t0 = time.perf_counter()
        with cell.saved_state():
            open_ = np.zeros((M, P), bool)
            for m in range(M):
                cell.set_joint_positions(q[m])
                for k, part in enumerate(env_parts):
                    open_[m, k] = cell.checker.evaluate(part) is not None
        rows["bullet (exact query)"] = _row(time.perf_counter() - t0, M, open_)
        rows.update(_coal(bp, parts, env, T_links, mesh, cell))
        leaves = bp.tree_arrays()[0][bp.tree_arrays()[2] < 0]
        sample = (T_links[:50, :, :3, :3] @ leaves[:200].T).transpose(0, 1, 3, 2).reshape(-1, 3)
        t0 = time.perf_counter()
        trimesh.proximity.closest_point(mesh, sample[:2000])
        dt = (time.perf_counter() - t0) / 2000 * len(leaves)
        rows["trimesh (closest point of every leaf centre)"] = {"us_per_candidate": dt * 1e6}
    result = {"bench": "broad_phase", "candidates": M, "parts": P, "rows": rows}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(args.out, json.dumps(result, indent=2, sort_keys=True) + "\n")
    table = Table(title=f"deciding {P} parts of {M} candidate poses (box on a table)")
    for col in ("method", "us / candidate", "parts left open"):
        table.add_column(col)
    for name, r in rows.items():
        table.add_row(
            name, f"{r['us_per_candidate']:.1f}", f"{r.get('open_share', float('nan')):.1%}"
        )
    Console().print(table)
    return 0


def _row(seconds: float, M: int, open_: np.ndarray) -> dict[str, float]:
    return {"us_per_candidate": seconds / M * 1e6, "open_share": float(open_.mean())}


def _coal(bp, parts, env, T_links, mesh, cell) -> dict[str, dict[str, float]]:  # type: ignore[no-untyped-def]
    try:
        import coal
    except ImportError:
        return {}
    t0 = time.perf_counter()
    bvh = coal.BVHModelOBBRSS()
    bvh.beginModel(len(mesh.faces), len(mesh.vertices))
    bvh.addVertices(np.asarray(mesh.vertices, dtype=float))
    bvh.addTriangles(np.asarray(mesh.faces, dtype=np.int32))
    bvh.endModel()
    build = time.perf_counter() - t0
    geoms = []
    for b in bp.links:
        g = []
        for s in b.shapes:
            if s.kind == "box":
                g.append((coal.Box(*s.size_m), s.T_link_shape))
            elif s.kind == "cylinder":
                g.append((coal.Cylinder(s.size_m[0], s.size_m[1]), s.T_link_shape))
        geoms.append(g)
    kind, _, T_env, dims, _ = env.arrays
    env_geom = [bvh if k == 3 else coal.Box(*(2 * d)) for k, d in zip(kind, dims)]
    T_wobj = cell.T_world_wobj
    env_tf = [
        coal.Transform3s(T_wobj[:3, :3], T_wobj[:3, 3])
        if k == 3
        else coal.Transform3s(T[:, :3], T[:, 3])
        for k, T in zip(kind, T_env)
    ]
    M, P = T_links.shape[0], parts.part_link.size
    open_ = np.zeros((M, P), bool)
    res = coal.CollisionResult()
    t0 = time.perf_counter()
    for m in range(M):
        for p in range(P):
            link, e, thr = parts.part_link[p], parts.part_env[p], parts.part_thr[p]
            req = coal.CollisionRequest()
            req.security_margin = float(thr)
            T = T_links[m, link]
            for g, T_ls in geoms[link]:
                Tw = T[:, :3] @ T_ls[:3, :3], T[:, :3] @ T_ls[:3, 3] + T[:, 3]
                res.clear()
                if coal.collide(g, coal.Transform3s(*Tw), env_geom[e], env_tf[e], req, res):
                    open_[m, p] = True
                    break
    return {
        "coal (collide with a security margin)": {
            **_row(time.perf_counter() - t0, M, open_),
            "bvh_build_s": build,
        }
    }


if __name__ == "__main__":
    raise SystemExit(main())
