"""Probe-pose feasibility near the machine's limit: poses per second, the reachability map, the
worst case, and agreement with the exact check. Both sides of every ratio run in this process.

The cell (:mod:`bench.feasibility_cell`): the built-in IRB 4400 with the cable-feeder tool, a
0.8 x 0.6 x 0.4 m box of 114,688 triangles on a table. Points are sampled uniformly by area on
the whole part (seeded), with their face normals.

1. Throughput: ``cell.check_probes`` on ``--n`` points (IK over 24 sensor rotations, limits,
   singularity, clearance with 5 mm against the part and the table and self-collision, with a
   reason for every "no"), the best of ``--repeat`` runs; the plain PyBullet loop
   (:func:`bench.feasibility_cell.run_plain_loop`) on the first ``--loop-n`` of them, and ours
   on those same points; the ratio is of those two rates.
2. Agreement: ``check_probes(staged=False)`` (one whole Bullet clearance query per candidate,
   the exact check) on all ``--n`` points; any difference in status, reason, branch, rotation,
   clearance pair or clearance (1e-6 m) counts as a disagreement.
3. The map: ``reachability_map`` of ``--map-n`` samples, warm (this process), and cold in fresh
   processes (:mod:`bench.feasibility_cold`): empty disk caches (allowed-collision list,
   distance field), with and without the compiled kernels cached.
4. The worst case (:mod:`bench.feasibility_worst`): demo-cell points that collide in every pose.

Run: ``python -m bench.bench_feasibility [--n 3000] [--loop-n 150] [--map-n 10000]``; writes
``bench/results/feasibility.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
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

from bench.feasibility_cell import bench_cell, run_plain_loop, work_object
from bench.feasibility_worst import print_worst, run_worst_case
from calib.atomic_io import write_text_atomic
from planner.cell.broad_phase import broad_phase_of
from planner.cell.cell import Cell
from planner.cell.reachability_map import reachability_map, sample_surface

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench/results/feasibility.json"


def _timed(cell: Cell, pts: np.ndarray, nrm: np.ndarray, repeat: int, **kw: object) -> tuple:
    best, res = np.inf, []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = cell.check_probes(pts, nrm, **kw)
        best = min(best, time.perf_counter() - t0)
    return res, best


def _key(r: object) -> tuple:
    return (r.status, r.reason, r.branch, r.rotation_rad, r.clearance_pair)  # type: ignore[attr-defined]


def disagreements(ours: list, exact: list) -> list[int]:
    """Indices where the answers differ (status, reason, branch, rotation, pair, clearance)."""
    out = []
    for i, (a, b) in enumerate(zip(ours, exact)):
        same = _key(a) == _key(b) or (np.isnan(a.rotation_rad) and _key(a)[:3] == _key(b)[:3])
        ca, cb = a.clearance_m, b.clearance_m
        same = same and ((np.isnan(ca) and np.isnan(cb)) or abs(ca - cb) <= 1e-6)
        if not same:
            out.append(i)
    return out


def _cold(samples: int, seed: int, fresh_kernels: bool) -> dict[str, object]:
    """The cold map in a new process with empty caches (and kernels, when asked)."""
    with tempfile.TemporaryDirectory(prefix="wobjcal_cold_") as tmp:
        env = dict(os.environ, WOBJCAL_CACHE_DIR=str(Path(tmp) / "cache"))
        if fresh_kernels:
            env["NUMBA_CACHE_DIR"] = str(Path(tmp) / "numba")
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
        cmd = [sys.executable, "-m", "bench.feasibility_cold", "--samples", str(samples)]
        t0 = time.perf_counter()
        out = subprocess.run(
            [*cmd, "--seed", str(seed)], capture_output=True, text=True, env=env, check=True
        )
        wall = time.perf_counter() - t0
    row = json.loads(out.stdout.strip().splitlines()[-1])
    row["process_wall_s"] = wall
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=3000, help="probe points for wobjcal")
    ap.add_argument("--loop-n", type=int, default=150, help="points for the plain loop")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs of ours (best kept)")
    ap.add_argument("--map-n", type=int, default=10_000, help="samples of the map")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--worst-n", type=int, default=40, help="demo samples for the worst case")
    ap.add_argument("--no-cold", action="store_true", help="skip the cold-start maps")
    ap.add_argument("--out", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    mesh = work_object()
    pts, nrm, _ = sample_surface(mesh, args.n, np.random.default_rng(args.seed))
    k = min(args.loop_n, args.n)
    with bench_cell(mesh) as cell:
        cell.check_probes(pts[:20], nrm[:20])  # compile / load the kernels, build the field
        ours, dt = _timed(cell, pts, nrm, args.repeat)
        ours_k, dt_k = _timed(cell, pts[:k], nrm[:k], args.repeat)
        t0 = time.perf_counter()
        loop = run_plain_loop(cell, pts[:k], nrm[:k])
        dt_loop = time.perf_counter() - t0
        t0 = time.perf_counter()
        exact = cell.check_probes(pts, nrm, staged=False)
        dt_exact = time.perf_counter() - t0
        bad = disagreements(ours, exact)
        reachability_map(cell, 200, np.random.default_rng(args.seed + 1))  # warm
        t0 = time.perf_counter()
        rmap = reachability_map(cell, args.map_n, np.random.default_rng(args.seed))
        dt_map = time.perf_counter() - t0
        fields = broad_phase_of(cell).fields
        field_mb = {str(b): f.nbytes / 1e6 for b, f in fields.items()}
        field_build_s = {str(b): f.build_s for b, f in fields.items()}
    status = [r.status for r in ours]
    ours_pp = [r.status != "infeasible" for r in ours_k]
    result: dict[str, object] = {
        "bench": "feasibility",
        "triangles": len(mesh.faces),
        "seed": args.seed,
        "points": args.n,
        "poses_per_s": args.n / dt,
        "status_counts": {s: status.count(s) for s in ("feasible", "marginal", "infeasible")},
        "loop_points": k,
        "ours_on_loop_points_per_s": k / dt_k,
        "plain_loop_per_s": k / dt_loop,
        "ratio_same_points": (k / dt_k) / (k / dt_loop),
        "loop_feasible": loop["feasible"],
        "ours_feasible_on_loop_points": sum(ours_pp),
        "only_loop_feasible_our_reasons": [
            ours_k[i].reason for i in range(k) if loop["per_point"][i] and not ours_pp[i]
        ],
        "exact_check_per_s": args.n / dt_exact,
        "disagreements": len(bad),
        "disagreement_points": bad[:20],
        "map_samples": args.map_n,
        "map_warm_s": dt_map,
        "map_feasible_fraction": rmap.fraction_feasible,
        "distance_field_mb": field_mb,
        "distance_field_build_s": field_build_s,
    }
    if not args.no_cold:
        result["map_cold_kernels_cached"] = _cold(args.map_n, args.seed, fresh_kernels=False)
        result["map_cold_everything"] = _cold(args.map_n, args.seed, fresh_kernels=True)
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
    t.add_row(f"wobjcal check_probes ({r['points']} points)", f"{r['poses_per_s']:,.0f} poses/s")
    t.add_row(
        f"same {r['loop_points']} points: wobjcal / plain PyBullet loop",
        f"{r['ours_on_loop_points_per_s']:,.0f} / {r['plain_loop_per_s']:,.0f} per s = "
        f"{r['ratio_same_points']:.1f}x",
    )
    t.add_row("exact check (one Bullet query per candidate)", f"{r['exact_check_per_s']:,.0f}/s")
    t.add_row("disagreements with the exact check", f"{r['disagreements']} of {r['points']}")
    t.add_row(f"map of {r['map_samples']:,} samples, warm", f"{r['map_warm_s']:.2f} s")
    for key, label in (
        ("map_cold_kernels_cached", "cold (empty caches, kernels compiled)"),
        ("map_cold_everything", "cold (everything from scratch)"),
    ):
        if key in r:
            c = r[key]
            t.add_row(
                f"map, {label}", f"{c['total_s']:.2f} s (cell {c['cell_s']:.2f} s, imports "
                f"{c['imports_s']:.2f} s)",
            )  # fmt: skip
    t.add_row(
        "distance field memory", ", ".join(f"{v:.1f} MB" for v in r["distance_field_mb"].values())
    )
    Console().print(t)
    print_worst(r["worst_case_demo"])


if __name__ == "__main__":
    raise SystemExit(main())
