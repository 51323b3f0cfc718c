"""One reachability map in a fresh process, for ``bench.bench_map_vs_reference``.

Run as a file with ``python3 -P bench/map_child.py`` (``-P``: not this folder on the path), the
working directory and ``PYTHONPATH`` set to the tree under test, so that ``planner`` and
``bench.feasibility_cell`` come from that tree: this file imports nothing of the project at
the top and uses only what the reference commit has too (``bench.feasibility_cell.bench_cell``,
``planner.cell.probe.reachability.reachability_map``, before issue 23's
subpackages ``planner.cell.reachability_map.reachability_map``). Prints one JSON line.

``--mode cold``: the whole cold command as ``bench.feasibility_cold`` times it: seconds from
the start of this file (before any project import) to the map done. ``--mode warm``: the cell
and a 200-sample map first (everything loaded, compiled and built), then ``--repeats`` timed
maps of ``--samples`` in this process, as ``bench.bench_feasibility`` times its warm map.
"""

from __future__ import annotations

import time

T0 = time.perf_counter()

import argparse  # noqa: E402
import hashlib  # noqa: E402
import json  # noqa: E402
import os  # noqa: E402
import resource  # noqa: E402

import numpy as np  # noqa: E402


def _cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _digest(rmap: object) -> dict[str, object]:
    """What must not change: the status of every sample, hence the feasible set."""
    status = np.asarray(rmap.status, dtype=np.int8)  # type: ignore[attr-defined]
    return {
        "samples": int(status.size),
        "feasible": int((status >= 1).sum()),
        "status_counts": [int((status == k).sum()) for k in range(3)],
        "status_sha256": hashlib.sha256(status.tobytes()).hexdigest()[:16],
        "feasible_sha256": hashlib.sha256((status >= 1).tobytes()).hexdigest()[:16],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mode", choices=("cold", "warm"), required=True)
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    import planner
    from bench.feasibility_cell import bench_cell

    try:
        from planner.cell.probe.reachability import reachability_map
    except ImportError:  # a reference commit from before planner/cell's subpackages
        from planner.cell.reachability_map import reachability_map  # type: ignore

    t_import = time.perf_counter() - T0
    out: dict[str, object] = {"planner": planner.__file__, "imports_s": round(t_import, 3)}
    with bench_cell() as cell:
        t_cell = time.perf_counter() - T0
        out["cell_s"] = round(t_cell, 3)
        if args.mode == "cold":
            rmap = reachability_map(cell, args.samples, np.random.default_rng(args.seed))
            t_map = time.perf_counter() - T0
            out["total_s"] = round(t_map, 3)
            out["map_only_s"] = round(t_map - t_cell, 3)
            out["cpu_s"] = round(_cpu_s(), 3)
        else:
            reachability_map(cell, 200, np.random.default_rng(args.seed + 1))
            walls, cpus = [], []
            for _ in range(args.repeats):
                c0, t0 = _cpu_s(), time.perf_counter()
                rmap = reachability_map(cell, args.samples, np.random.default_rng(args.seed))
                walls.append(round(time.perf_counter() - t0, 4))
                cpus.append(round(_cpu_s() - c0, 4))
            out["map_wall_s"] = walls
            out["map_cpu_s"] = cpus
    out.update(_digest(rmap))
    out["load_1min_end"] = round(os.getloadavg()[0], 2)
    print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
