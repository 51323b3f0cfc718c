"""Run every benchmark in turn: ``python -m bench`` (add ``--quick`` for smaller sizes).

Each benchmark writes its JSON into ``bench/results/`` and prints a short table; see
``bench/README.md`` for what each measures and against which reference.
"""

from __future__ import annotations

import argparse
import subprocess
import sys

#: (module, full-size arguments, quick arguments)
BENCHMARKS: list[tuple[str, list[str], list[str]]] = [
    ("bench.bench_ik", [], ["--n", "2000"]),
    ("bench.bench_feasibility", [], ["--n", "500", "--loop-n", "50", "--map-n", "2000"]),
    ("bench.bench_broad_phase", [], ["--n", "300"]),
    ("bench.bench_rays", [], ["--rays", "20000"]),
    ("bench.bench_validate", [], ["--small", "100", "--large", "400"]),
    ("bench.bench_ui_latency", ["--browser"], ["--clicks", "10"]),
    (
        "bench.bench_ui_render",
        [],
        ["--clicks", "4", "--refs", "4", "--order", "baseline", "ours"],
    ),
    ("bench.bench_suggest", [], ["--trials", "100", "--random", "30", "--max", "10"]),
    ("bench.bench_click_ray", [], ["--clicks", "50"]),
    ("bench.bench_edge_events", [], ["--trials", "100"]),
]


def main(argv: list[str] | None = None) -> int:
    """Run the benchmarks one after another; return the number that failed."""
    ap = argparse.ArgumentParser(prog="python -m bench", description=__doc__)
    ap.add_argument("--quick", action="store_true", help="smaller sizes (a minute or two)")
    ap.add_argument("only", nargs="*", help="run only these (e.g. bench_ik bench_rays)")
    args = ap.parse_args(argv)
    failed = 0
    for module, full, quick in BENCHMARKS:
        if args.only and module.split(".")[-1] not in args.only:
            continue
        cmd = [sys.executable, "-m", module, *(quick if args.quick else full)]
        print(f"\n== {' '.join(cmd[1:])}", flush=True)
        if subprocess.run(cmd, check=False).returncode != 0:
            failed += 1
            print(f"!! {module} failed", flush=True)
    return failed


if __name__ == "__main__":
    sys.exit(main())
