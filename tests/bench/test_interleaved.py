"""``bench.interleaved``: pairs alternate which tree runs first, ratios are reference / ours,
and an answer that differs from the reference's first is said."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from bench.interleaved import interleaved

OURS, REF = Path("/ours"), Path("/ref")


def _runner(
    walls: dict[Path, list[float]], answers: dict[Path, list[str]], codes: tuple[int, ...] = ()
) -> Any:
    order: list[Path] = []

    def run(tree: Path) -> dict[str, Any]:
        k = sum(t == tree for t in order)
        order.append(tree)
        return {
            "wall_s": walls[tree][k],
            "exit_code": codes[k] if tree == OURS and codes else 0,
            "load_1min_before": 1.0 + k,
            "load_1min_after": 1.5 + k,
            "digest": answers[tree][k],
        }

    return run, order


def test_pairs_alternate_and_ratios_are_reference_over_ours() -> None:
    run, order = _runner(
        {OURS: [2.0, 4.0, 1.0], REF: [6.0, 4.0, 3.0]}, {OURS: ["a"] * 3, REF: ["a"] * 3}
    )
    out = interleaved(OURS, REF, 3, run, "digest", "same_digest", "t")
    assert order == [OURS, REF, REF, OURS, OURS, REF]
    assert [p["ratio"] for p in out["pairs"]] == [3.0, 1.0, 3.0]
    assert [p["first"] for p in out["pairs"]] == ["ours", "reference", "ours"]
    assert out["ratio_median"] == 3.0 and out["ratio_range"] == [1.0, 3.0]
    assert out["ours_median_s"] == 2.0 and out["load_range"] == [1.0, 3.5]
    assert out["same_digest"] is True


def test_an_answer_unlike_the_references_first_is_said() -> None:
    run, _ = _runner({OURS: [1.0, 1.0], REF: [1.0, 1.0]}, {OURS: ["a", "b"], REF: ["a", "a"]})
    out = interleaved(OURS, REF, 2, run, "digest", "same_digest", "t")
    assert [p["same_digest"] for p in out["pairs"]] == [True, False]
    assert out["same_digest"] is False


def test_the_same_answer_with_another_exit_code_is_not_the_same() -> None:
    run, _ = _runner({OURS: [1.0, 1.0], REF: [1.0, 1.0]}, {OURS: ["a"] * 2, REF: ["a"] * 2}, (0, 1))
    out = interleaved(OURS, REF, 2, run, "digest", "same_digest", "t")
    assert [p["same_digest"] for p in out["pairs"]] == [True, False]
