"""The reachability map from a cold start: a fresh process, every cache empty.

Run by ``bench.bench_feasibility`` in a subprocess with ``WOBJCAL_CACHE_DIR`` (allowed-collision
lists, distance fields) and, for the fully cold case, ``NUMBA_CACHE_DIR`` (the compiled
kernels) pointing at new empty directories. Prints one JSON line: seconds from the start of
this module (before any project import) to the cell, to the map, and the map's size.

    python -m bench.feasibility_cold --samples 10000 --seed 0
"""

from __future__ import annotations

import time

T0 = time.perf_counter()

import argparse  # noqa: E402
import json  # noqa: E402

import numpy as np  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    from bench.feasibility_cell import bench_cell
    from planner.cell.probe.reachability import reachability_map

    t_import = time.perf_counter() - T0
    with bench_cell() as cell:
        t_cell = time.perf_counter() - T0
        rmap = reachability_map(cell, args.samples, np.random.default_rng(args.seed))
        t_map = time.perf_counter() - T0
    print(
        json.dumps(
            {
                "imports_s": t_import,
                "cell_s": t_cell,
                "total_s": t_map,
                "map_only_s": t_map - t_cell,
                "samples": int(rmap.status.size),
                "feasible_fraction": rmap.fraction_feasible,
            }
        )
    )


if __name__ == "__main__":
    main()
