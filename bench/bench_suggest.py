"""``wobjcal suggest`` on the demo stator: speed, and the proof by simulation (issue 13).

1. Speed: ``suggest_plan`` of the shipped A-H plan's cell (target 0.3 mm), against the
   reference measured in the same run: one ``check_plan`` of the same plan (its cell opened
   the same way). Also the live layout quality (``planner.check.job.plan_quality``, what the UI
   runs after a point moves): ms per change over ``--moves`` moved points.
2. The stator comparison at the paper's eight points: the suggestion (best fit, 8 points)
   against the hand-placed A-H, predicted (the procedure linearised) and simulated
   (``validate_plan``, ``--trials``), and against ``--random`` random feasible 8-point best-fit
   layouts drawn from the same candidate pool (predicted: median and best).
3. The machined plate: the suggestion at the hand-made plan's ten points against that plan,
   predicted and simulated (``--trials``).
4. Error against number of points: the suggestion with 6 ... ``--max`` points (predicted), and
   ``docs/img/suggest_points.png``.

Run: ``python -m bench.bench_suggest [--trials 400] [--random 100] [--max 14]``; writes
``bench/results/suggest.json``.
"""

from __future__ import annotations

import argparse
import math
import platform
import time
from pathlib import Path
from typing import Any

import msgspec
import numpy as np

from bench.result_file import write_result
from calib.plan.file import load_plan
from planner.check.job import check_plan, plan_quality
from planner.suggest import suggest_plan
from planner.validate.job import validate_plan

ROOT = Path(__file__).resolve().parent.parent
PLANS = ROOT / "assets" / "plans"
OUT = ROOT / "bench" / "results" / "suggest.json"
PNG = ROOT / "docs" / "img" / "suggest_points.png"
LEVEL = 95.5


def _simulated(plan: Any, trials: int, keys: list[str]) -> dict[str, float]:
    rep = validate_plan(plan, trials=trials, seed=1, plan_dir=PLANS)
    return {r.key: r.procedure for r in rep.rows if r.key in keys and r.level_percent == LEVEL}


def _live(plan: Any, mesh: Any, rng: np.random.Generator, moves: int) -> dict[str, float]:
    """ms per change of ``plan_quality`` after one approach point moved 3 mm along its face,
    as a drag in the UI."""
    times = []
    for _ in range(moves):
        pts = list(plan.points)
        i = int(rng.integers(len(pts)))
        if pts[i].search.kind == "edge":
            continue
        p = np.asarray(pts[i].position_m) + np.cross(pts[i].normal, rng.normal(size=3)) * 0.003
        pts[i] = msgspec.structs.replace(pts[i], position_m=tuple(float(c) for c in p))
        moved = msgspec.structs.replace(plan, points=pts)
        t = time.perf_counter()
        plan_quality(moved, mesh)
        times.append(time.perf_counter() - t)
    return {
        "median": 1e3 * float(np.median(times)),
        "max": 1e3 * float(np.max(times)),
        "n": len(times),
    }


def _large_part(ah: Any) -> dict[str, Any]:
    """``suggest`` on the 114,688-triangle box of :mod:`bench.feasibility_cell` (file, cell
    and table as a plan), target 0.3 mm at the box's far top corner."""
    import tempfile

    from bench.feasibility_cell import T_WORLD_TABLE, T_WORLD_WOBJ, TABLE_SIZE_M, work_object
    from calib.plan.file import FixtureSpec, Pose, file_sha256

    mesh = work_object()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "box.stl"
        mesh.export(path)
        rep = msgspec.structs.replace
        plan = rep(
            ah,
            work_object=rep(
                ah.work_object,
                mesh="box.stl",
                units="m",
                sha256=file_sha256(path),
                T_world_wobj=Pose(position_m=tuple(float(c) for c in T_WORLD_WOBJ[:3, 3])),
            ),
            cell=rep(
                ah.cell,
                fixtures=[
                    FixtureSpec(
                        name="table",
                        box_size_m=TABLE_SIZE_M,
                        T_world_fixture=Pose(
                            position_m=tuple(float(c) for c in T_WORLD_TABLE[:3, 3])
                        ),
                    )
                ],
            ),
        )
        t = time.perf_counter()
        res = suggest_plan(plan, Path(tmp), target_m=0.3e-3, at_m=np.array([[0.4, 0.3, 0.2]]))
        dt = time.perf_counter() - t
    return {
        "triangles": len(mesh.faces),
        "suggest_s": dt,
        "points": len(res.plan.points),
        "worst_mm": res.worst_m * 1e3,
        "met": res.met,
        "candidates": res.n_candidates,
        "feasible": res.n_feasible,
    }


