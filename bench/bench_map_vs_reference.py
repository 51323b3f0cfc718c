"""The 10,000-sample reachability map against a reference commit, warm and cold, interleaved.

The map of ``bench.bench_feasibility`` (the 114,688-triangle box on its table, the built-in
IRB 4400 with the cable feeder, ``reachability_map(cell, 10000, default_rng(0))``: the same
call in both trees) is run by ``bench/map_child.py`` in a fresh process of each tree (see
``bench.reference_tree``: its own code on the path, its own cache directory):

- **warm**: the caches already filled (an untimed run of each tree first); in the process,
  the cell and a 200-sample map, then ``--inner`` timed maps; a run's figure is the fastest
  of them (as ``bench.bench_feasibility``'s warm map);
- **cold**: a new empty cache directory for every run (no distance field, no allowed-collision
  list, no compiled kernel: numba compiles every kernel, with the background compile helper
  each tree starts by default); the whole command's wall time, as the user waits for it, and
  the child's own seconds from its start to the map (imports, cell, map).

Pairs alternate their order (ours first, then the reference first, ...) so that both sides
meet the same drift of the machine's load; each pair's ratio is reference / ours (> 1: ours
is faster). Every run's map must give the same statuses as the reference's first (the
sample's status bytes hashed): a difference is recorded and fails the bench.

    git worktree add --detach /tmp/wt-ref b68e00a
    git worktree add --detach /tmp/wt-head HEAD
    python -m bench.bench_map_vs_reference --reference /tmp/wt-ref --ours /tmp/wt-head
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import tempfile
from pathlib import Path
from typing import Any

from bench.reference_tree import ROOT, adopt_orphans, run_header, run_in_tree
from bench.result_file import write_result

RESULTS = ROOT / "bench" / "results"
CHILD = str(ROOT / "bench" / "map_child.py")
LOAD_KEYS = ("load_1min_before", "load_1min_after")


def _child(tree: Path, cache: Path, mode: str, samples: int, inner: int) -> dict[str, Any]:
    argv = ["-P", CHILD, "--mode", mode, "--samples", str(samples), "--repeats", str(inner)]
    run = run_in_tree(tree, argv, cache)
    if run["exit_code"] != 0:
        raise SystemExit(f"{tree} {mode} map failed: {run['stderr_last']}")
    out = json.loads(run.pop("stdout").strip().splitlines()[-1])
    run.update(out)
    if mode == "warm":
        run["figure_s"] = min(out["map_wall_s"])
    else:
        run["figure_s"] = run["wall_s"]
    return run


def _summary(pairs: list[dict[str, Any]]) -> dict[str, Any]:
    ratios = [p["ratio"] for p in pairs]
    loads = [p[s][k] for p in pairs for s in ("ours", "reference") for k in LOAD_KEYS]
    return {
        "ours_median_s": statistics.median(p["ours"]["figure_s"] for p in pairs),
        "reference_median_s": statistics.median(p["reference"]["figure_s"] for p in pairs),
        "ratio_median": statistics.median(ratios),
        "ratio_range": [min(ratios), max(ratios)],
        "load_range": [min(loads), max(loads)],
        "same_statuses": all(p["same_statuses"] for p in pairs),
    }


def compare(
    ours: Path, reference: Path, mode: str, samples: int, repeats: int, inner: int, tmp: Path
) -> dict[str, Any]:
    """``repeats`` pairs of one mode, alternating which tree goes first."""
    warm = {ours: tmp / "warm-ours", reference: tmp / "warm-reference"}
    expected = None
    if mode == "warm":  # fill both caches, untimed; the reference's answer is the yardstick
        expected = _child(reference, warm[reference], "warm", samples, 1)["status_sha256"]
        _child(ours, warm[ours], "warm", samples, 1)
    pairs = []
    for k in range(repeats):
        order = (ours, reference) if k % 2 == 0 else (reference, ours)
        got: dict[Path, dict[str, Any]] = {}
        for tree in order:
            if mode == "warm":
                got[tree] = _child(tree, warm[tree], "warm", samples, inner)
            else:
                cache = Path(tempfile.mkdtemp(prefix="cold-", dir=tmp))
                got[tree] = _child(tree, cache, "cold", samples, inner)
                shutil.rmtree(cache, ignore_errors=True)
        a, b = got[ours], got[reference]
        expected = expected or b["status_sha256"]
        pair = {
            "first": "ours" if order[0] == ours else "reference",
            "ours": a,
            "reference": b,
            "ratio": round(b["figure_s"] / a["figure_s"], 3),
            "same_statuses": a["status_sha256"] == b["status_sha256"] == expected,
        }
        pairs.append(pair)
        print(
            f"map {mode} #{k + 1}: ours {a['figure_s']:.2f} s, reference {b['figure_s']:.2f} s,"
            f" ratio {pair['ratio']:.2f}, same statuses {pair['same_statuses']} (load"
            f" {min(a['load_1min_before'], b['load_1min_before']):.1f}-"
            f"{max(a['load_1min_after'], b['load_1min_after']):.1f})",
            flush=True,
        )
    return {"samples": samples, "pairs": pairs, **_summary(pairs)}


def main(argv: list[str] | None = None) -> int:
    """Run the comparison; write ``bench/results/map_vs_<name>.json``."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--reference", type=Path, required=True, help="the reference worktree")
    ap.add_argument("--ours", type=Path, default=ROOT, help="our tree (default: this one)")
    ap.add_argument("--name", default="b68e00a", help="the reference's name in the result file")
    ap.add_argument("--modes", default="warm,cold", help="comma-separated of warm, cold")
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--repeats", type=int, default=3, help="pairs per mode")
    ap.add_argument("--inner", type=int, default=3, help="timed maps per warm process")
    ap.add_argument("--out", type=Path, default=None, help="result file (default by --name)")
    args = ap.parse_args(argv)
    adopt_orphans()  # a fork server's CPU counts too (bench.reference_tree.reap_orphans)
    ours, reference = args.ours.resolve(), args.reference.resolve()
    out_path = args.out or RESULTS / f"map_vs_{args.name}.json"
    result: dict[str, Any] = json.loads(out_path.read_text()) if out_path.exists() else {}
    result.update(run_header(ours, reference, args.name))
    result["call"] = f"reachability_map(bench_cell(), {args.samples}, default_rng(0))"
    with tempfile.TemporaryDirectory(prefix="wobjcal-map-bench-") as tmp:
        for mode in args.modes.split(","):
            result[mode] = compare(
                ours, reference, mode, args.samples, args.repeats, args.inner, Path(tmp)
            )
            write_result(out_path, result, echo=False)
    write_result(out_path, result, echo=False)
    same = all(result[m]["same_statuses"] for m in args.modes.split(","))
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
