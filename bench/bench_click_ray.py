"""What a click ray hits first on the robot (issue 14): PyBullet ``rayTest`` against the cell's
collision bodies (:func:`planner.cell.scene.first_hit`) against trimesh rays on the robot's
visual meshes (one Embree intersector per link, built once; the ray moved into each link's
frame at the click's joint values), on the vendor UR5 of ``../shared/reference`` (STL meshes,
which PyBullet turns into convex hulls), rays aimed at random points around the arm.

    python -m bench.bench_click_ray [--clicks 200]

Prints the median time per click of each, their ratio (same run, same rays), and how often
they agree on hit or miss (they differ where a ray passes a hollow of a link's hull).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import trimesh
import yourdfpy

from bench.result_file import write_result
from calib.frames import invert_transform
from planner.cell.cell import Cell
from planner.cell.scene.ray_hit import first_hit

UR5 = Path(__file__).resolve().parents[2] / "shared" / "reference" / "robots" / "ur5" / "ur5.urdf"

RESULTS = Path(__file__).parent / "results" / "click_ray.json"


def _visual_links(urdf: yourdfpy.URDF) -> dict[str, trimesh.Trimesh]:
    """Each link's visual meshes in its own frame, as one mesh."""
    out: dict[str, trimesh.Trimesh] = {}
    for name, link in urdf.link_map.items():
        parts = []
        for visual in link.visuals:
            if visual.geometry.mesh is None:
                continue
            path = Path(urdf._filename_handler(visual.geometry.mesh.filename))
            mesh = trimesh.load(path, force="mesh")
            T = np.eye(4) if visual.origin is None else visual.origin
            parts.append(mesh.apply_transform(T))
        if parts:
            out[name] = trimesh.util.concatenate(parts)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--clicks", type=int, default=200)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(0)
    cell = Cell(UR5, tool=None)
    q = cell.home_q + np.array([0.3, -1.2, 1.0, -0.8, 0.5, 0.0])
    eye = np.array([1.5, 1.0, 0.8])
    with cell.saved_state():
        cell.set_joint_positions(q)
        joints = np.array([T[:3, 3] for T in cell.link_poses().values()])
    targets = joints[rng.integers(0, len(joints), args.clicks)] + rng.normal(
        0.0, 0.05, (args.clicks, 3)
    )
    dirs = targets - eye

    t_pb, hit_pb = [], []
    for d in dirs:
        t0 = time.perf_counter()
        hit = first_hit(cell, eye, d, q=q)
        t_pb.append(time.perf_counter() - t0)
        hit_pb.append(hit is not None)

    t0 = time.perf_counter()
    urdf = yourdfpy.URDF.load(str(UR5))
    meshes = _visual_links(urdf)
    casters = {n: trimesh.ray.ray_pyembree.RayMeshIntersector(m) for n, m in meshes.items()}
    build_s = time.perf_counter() - t0
    n_tri = sum(len(m.faces) for m in meshes.values())
    T_world_base = cell.T_world_base
    t_tm, hit_tm = [], []
    for d in dirs:
        t0 = time.perf_counter()
        urdf.update_cfg(q)
        any_hit = False
        for name, caster in casters.items():
            T_link_world = invert_transform(T_world_base @ urdf.get_transform(name))
            o = T_link_world[:3, :3] @ eye + T_link_world[:3, 3]
            loc, _, _ = caster.intersects_location(
                [o], [T_link_world[:3, :3] @ d], multiple_hits=False
            )
            any_hit = any_hit or len(loc) > 0
        t_tm.append(time.perf_counter() - t0)
        hit_tm.append(any_hit)
    cell.close()
    result = {
        "clicks": args.clicks,
        "pybullet_median_ms": 1e3 * float(np.median(t_pb)),
        "trimesh_visual_median_ms": 1e3 * float(np.median(t_tm)),
        "trimesh_build_s": build_s,
        "visual_triangles": n_tri,
        "rays_hitting_pybullet": int(sum(hit_pb)),
        "rays_hitting_visual": int(sum(hit_tm)),
        "agree_hit_or_miss": float(np.mean(np.equal(hit_pb, hit_tm))),
    }
    result["ratio_trimesh_over_pybullet"] = (
        result["trimesh_visual_median_ms"] / result["pybullet_median_ms"]
    )
    RESULTS.parent.mkdir(exist_ok=True)
    write_result(RESULTS, result, echo=False)
    for k, v in result.items():
        print(f"{k:32s} {v:.4g}" if isinstance(v, float) else f"{k:32s} {v}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
