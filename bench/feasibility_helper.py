"""The background compile helper as the UI meets it: a fresh cache, the cell loaded, a wait.

Run in a fresh process with an empty cache (the helper starts when the first kernel module is
imported), it waits (as a user looks at the scene) until the helper's marker appears or
``--wait`` seconds pass, then runs a map of ``--samples`` and prints one JSON line: when the
cell was ready, when the helper was done, the map's seconds and what numba compiled in this
process after the wait (nothing, when the helper finished first).

    WOBJCAL_CACHE_DIR=$(mktemp -d) python -m bench.feasibility_helper --wait 120
"""

from __future__ import annotations

import time

T0 = time.perf_counter()

import argparse  # noqa: E402
import json  # noqa: E402

import numpy as np  # noqa: E402
from numba.core import event  # noqa: E402


class _Compiles(event.Listener):
    def __init__(self) -> None:
        self.names: set[str] = set()

    def on_start(self, ev: event.Event) -> None:
        self.names.add(ev.data["dispatcher"].py_func.__name__)

    def on_end(self, ev: event.Event) -> None:
        pass


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wait", type=float, default=120.0, help="longest wait for the helper, s")
    ap.add_argument("--samples", type=int, default=500)
    args = ap.parse_args()
    from bench.feasibility_cell import bench_cell
    from planner.cell.kernels.kernel_cache import kernel_cache_dir, marker_path
    from planner.cell.probe.reachability import reachability_map

    cache = kernel_cache_dir()
    with bench_cell() as cell:
        t_cell = time.perf_counter() - T0
        while cache is not None and not marker_path(cache).exists():
            if time.perf_counter() - T0 > args.wait:
                break
            time.sleep(0.2)
        t_ready = time.perf_counter() - T0
        compiles = _Compiles()
        event.register("numba:compile", compiles)
        t1 = time.perf_counter()
        reachability_map(cell, args.samples, np.random.default_rng(0))
        map_s = time.perf_counter() - t1
    done = cache is not None and marker_path(cache).exists()
    print(
        json.dumps(
            {
                "cell_ready_s": t_cell,
                "helper_done_s": t_ready if done else None,
                "map_s": map_s,
                "samples": args.samples,
                "compiled_after_wait": sorted(compiles.names),
            }
        )
    )


if __name__ == "__main__":
    main()
