"""Probe-pose feasibility near the machine's limit: poses per second, the reachability map, the
worst case, and agreement with the exact check. Both sides of every ratio run in this process.

The cell (:mod:`bench.feasibility_cell`): the built-in IRB 4400 with the cable-feeder tool, a
0.8 x 0.6 x 0.4 m box of 114,688 triangles on a table. Points are sampled uniformly by area on
the whole part (seeded), with their face normals.

1. Throughput (:mod:`bench.feasibility_rates`): poses/s (a TCP target with its sensor
   rotation fixed) and points/s (24 rotations searched), ours (the best of ``--repeat`` batch
   runs) and the plain loop that makes the same decisions (one exact ``check_probes`` call per
   target, also the best of ``--repeat`` runs) on the first ``--loop-n`` poses and half as
   many points; the ratio is of those rates, and the loop's answers are compared with ours.
2. Agreement: ``check_probes(staged=False)`` (one whole Bullet clearance query per candidate,
   the exact check) on all ``--n`` poses and points; any difference in status, reason, branch,
   rotation, clearance pair or clearance (1e-6 m) counts as a disagreement.
3. The map: ``reachability_map`` of ``--map-n`` samples, warm (this process, the best of
   ``--repeat`` runs), and cold in fresh processes (:mod:`bench.feasibility_cold`, two runs
   each, the faster kept): empty disk caches (allowed-collision list, distance field), with
   and without the compiled kernels cached.
4. The worst case (:mod:`bench.feasibility_worst`): demo-cell points that collide in every pose.

Run: ``python -m bench.bench_feasibility [--n 3000] [--loop-n 1000] [--map-n 10000]``; writes
``bench/results/feasibility.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bench.feasibility_cell import bench_cell, work_object
from bench.feasibility_rates import POSE_STEP_DEG, disagreements, run_rates
from bench.feasibility_worst import print_worst, run_worst_case
from calib.atomic_io import write_text_atomic
from planner.cell.broad.broad_phase import broad_phase_of
from planner.cell.kernels.kernel_cache import kernel_cache_dir
from planner.cell.probe.reachability import reachability_map, sample_surface

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench/results/feasibility.json"


def _children_cpu() -> float:
    """CPU seconds (user + system) of this process's finished children."""
    use = resource.getrusage(resource.RUSAGE_CHILDREN)
    return use.ru_utime + use.ru_stime


