"""Monte Carlo validation speed and the prediction's agreement with the simulation.

Three parts, each written to ``bench/results/validate.json``:

1. ``stator``: 400 and 10,000 trials of the demo A-H plan (the paper's stator, 65 k triangles),
   as the benchmark always ran it, so the time can be compared with earlier runs.
2. ``best_fit_100k``: 400 and 10,000 trials of the 10-point best-fit plan of the machined plate
   (``assets/plans/plate_holes_best_fit.json``, touch probe) on the plate's mesh subdivided to
   about 100,000 triangles (targets: 400 in <= 10 s, 10,000 in <= 120 s on 2 cores).
3. ``box`` (``--box N``): every estimator on the ideal box of :mod:`bench.box_plans`, N trials,
   simulated / predicted - 1 for every row (done when: within 5 %); the A-H plan once with a
   point sensor and once with the 18 mm face sampled by 16,384 rays.

Wall times depend on what else runs, so the JSON also holds references measured in the same
run: the time of one 256-ray bundle cast on the stator (machine speed for the hot path), a
1-worker run of the small case (parallel speedup and same-seed identity), and CPU seconds.

    python -m bench.bench_validate                       # stator and best fit, 400 and 10,000
    python -m bench.bench_validate --large 2000 --box 0  # a shorter run, no box
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import time
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from bench.box_plans import FINE_SENSOR, POINT_SENSOR, agreement, box_mesh, box_plans
from calib.atomic_io import write_text_atomic
from calib.models.proximity import ProximitySensor
from calib.plan.file import load_plan
from planner.parts.stator import StatorGeometry
from planner.parts.stator_demo import nominal_T_base_wobj, stator_ah_points
from planner.parts.stator_mesh import build_stator_mesh
from planner.sim.montecarlo import simulate_stator_ah
from planner.sim.raycast import MeshRayCaster
from planner.validate.job import validate_plan

RESULTS = Path(__file__).resolve().parent / "results"
PLATE_PLAN = (
    Path(__file__).resolve().parent.parent / "assets" / "plans" / "plate_holes_best_fit.json"
)


def _bundle_time(mesh: trimesh.Trimesh, n: int = 2000) -> float:
    """Seconds per 256-ray sensor bundle cast at the side face (the hot path's unit)."""
    caster = MeshRayCaster(mesh)
    s = ProximitySensor()
    axis = np.array([-1.0, 0.0, 0.0])
    rng = np.random.default_rng(0)
    tcps = np.column_stack(
        [np.full(n, 0.01), rng.uniform(-0.9, -0.1, n), rng.uniform(-0.18, -0.02, n)]
    )
    dirs = np.tile(axis, (s.n_rays, 1))
    t0 = time.perf_counter()
    for tcp in tcps:
        caster.first_hits(s.ray_origins(tcp, axis), dirs)
    return (time.perf_counter() - t0) / n


def _cpu_s() -> float:
    """CPU seconds used so far by this process and its finished children."""
    me, kids = (
        resource.getrusage(resource.RUSAGE_SELF),
        resource.getrusage(resource.RUSAGE_CHILDREN),
    )
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _timed(fn: Any) -> tuple[Any, float, float]:
    c0, t0 = _cpu_s(), time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0, _cpu_s() - c0


def _stator(n: int, workers: int, seed: int) -> Any:
    g = StatorGeometry.full_section()
    return simulate_stator_ah(
        stator_ah_points(g),
        g,
        nominal_T_base_wobj(),
        n,
        np.random.default_rng(seed),
        workers=workers,
    )


def dense_plate(target_triangles: int = 100_000) -> trimesh.Trimesh:
    """The plate of the best-fit plan, its triangles split to about ``target_triangles``."""
    from planner.cell.scene.workobject import load_work_object

    plan = load_plan(PLATE_PLAN)
    ref = PLATE_PLAN.parent / plan.work_object.mesh
    mesh = load_work_object(ref, units=plan.work_object.units).mesh
    edge = 0.02
    while True:
        v, f = trimesh.remesh.subdivide_to_size(mesh.vertices, mesh.faces, max_edge=edge)
        if len(f) >= target_triangles:
            return trimesh.Trimesh(v, f, process=False)
        edge *= 0.9


def _case(name: str, run: Any, small: int, large: int, seed: int) -> dict[str, Any]:
    r2, t2, _ = _timed(lambda: run(small, 2, seed))
    r1, t1, c1 = _timed(lambda: run(small, 1, seed))
    big, tl, cl = _timed(lambda: run(large, 2, seed))
    out = {
        "small": {
            "trials": small,
            "wall_s_2_workers": t2,
            "wall_s_1_worker": t1,
            "cpu_s_1_worker": c1,
            "parallel_speedup": t1 / t2,
            "identical_1_vs_2_workers": bool(
                np.array_equal(r1.delta_procedure, r2.delta_procedure)
            ),
            "target_s": 10.0,
        },
        "large": {
            "trials": large,
            "wall_s_2_workers": tl,
            "cpu_s": cl,
            "cpu_ms_per_trial": cl / large * 1e3,
            "wall_s_if_2_free_cores": cl / 2,
            "target_s_for_10000": 120.0,
            "scaled_to_10000_s": tl * 10_000 / large,
            "failures": big.failures,
            "n_ok": big.n_ok,
        },
    }
    print(
        f"{name}: {small} trials {t2:.2f} s (2 workers), {t1:.2f} s (1 worker); "
        f"{large} trials {tl:.1f} s wall, {cl:.1f} s CPU"
    )
    print(big.to_markdown())
    return out


def _box(n: int, seed: int) -> dict[str, Any]:
    mesh = box_mesh()
    out: dict[str, Any] = {"trials": n}
    cases = {m: p for m, p in box_plans(POINT_SENSOR).items()}
    cases["hultman2013_18mm_16384_rays"] = box_plans(FINE_SENSOR)["hultman2013"]
    for name, plan in cases.items():
        trials = n if "16384" not in name else max(2, n // 5)
        rep, wall, _ = _timed(
            lambda p=plan, k=trials: validate_plan(p, trials=k, seed=seed, mesh=mesh)
        )
        rel = agreement(rep)
        out[name] = {
            "trials": trials,
            "wall_s": wall,
            "simulated_over_predicted_minus_1": rel,
            "worst": max(abs(v) for v in rel.values()),
        }
        print(f"box {name}: {trials} trials, worst |sim/pred - 1| = {out[name]['worst']:.3f}")
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; write ``bench/results/validate.json``."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", type=int, default=400)
    ap.add_argument("--large", type=int, default=10_000)
    ap.add_argument("--box", type=int, default=10_000, help="box trials per estimator (0: skip)")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    stator_mesh = build_stator_mesh(StatorGeometry.full_section())
    bundle_s = _bundle_time(stator_mesh)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    out: dict[str, Any] = {
        "cpu_count": os.cpu_count(),
        "load_average_1min_at_start": load,
        "reference_256_ray_bundle_s": bundle_s,
    }
    out["stator"] = _case("stator A-H", _stator, args.small, args.large, args.seed)
    plate = load_plan(PLATE_PLAN)
    mesh = dense_plate()
    out["best_fit_100k"] = {"triangles": len(mesh.faces)} | _case(
        f"plate best fit, {len(mesh.faces)} triangles",
        lambda n, w, s: validate_plan(
            plate, trials=n, seed=s, workers=w, mesh=mesh, plan_dir=PLATE_PLAN.parent
        ),
        args.small,
        args.large,
        args.seed,
    )
    out["stator"]["trial_cost_in_bundle_casts"] = (
        out["stator"]["small"]["wall_s_1_worker"] / args.small
    ) / bundle_s
    if args.box:
        out["box"] = _box(args.box, args.seed)
    RESULTS.mkdir(parents=True, exist_ok=True)
    write_text_atomic(RESULTS / "validate.json", json.dumps(out, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
