"""``wobjcal sweep`` speed: placements of the demo cell checked on 1 and 2 Dask workers.

Three runs of :func:`planner.sweep.run_sweep` on the same plan and seed, each into a fresh
folder:

1. ``serial``: ``--serial`` placements in this process (``workers=0``): the reference, the
   cost of one placement's check with nothing of Dask around it (the first placement, which
   builds the process's caches, is timed apart as ``cold``);
2. ``workers_1``: ``--samples-1`` placements on a local cluster of one worker process;
3. ``workers_2``: ``--samples`` placements on two worker processes.

Speed is reported as ratios against the reference measured in the same run: the per-placement
cost of each run over the serial one, and the speedup of 2 workers over 1. The peak resident
memory of each worker process is sampled every 0.2 s (psutil), and the load average
(``os.getloadavg``) is recorded before and after. The rows of the runs must be the same where
they overlap (checked: a sweep's row is its placement's, whichever way it ran).

    python -m bench.bench_sweep                                  # the stator, 200 / 100 / 3
    python -m bench.bench_sweep --plan assets/plans/plate_holes_321.json --samples 40
"""

from __future__ import annotations

import argparse
import os
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import psutil

from bench.result_file import write_result
from planner.sweep import run_sweep
from planner.sweep.files import read_rows

ROOT = Path(__file__).resolve().parent.parent
RESULTS = Path(__file__).resolve().parent / "results"
STATOR = ROOT / "assets" / "plans" / "stator_section_ah.json"


class PeakMemory:
    """The peak resident set size of every child process of this one, sampled in a thread."""

    def __init__(self, period_s: float = 0.2) -> None:
        self.period_s = period_s
        self.peak: dict[int, int] = {}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        me = psutil.Process()
        while not self._stop.is_set():
            for child in me.children(recursive=True):
                try:
                    rss = child.memory_info().rss
                except psutil.Error:
                    continue
                self.peak[child.pid] = max(self.peak.get(child.pid, 0), rss)
            self._stop.wait(self.period_s)

    def __enter__(self) -> PeakMemory:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()


def _run(plan: Path, out: Path, samples: int, workers: int, seed: int) -> dict[str, Any]:
    with PeakMemory() as mem:
        t0 = time.perf_counter()
        result = run_sweep(plan, out, samples=samples, seed=seed, workers=workers)
        wall = time.perf_counter() - t0
    peaks = sorted(mem.peak.values(), reverse=True)
    return {
        "samples": samples,
        "workers": workers,
        "wall_s": wall,
        "per_placement_s": wall / samples,
        "feasible": result.feasible,
        "errors": result.errors,
        # the worker processes are the largest children (a nanny is ~100 MB)
        "worker_peak_rss_mib": [round(p / 2**20) for p in peaks[: max(workers, 0)]],
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plan", type=Path, default=STATOR)
    ap.add_argument("--samples", type=int, default=200, help="placements on 2 workers")
    ap.add_argument("--samples-1", type=int, default=100, help="placements on 1 worker")
    ap.add_argument("--serial", type=int, default=3, help="placements in this process")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        base = Path(tmp)
        t0 = time.perf_counter()
        run_sweep(args.plan, base / "cold", samples=1, seed=args.seed, workers=0)
        cold = time.perf_counter() - t0
        serial = _run(args.plan, base / "serial", args.serial, 0, args.seed)
        one = _run(args.plan, base / "w1", args.samples_1, 1, args.seed)
        two = _run(args.plan, base / "w2", args.samples, 2, args.seed)
        rows = {k: read_rows(base / k / "sweep.csv") for k in ("serial", "w1", "w2")}
        same = all(rows[k][i] == rows["w2"][i] for k in ("serial", "w1") for i in rows[k])
    ref = serial["per_placement_s"]
    result = {
        "plan": str(args.plan.relative_to(ROOT) if args.plan.is_relative_to(ROOT) else args.plan),
        "seed": args.seed,
        "cpus": os.cpu_count(),
        "load_before": load_before,
        "load_after": os.getloadavg(),
        "cold_first_placement_s": cold,
        "serial": serial,
        "workers_1": one | {"cost_vs_serial": one["per_placement_s"] / ref},
        "workers_2": two | {"cost_vs_serial": two["per_placement_s"] / ref},
        "speedup_2_over_1": one["per_placement_s"] / two["per_placement_s"],
        "rows_identical": same,
    }
    write_result(RESULTS / "sweep.json", result)
    print("| run | placements | wall s | s per placement | vs serial | worker peak RSS MiB |")
    print("|---|---|---|---|---|---|")
    for name, r in (("serial (in process)", serial), ("1 worker", one), ("2 workers", two)):
        print(
            f"| {name} | {r['samples']} | {r['wall_s']:.1f} | {r['per_placement_s']:.2f} | "
            f"{r['per_placement_s'] / ref:.2f} | {r['worker_peak_rss_mib'] or '-'} |"
        )
    print(f"speedup 2 over 1 worker: {result['speedup_2_over_1']:.2f}; rows identical: {same}")
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