def _cold(samples: int, seed: int, fresh_kernels: bool, helper: bool = True) -> dict[str, object]:
    """The cold map in a new process with an empty ``WOBJCAL_CACHE_DIR`` (ACL, distance
    field and, unless ``NUMBA_CACHE_DIR`` says otherwise, the compiled kernels); with
    ``fresh_kernels=False`` numba is pointed at this process's (warm) kernel cache (what the
    first use after the install's warm-up finds). ``helper``: the background compile of
    :mod:`planner.cell.kernels.warmup` (the default) or not; the run waits for a helper to finish
    before the next one starts."""
    with tempfile.TemporaryDirectory(prefix="wobjcal_cold_") as tmp:
        env = dict(os.environ, WOBJCAL_CACHE_DIR=str(Path(tmp) / "cache"))
        env["WOBJCAL_BACKGROUND_COMPILE"] = "1" if helper else "0"
        env.pop("NUMBA_CACHE_DIR", None)
        warm = kernel_cache_dir()
        if not fresh_kernels and warm is not None:
            env["NUMBA_CACHE_DIR"] = str(warm)
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
        cmd = [sys.executable, "-m", "bench.feasibility_cold", "--samples", str(samples)]
        t0, cpu0 = time.perf_counter(), _children_cpu()
        out = subprocess.run(
            [*cmd, "--seed", str(seed)], capture_output=True, text=True, env=env, check=True
        )
        wall, cpu = time.perf_counter() - t0, _children_cpu() - cpu0
        numba_dir = Path(tmp) / "cache" / "numba"
        deadline = time.monotonic() + 300
        while fresh_kernels and helper and time.monotonic() < deadline:
            if any(numba_dir.rglob("warm-*")):  # the helper is done
                break
            time.sleep(0.2)
    row = json.loads(out.stdout.strip().splitlines()[-1])
    row["process_wall_s"] = wall
    row["process_cpu_s"] = cpu  # the map's process (not the helper: it is not its parent's)
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=3000, help="probe points for wobjcal")
    ap.add_argument(
        "--loop-n", type=int, default=1000, help="poses for the plain loop (half as many points)"
    )
    ap.add_argument("--repeat", type=int, default=3, help="timed runs of ours (best kept)")
    ap.add_argument("--map-n", type=int, default=10_000, help="samples of the map")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--worst-n", type=int, default=40, help="demo samples for the worst case")
    ap.add_argument("--no-cold", action="store_true", help="skip the cold-start maps")
    ap.add_argument("--out", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    mesh = work_object()
    pts, nrm, _ = sample_surface(mesh, args.n, np.random.default_rng(args.seed))
    with bench_cell(mesh) as cell:
        cell.check_probes(pts[:20], nrm[:20])  # compile / load the kernels, build the field
        rates = run_rates(cell, pts, nrm, args.loop_n, args.repeat)
        agreement = {}
        for unit, kw in (("poses", {"rotation_step_deg": POSE_STEP_DEG}), ("points", {})):
            ours = cell.check_probes(pts, nrm, **kw)
            t0 = time.perf_counter()
            exact = cell.check_probes(pts, nrm, staged=False, **kw)
            dt_exact = time.perf_counter() - t0
            bad = disagreements(ours, exact)
            agreement[unit] = {
                "exact_check_per_s": args.n / dt_exact,
                "disagreements": len(bad),
                "disagreement_points": bad[:20],
            }
        reachability_map(cell, 200, np.random.default_rng(args.seed + 1))  # warm
        map_s, map_cpu = [], []
        for _ in range(args.repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            rmap = reachability_map(cell, args.map_n, np.random.default_rng(args.seed))
            map_s.append(time.perf_counter() - t0)
            map_cpu.append(time.process_time() - c0)
        fields = broad_phase_of(cell).fields
        field_mb = {str(b): f.nbytes / 1e6 for b, f in fields.items()}
        field_build_s = {str(b): f.build_s for b, f in fields.items()}
    result: dict[str, object] = {
        "bench": "feasibility",
        "triangles": len(mesh.faces),
        "seed": args.seed,
        "targets": args.n,
        "rates": rates,
        "agreement": agreement,
        "map_samples": args.map_n,
        "map_warm_s": min(map_s),
        "map_warm_runs_s": map_s,
        "map_warm_cpu_s": min(map_cpu),
        "map_feasible_fraction": rmap.fraction_feasible,
        "distance_field_mb": field_mb,
        "distance_field_build_s": field_build_s,
    }
    if not args.no_cold:
        for key, fresh, helper in (
            ("map_cold_kernels_cached", False, False),
            ("map_cold_everything", True, True),
            ("map_cold_everything_no_helper", True, False),
        ):
            runs = [_cold(args.map_n, args.seed, fresh, helper) for _ in range(2)]
            result[key] = min(runs, key=lambda r: float(r["total_s"]))  # type: ignore[arg-type]
            result[key + "_runs_s"] = [r["total_s"] for r in runs]
    result["worst_case_demo"] = run_worst_case(args.worst_n, args.seed)
    result["machine"] = {
        "python": platform.python_version(),
        "cpu": platform.processor(),
        "load_avg": os.getloadavg(),
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(args.out, json.dumps(result, indent=2, sort_keys=True) + "\n")
    _print(result)
    return 0


def _print(r: dict) -> None:
    t = Table(title=f"probe feasibility, {r['triangles']:,}-triangle part on a table")
    for col in ("", "figure"):
        t.add_column(col)
    for unit, what in (("poses", "rotation fixed"), ("points", "24 rotations searched")):
        s, a = r["rates"][unit], r["agreement"][unit]
        t.add_row(
            f"ours, {s['n']} {unit} ({what})",
            f"{s['ours_per_s']:,.0f} {unit}/s (per CPU second {s['ours_per_cpu_s']:,.0f})",
        )
        t.add_row(
            f"same {s['loop_n']} {unit}: ours / plain loop, same decisions",
            f"{s['ours_on_loop_targets_per_s']:,.0f} / {s['plain_loop_per_s']:,.0f} per s = "
            f"{s['ratio']:.1f}x ({s['loop_disagreements']} different answers)",
        )
        t.add_row(f"exact check, one batch of {unit}", f"{a['exact_check_per_s']:,.0f} {unit}/s")
        t.add_row(f"disagreements with the exact check ({unit})",
                  f"{a['disagreements']} of {r['targets']}")  # fmt: skip
    p = r["rates"]["points"]
    t.add_row(
        "points: PyBullet-IK loop (one branch, no self-collision)",
        f"{p['pybullet_ik_loop_per_s']:,.0f}/s, ours {p['ratio_vs_pybullet_ik_loop']:.1f}x",
    )
    t.add_row(
        f"map of {r['map_samples']:,} samples, warm",
        f"{r['map_warm_s']:.2f} s (CPU {r['map_warm_cpu_s']:.2f} s)",
    )
    for key, label in (
        ("map_cold_kernels_cached", "cold, first use after the warm-up (kernels compiled)"),
        ("map_cold_everything", "cold, everything from scratch (background compile)"),
        ("map_cold_everything_no_helper", "cold, everything from scratch, one process"),
    ):
        if key in r:
            c = r[key]
            t.add_row(
                f"map, {label}", f"{c['total_s']:.2f} s (cell {c['cell_s']:.2f} s, imports "
                f"{c['imports_s']:.2f} s; CPU {c.get('process_cpu_s', float('nan')):.1f} s)",
            )  # fmt: skip
    t.add_row(
        "distance field memory", ", ".join(f"{v:.1f} MB" for v in r["distance_field_mb"].values())
    )
    Console().print(t)
    print_worst(r["worst_case_demo"])


if __name__ == "__main__":
    raise SystemExit(main())
