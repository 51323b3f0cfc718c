"""Edge events of the proximity sensor: plain rays against rays resolved between (issue 13).

1. One edge search over a 0.4 m plate toward its straight edge, the plate turned to 72 angles
   about the sensor axis (no noise): the event against the exact disk's offset (1 sigma and
   worst, mm) and the time per search, at 256, 512 and 1,024 rays, with plain rays (each ray
   switches at once) and resolved between rays (``planner.sim.subray``). Reference measured in
   the same run: plain rays at 256 (the time ratios).
2. The thin box (200 x 300 x 10 mm, sides too thin for the footprint) of
   ``tests/planner/suggest/test_suggest_edges.py``: its suggested plan (4 approaches + 4 edge
   searches)
   validated with ``--trials`` trials at 256, 512 and 1,024 rays: ms per trial (ratio against
   256 in the same run) and simulated / predicted of the 95.5 % rows (smallest and largest).

Run: ``python -m bench.bench_edge_events [--trials 300]``; writes
``bench/results/edge_events.json``.
"""

from __future__ import annotations

import argparse
import math
import platform
import tempfile
import time
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import trimesh

from bench.result_file import write_result
from calib.frames import make_transform, matrix_from_rotvec
from calib.models.proximity import ProximitySensor
from calib.models.robot_error import RobotErrorModel
from calib.plan.base import file_sha256
from calib.plan.file import load_plan
from calib.probing import ProbePoint, SearchCommand, SearchSpec
from planner.sim.proximity import SimulatedProbe
from planner.sim.raycast import MeshRayCaster

ROOT = Path(__file__).resolve().parent.parent
PLANS = ROOT / "assets" / "plans"
OUT = ROOT / "bench" / "results" / "edge_events.json"
RAYS = (256, 512, 1024)
INSET_M = 0.003


def _events(n_rays: int, between: bool, angles: np.ndarray) -> dict[str, float]:
    plate = trimesh.creation.box(extents=(0.4, 0.4, 0.01))
    plate.apply_translation((0.0, -0.2, -0.005))
    caster = MeshRayCaster(plate)
    sensor = ProximitySensor(repeatability_sigma_m=0.0, n_rays=n_rays)
    exact = sensor.edge_event_offset_m(INSET_M)
    point = ProbePoint(
        "f", (0.0, 0.0, 0.0), (0, 0, 1), SearchSpec("edge", 0.05, 0.03, (0, 1, 0)), (0, 1, 0)
    )
    err, t_total = [], 0.0
    for a in angles:
        T = make_transform(matrix_from_rotvec([0.0, 0.0, float(a)]), [0.0, 0.0, 0.0])
        probe = SimulatedProbe(
            caster,
            T,
            np.random.default_rng(0),
            sensor=sensor,
            robot_error=RobotErrorModel.none(),
            edge_inset_m=INSET_M,
            between_rays=between,
        )
        cmd = SearchCommand.from_point(point, T)
        t = time.perf_counter()
        res = probe(cmd)
        t_total += time.perf_counter() - t
        assert res.point_m is not None, res.reason
        err.append((np.linalg.inv(T) @ np.append(res.point_m, 1.0))[1] - exact)
    e = np.array(err) * 1e3
    return {
        "sigma_mm": float(e.std()),
        "worst_mm": float(np.abs(e).max()),
        "mean_mm": float(e.mean()),
        "ms_per_search": t_total / len(angles) * 1e3,
    }


def _thin_box(trials: int) -> dict[str, Any]:
    from planner.suggest import suggest_plan
    from planner.validate.job import validate_plan

    folder = Path(tempfile.mkdtemp(prefix="wobjcal_bench_"))
    box = trimesh.creation.box(extents=(200.0, 300.0, 10.0))
    box.apply_translation(np.array((200.0, 300.0, 10.0)) / 2)
    stl = folder / "thin_box.stl"
    box.export(stl)
    plate = load_plan(PLANS / "plate_holes_best_fit.json")
    sensor = load_plan(PLANS / "stator_section_ah.json").validation.sensor
    wo = msgspec.structs.replace(plate.work_object, mesh=str(stl), sha256=file_sha256(stl))
    v = msgspec.structs.replace(plate.validation, sensor=sensor)
    plan = suggest_plan(
        msgspec.structs.replace(plate, work_object=wo, validation=v), PLANS, max_points=8
    ).plan
    out: dict[str, Any] = {"points": [f"{p.id}:{p.search.kind}" for p in plan.points]}
    for n in RAYS:
        s = msgspec.structs.replace(plan.validation.sensor, n_rays=n)
        p = msgspec.structs.replace(plan, validation=msgspec.structs.replace(v, sensor=s))
        t = time.perf_counter()
        rep = validate_plan(p, trials=trials, seed=7, workers=1, plan_dir=PLANS)
        dt = time.perf_counter() - t
        ratio = {
            r.key: r.procedure / r.procedure_predicted
            for r in rep.rows
            if r.level_percent == 95.5 and r.procedure_predicted
        }
        out[str(n)] = {
            "ms_per_trial": dt / trials * 1e3,
            "failures": dict(rep.failures),
            "sim_over_pred": ratio,
            "min": min(ratio.values()),
            "max": max(ratio.values()),
        }
    base = out[str(RAYS[0])]["ms_per_trial"]
    for n in RAYS:
        out[str(n)]["time_vs_256"] = out[str(n)]["ms_per_trial"] / base
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; print the JSON and write it."""
    ap = argparse.ArgumentParser(prog="python -m bench.bench_edge_events", description=__doc__)
    ap.add_argument("--trials", type=int, default=300)
    args = ap.parse_args(argv)
    angles = np.linspace(0.0, 2 * math.pi, 73)[:-1]
    out: dict[str, Any] = {"machine": platform.platform(), "events": {}}
    _events(256, True, angles[:4])  # warm the caster and the sunflower caches
    for n in RAYS:
        for between in (False, True):
            out["events"][f"{n} {'between' if between else 'plain'}"] = _events(n, between, angles)
    ref = out["events"]["256 plain"]["ms_per_search"]
    for row in out["events"].values():
        row["time_vs_256_plain"] = row["ms_per_search"] / ref
    out["thin_box"] = _thin_box(args.trials)
    write_result(OUT, out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
