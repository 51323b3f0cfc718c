"""Monte Carlo validation speed: 400 and 10,000 trials of the demo A-H plan.

The acceptance targets are 400 trials in <= 10 s and 10,000 in <= 120 s on the 2-core machine.
Wall times depend on what else runs, so the JSON also holds references measured in the same
run: the time of one 256-ray bundle cast (machine speed for the hot path), a 1-worker run of the
small case (the parallel speedup), and the CPU time of the large run (its wall time on two free
cores is about half of it). Same seed, same report: the 1- and 2-worker runs of the
small case must give identical errors, which is checked and recorded.

    python -m bench.bench_validate                      # 400 and 10,000 trials
    python -m bench.bench_validate --large 2000         # a shorter large run
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import time
from pathlib import Path

import numpy as np

from calib.atomic_io import write_text_atomic
from calib.models.proximity import ProximitySensor
from planner.parts.stator import StatorGeometry
from planner.parts.stator_demo import nominal_T_base_wobj, stator_ah_points
from planner.parts.stator_mesh import build_stator_mesh
from planner.sim.montecarlo import validate
from planner.sim.raycast import MeshRayCaster

RESULTS = Path(__file__).resolve().parent / "results"


def _bundle_time(mesh, n: int = 2000) -> float:  # type: ignore[no-untyped-def]
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


def _run(n: int, workers: int, seed: int):  # type: ignore[no-untyped-def]
    g = StatorGeometry.full_section()
    c0 = _cpu_s()
    t0 = time.perf_counter()
    report = validate(
        stator_ah_points(g),
        g,
        nominal_T_base_wobj(),
        n,
        np.random.default_rng(seed),
        workers=workers,
    )
    return report, time.perf_counter() - t0, _cpu_s() - c0


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; write ``bench/results/validate.json``."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", type=int, default=400)
    ap.add_argument("--large", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    mesh = build_stator_mesh(StatorGeometry.full_section())
    bundle_s = _bundle_time(mesh)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    small2, t_small2, _ = _run(args.small, 2, args.seed)
    small1, t_small1, cpu_small1 = _run(args.small, 1, args.seed)
    identical = bool(np.array_equal(small1.delta_procedure, small2.delta_procedure))
    large, t_large, cpu_large = _run(args.large, 2, args.seed)
    out = {
        "cpu_count": os.cpu_count(),
        "load_average_1min_at_start": load,
        "reference_256_ray_bundle_s": bundle_s,
        "small": {
            "trials": args.small,
            "wall_s_2_workers": t_small2,
            "wall_s_1_worker": t_small1,
            "cpu_s_1_worker": cpu_small1,
            "parallel_speedup": t_small1 / t_small2,
            "identical_1_vs_2_workers": identical,
            "target_s": 10.0,
        },
        "large": {
            "trials": args.large,
            "wall_s_2_workers": t_large,
            "cpu_s": cpu_large,
            "cpu_ms_per_trial": cpu_large / args.large * 1e3,
            "wall_s_if_2_free_cores": cpu_large / 2,
            "target_s_for_10000": 120.0,
            "scaled_to_10000_s": t_large * 10_000 / args.large,
            "failures": large.failures,
            "n_ok": large.n_ok,
        },
        "trial_cost_in_bundle_casts": (t_small1 / args.small) / bundle_s,
    }
    print(
        f"load {load:.1f}; 256-ray bundle {bundle_s * 1e3:.3f} ms; "
        f"{args.small} trials: {t_small2:.2f} s (2 workers), {t_small1:.2f} s (1 worker), "
        f"identical={identical}; {args.large} trials: {t_large:.1f} s wall, {cpu_large:.1f} s CPU; "
        f"one trial costs "
        f"{out['trial_cost_in_bundle_casts']:.0f} bundle casts"
    )
    print(large.to_markdown())
    RESULTS.mkdir(parents=True, exist_ok=True)
    write_text_atomic(RESULTS / "validate.json", json.dumps(out, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
