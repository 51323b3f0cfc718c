"""Pairs of one whole command in our tree and a reference's, alternating which goes first.

Shared by ``bench.bench_suggest_vs_reference`` and ``bench.bench_check_vs_reference``: each
pair's ratio is reference / ours wall seconds (> 1: ours is faster), both sides meet the same
drift of the machine's load, and each run's answer (a digest the bench computes) is compared
with the reference's first.
"""

from __future__ import annotations

import statistics
from collections.abc import Callable
from pathlib import Path
from typing import Any

LOAD_KEYS = ("load_1min_before", "load_1min_after")


def interleaved(
    ours: Path,
    reference: Path,
    repeats: int,
    run: Callable[[Path], dict[str, Any]],
    answer: str,
    same: str,
    label: str,
) -> dict[str, Any]:
    """``repeats`` pairs of ``run(tree)`` (a :func:`bench.reference_tree.run_in_tree` record
    with the key ``answer`` added), alternating the order; printed as they go.

    Returns:
        The pairs (their key ``same``: both sides gave the reference's first ``answer`` and
        exit code) and their medians, ratio range and load range.
    """
    pairs: list[dict[str, Any]] = []
    expected: dict[str, Any] | None = None
    for k in range(repeats):
        order = (ours, reference) if k % 2 == 0 else (reference, ours)
        got = {tree: run(tree) for tree in order}
        a, b = got[ours], got[reference]
        expected = expected or b
        pair = {
            "first": "ours" if order[0] == ours else "reference",
            "ours": a,
            "reference": b,
            "ratio": round(b["wall_s"] / a["wall_s"], 3),
            same: a[answer] == b[answer] == expected[answer] and a["exit_code"] == b["exit_code"],
        }
        pairs.append(pair)
        print(
            f"{label} #{k + 1}: ours {a['wall_s']:.1f} s, reference {b['wall_s']:.1f} s,"
            f" ratio {pair['ratio']:.2f}, {same.replace('_', ' ')} {pair[same]} (load"
            f" {min(a['load_1min_before'], b['load_1min_before']):.1f}-"
            f"{max(a['load_1min_after'], b['load_1min_after']):.1f})",
            flush=True,
        )
    ratios = [p["ratio"] for p in pairs]
    loads = [p[s][key] for p in pairs for s in ("ours", "reference") for key in LOAD_KEYS]
    return {
        "pairs": pairs,
        "ours_median_s": statistics.median(p["ours"]["wall_s"] for p in pairs),
        "reference_median_s": statistics.median(p["reference"]["wall_s"] for p in pairs),
        "ratio_median": statistics.median(ratios),
        "ratio_range": [min(ratios), max(ratios)],
        "load_range": [min(loads), max(loads)],
        same: all(p[same] for p in pairs),
    }
