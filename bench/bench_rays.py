"""Ray casting for the sensor model: Embree (``planner.sim.raycast``) against PyBullet rayTestBatch.

Both cast the same sensor-like ray bundles (rays along -x from just in front of the side face of
the full stator section, the mesh the Monte Carlo validation uses) in batches of the sizes the
simulation uses, and report rays per second; PyBullet is the reference of the ratio. Also checks
that both agree on hit / miss and on the hit distance.

    python -m bench.bench_rays                  # writes bench/results/rays.json
    python -m bench.bench_rays --rays 200000
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import pybullet as pb

from calib.atomic_io import write_text_atomic
from planner.parts.stator import StatorGeometry
from planner.parts.stator_mesh import build_stator_mesh
from planner.sim.raycast import MeshRayCaster

RESULTS = Path(__file__).resolve().parent / "results"


def _rays(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    y = rng.uniform(-1.0, -0.01, n)
    z = rng.uniform(-0.19, -0.01, n)
    origins = np.column_stack([rng.uniform(0.002, 0.02, n), y, z])
    return origins, np.tile([-1.0, 0.0, 0.0], (n, 1))


def _pybullet_caster(mesh):  # type: ignore[no-untyped-def]
    client = pb.connect(pb.DIRECT)
    shape = pb.createCollisionShape(
        pb.GEOM_MESH,
        vertices=mesh.vertices.tolist(),
        indices=mesh.faces.ravel().tolist(),
        flags=pb.GEOM_FORCE_CONCAVE_TRIMESH,
        physicsClientId=client,
    )
    pb.createMultiBody(0, shape, physicsClientId=client)

    def cast(origins: np.ndarray, dirs: np.ndarray, reach: float = 0.1) -> np.ndarray:
        out = np.full(len(origins), np.inf)
        for i in range(0, len(origins), 8192):  # PyBullet's batch limit
            o, d = origins[i : i + 8192], dirs[i : i + 8192]
            res = pb.rayTestBatch(
                o.tolist(), (o + reach * d).tolist(), numThreads=1, physicsClientId=client
            )
            frac = np.array([r[2] if r[0] >= 0 else np.inf for r in res])
            out[i : i + len(o)] = frac * reach
        return out

    return client, cast


def _time(fn, origins, dirs, batch: int) -> float:  # type: ignore[no-untyped-def]
    t0 = time.perf_counter()
    for i in range(0, len(origins), batch):
        fn(origins[i : i + batch], dirs[i : i + batch])
    return time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; write ``bench/results/rays.json``."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=100_000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    mesh = build_stator_mesh(StatorGeometry.full_section())
    t0 = time.perf_counter()
    caster = MeshRayCaster(mesh)
    build_embree = time.perf_counter() - t0
    t0 = time.perf_counter()
    client, pb_cast = _pybullet_caster(mesh)
    build_pb = time.perf_counter() - t0
    origins, dirs = _rays(rng, args.rays)
    results: dict[str, object] = {
        "rays": args.rays,
        "triangles": len(mesh.faces),
        "build_s": {"embree": build_embree, "pybullet": build_pb},
        "batches": {},
    }
    print(f"{len(mesh.faces)} triangles, {args.rays} rays")
    for batch in (19, 256, 4096):
        t_e = _time(caster.first_hits, origins, dirs, batch)
        t_p = _time(pb_cast, origins, dirs, batch)
        row = {
            "embree_rays_per_s": args.rays / t_e,
            "pybullet_rays_per_s": args.rays / t_p,
            "speedup_embree_over_pybullet": t_p / t_e,
        }
        results["batches"][str(batch)] = row  # type: ignore[index]
        print(
            f"batch {batch:5d}: embree {row['embree_rays_per_s']:12,.0f} rays/s, "
            f"pybullet {row['pybullet_rays_per_s']:12,.0f} rays/s, "
            f"ratio {row['speedup_embree_over_pybullet']:.1f}x"
        )
    d_e = caster.first_hits(origins, dirs)
    d_p = pb_cast(origins, dirs)
    agree = np.isinf(d_e) == np.isinf(d_p)
    both = ~np.isinf(d_e) & ~np.isinf(d_p)
    results["agreement"] = {
        "hit_miss_agree_fraction": float(agree.mean()),
        "max_distance_difference_m": float(np.abs(d_e[both] - d_p[both]).max()),
    }
    print(
        f"hit/miss agree on {agree.mean():.4%}; distances within "
        f"{results['agreement']['max_distance_difference_m']:.2e} m"
    )  # type: ignore[index]
    pb.disconnect(client)
    RESULTS.mkdir(parents=True, exist_ok=True)
    write_text_atomic(RESULTS / "rays.json", json.dumps(results, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