def _plate(trials: int) -> dict[str, Any]:
    """The machined plate (``plate_holes_best_fit.json``, touch probe, 10 hand-placed points):
    the suggestion at the same number of points against the hand-made plan, predicted and
    simulated (``validate_plan``, ``trials``), at the plan's point of interest."""
    from planner.check.simulatable import check_simulatable, work_object_mesh

    hand = load_plan(PLANS / "plate_holes_best_fit.json")
    mesh = work_object_mesh(hand, PLANS, check_simulatable(hand))
    t = time.perf_counter()
    sug = suggest_plan(hand, PLANS, max_points=len(hand.points))
    dt = time.perf_counter() - t
    out: dict[str, Any] = {"points": len(hand.points), "suggest_s": dt}
    for name, plan in (("hand-made", hand), ("suggested", sug.plan)):
        q, why = plan_quality(plan, mesh)
        assert q is not None, why
        keys = [p.key for p in q.poi]
        out[name] = {
            "n_points": len(plan.points),
            "predicted": {p.key: p.at(LEVEL) * 1e3 for p in q.poi},
            "simulated": _simulated(plan, trials, keys),
        }
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; print a summary and write the JSON."""
    ap = argparse.ArgumentParser(prog="python -m bench.bench_suggest", description=__doc__)
    ap.add_argument("--trials", type=int, default=400)
    ap.add_argument("--random", type=int, default=100)
    ap.add_argument("--max", type=int, default=14)
    ap.add_argument("--moves", type=int, default=20)
    args = ap.parse_args(argv)
    ah = load_plan(PLANS / "stator_section_ah.json")
    out: dict[str, Any] = {"machine": platform.platform(), "level_percent": LEVEL}

    t = time.perf_counter()
    check_plan(ah, PLANS)
    t_check = time.perf_counter() - t
    t = time.perf_counter()
    res = suggest_plan(ah, PLANS, target_m=0.3e-3, max_points=12)
    t_suggest = time.perf_counter() - t
    out["speed"] = {
        "check_s": t_check,
        "suggest_s": t_suggest,
        "ratio": t_suggest / t_check,
        "points": len(res.plan.points),
        "candidates": res.n_candidates,
        "feasible": res.n_feasible,
    }

    # the ~100,000-triangle part: the feasibility benchmark's box on its table, as a plan
    out["large_part"] = _large_part(ah)

    # live quality: move one point of the A-H plan by a few mm, as a drag in the UI
    from planner.check.simulatable import check_simulatable, work_object_mesh

    mesh = work_object_mesh(ah, PLANS, check_simulatable(ah))
    rng = np.random.default_rng(13)
    out["live_quality_ms"] = {
        "A-H (linearised)": _live(ah, mesh, rng, args.moves),
        "suggested best fit (closed form)": _live(res.plan, mesh, rng, args.moves),
    }

    # the stator comparison at eight points
    s8 = suggest_plan(ah, PLANS, max_points=8)
    q_ah, _ = plan_quality(ah, mesh)
    assert q_ah is not None and s8.quality is not None
    keys = [p.key for p in q_ah.poi]
    comp = {
        "A-H": {
            "predicted": {p.key: p.at(LEVEL) * 1e3 for p in q_ah.poi},
            "simulated": _simulated(ah, args.trials, keys),
        },
        "suggested_8": {
            "predicted": {p.key: p.at(LEVEL) * 1e3 for p in s8.quality.poi},
            "simulated": _simulated(s8.plan, args.trials, keys),
        },
    }
    # random 8-point layouts from the same pool of candidates (feasible probe poses; their
    # search paths are not checked: a lower bound on what random placement gives)
    from calib.plan.file import PlanPoint
    from calib.probing import ProbePoint, SearchSpec

    assert s8.pool is not None
    P, N = s8.pool.positions_m, s8.pool.normals
    worst = []
    for _ in range(args.random):
        pick = rng.choice(len(P), size=8, replace=False)
        pts = [
            PlanPoint.from_probe_point(
                ProbePoint(f"R{j + 1}", tuple(P[k]), tuple(N[k]), SearchSpec("approach")), "fit"
            )
            for j, k in enumerate(pick)
        ]
        q, _ = plan_quality(msgspec.structs.replace(s8.plan, points=pts), mesh)
        if q is None or q.rating == "unobservable":
            continue
        worst.append(q.worst_poi_m(LEVEL) * 1e3)
    comp["random_8"] = {
        "n_drawn": args.random,
        "n_observable": len(worst),
        "median_worst_mm": float(np.median(worst)) if worst else math.nan,
        "best_worst_mm": float(np.min(worst)) if worst else math.nan,
    }
    comp["A-H_worst_mm"] = q_ah.worst_poi_m(LEVEL) * 1e3
    comp["suggested_8_worst_mm"] = s8.worst_m * 1e3
    out["stator_8"] = comp

    out["plate_10"] = _plate(args.trials)

    curve = []
    for n in range(6, args.max + 1):
        r = suggest_plan(ah, PLANS, max_points=n)
        curve.append((n, r.worst_m * 1e3))
    out["points_curve"] = curve
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.plot([c[0] for c in curve], [c[1] for c in curve], "o-", label="suggested (best fit)")
        ax.axhline(comp["A-H_worst_mm"], color="r", ls="--", label="A-H (8 points)")
        ax.set_xlabel("points")
        ax.set_ylabel(f"predicted yz error, {LEVEL:g} % (mm)")
        ax.set_title("stator demo: worst point of interest")
        ax.legend()
        fig.tight_layout()
        PNG.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(PNG, dpi=100)
    except ImportError:  # matplotlib is optional
        pass
    OUT.parent.mkdir(parents=True, exist_ok=True)
    write_result(OUT, out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
