"""The worst case of probe feasibility: demo-cell points that collide in every pose.

In the demo cell (stator section on a table) ``n`` stator samples are checked one per call
(a UI click); those whose answer is a collision (every candidate collides) are the worst
case, the feasible ones the typical case. Each is checked by ``check_probes`` (the default
path), by ``check_probes(staged=False)`` (one whole Bullet query per candidate: the exact
check) and by the plain PyBullet loop; then all samples as one heat-map batch, both ways;
then the UI's heat map (500 samples at its settings): statuses alone against the full check.
"""

from __future__ import annotations

import time

import numpy as np
from rich.console import Console
from rich.table import Table

from bench.feasibility_cell import run_plain_loop
from planner.cell.cell import Cell
from planner.cell.probe.feasibility import check_probes
from planner.cell.probe.probe_status import probe_statuses
from planner.cell.probe.reachability import reachability_map, sample_surface


def _timed_points(cell: Cell, pts: np.ndarray, nrm: np.ndarray, staged: bool) -> dict:
    """Each point checked alone (one UI click each): per-point seconds and the answers."""
    seconds, answers = [], []
    for i in range(len(pts)):
        t0 = time.perf_counter()
        (r,) = cell.check_probes(pts[i : i + 1], nrm[i : i + 1], staged=staged)
        seconds.append(time.perf_counter() - t0)
        answers.append((r.status, r.reason, r.branch, round(r.clearance_m, 6)))
    return {"seconds": seconds, "answers": answers}


def _summary(seconds: list[float]) -> dict[str, float]:
    s = np.asarray(seconds) * 1e3
    return {"median_ms": float(np.median(s)), "max_ms": float(s.max()), "mean_ms": float(s.mean())}


def run_worst_case(n_samples: int, seed: int) -> dict[str, object]:
    """See the module docstring; per-point medians and maxima, ratios, same answers."""
    from planner.demo import make_demo_cell

    with make_demo_cell() as cell:
        pts, nrm, _ = sample_surface(cell.work_object.mesh, n_samples, np.random.default_rng(seed))
        cell.check_probes(pts[:2], nrm[:2])  # warm-up
        first = _timed_points(cell, pts, nrm, staged=True)
        worst = [i for i, a in enumerate(first["answers"]) if " hits " in a[1]]
        typical = [i for i, a in enumerate(first["answers"]) if a[0] == "feasible"]
        out: dict[str, object] = {"samples": n_samples, "worst_points": len(worst)}
        for name, idx in (("worst", worst), ("typical", typical)):
            if not idx:
                continue
            ours = _timed_points(cell, pts[idx], nrm[idx], staged=True)
            exact = _timed_points(cell, pts[idx], nrm[idx], staged=False)
            row: dict[str, object] = {"ours": _summary(ours["seconds"])}
            row["exact_check"] = _summary(exact["seconds"])
            row["same_answers"] = ours["answers"] == exact["answers"]
            t0 = time.perf_counter()
            run_plain_loop(cell, pts[idx], nrm[idx])
            row["pybullet_loop_ms_per_point"] = 1e3 * (time.perf_counter() - t0) / len(idx)
            out[name] = row
        heat = {}
        for label, staged in (("ours", True), ("exact_check", False)):
            t0 = time.perf_counter()
            reachability_map(cell, n_samples, np.random.default_rng(seed), staged=staged)
            heat[label] = 1e3 * (time.perf_counter() - t0) / n_samples
        out["heat_map_ms_per_sample"] = heat
        out["ui_heat_map"] = _ui_heat_map(cell, seed)
    return out


def _ui_heat_map(cell: Cell, seed: int) -> dict[str, object]:
    """The UI's heat map (its samples and search settings), one batch each way (CPU ms per
    sample, best of 2): the statuses alone (:func:`probe_statuses`, what the UI runs) and the
    full check (:func:`check_probes`, what it ran before); the statuses compared."""
    from webui.heatmap import MAX_CHECKS, N_SAMPLES, ROTATION_STEP_DEG

    pts, nrm, _ = sample_surface(cell.work_object.mesh, N_SAMPLES, np.random.default_rng(seed))
    kw: dict = {"rotation_step_deg": ROTATION_STEP_DEG, "max_checks": MAX_CHECKS}
    ms: dict[str, float] = {}
    for label, fn in (("statuses", probe_statuses), ("full_check", check_probes)):
        best = np.inf
        for _ in range(2):
            c0 = time.process_time()
            res = fn(cell, pts, nrm, **kw)
            best = min(best, time.process_time() - c0)
        ms[label] = 1e3 * best / N_SAMPLES
        if label == "statuses":
            statuses = list(res.statuses)  # type: ignore[union-attr]
        else:
            full = [r.status for r in res]  # type: ignore[union-attr]
    return {
        "samples": N_SAMPLES,
        "cpu_ms_per_sample": ms,
        "ratio": ms["full_check"] / ms["statuses"],
        "different_statuses": sum(a != b for a, b in zip(statuses, full)),
        "statuses": {k: statuses.count(k) for k in sorted(set(statuses))},
    }


def print_worst(w: dict) -> None:
    """A table of :func:`run_worst_case`'s result."""
    table = Table(title=f"demo cell, one point per call ({w['samples']} stator samples)")
    for col in ("points", "n", "ours median / max ms", "exact check median / max ms", "same"):
        table.add_column(col)
    for name in ("worst", "typical"):
        if name not in w:
            continue
        r = w[name]
        table.add_row(
            name,
            str(w["worst_points"]) if name == "worst" else "",
            f"{r['ours']['median_ms']:.1f} / {r['ours']['max_ms']:.0f}",
            f"{r['exact_check']['median_ms']:.1f} / {r['exact_check']['max_ms']:.0f}",
            str(r["same_answers"]),
        )
    Console().print(table)
    h = w["heat_map_ms_per_sample"]
    Console().print(
        f"heat map: {h['ours']:.2f} ms/sample, exact check {h['exact_check']:.1f} ms/sample"
    )
    u = w["ui_heat_map"]
    ms = u["cpu_ms_per_sample"]
    Console().print(
        f"UI heat map ({u['samples']} samples, its settings), CPU per sample: statuses "
        f"{ms['statuses']:.2f} ms, full check {ms['full_check']:.2f} ms = {u['ratio']:.1f}x "
        f"({u['different_statuses']} different statuses; {u['statuses']})"
    )
