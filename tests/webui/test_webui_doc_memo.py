"""Results kept for a plan object seen before (undo and redo bring the very object back)."""

from __future__ import annotations

import pytest

from webui.doc_memo import DocMemo


def test_only_the_very_object_hits_not_an_equal_copy() -> None:
    memo: DocMemo[str] = DocMemo()
    doc = ("A", "B")
    memo.put(doc, "flags of doc")
    assert memo.get(doc) == "flags of doc"
    assert memo.get(tuple(list(doc))) is None, "an equal plan built apart is not the same plan"


def test_the_tag_is_compared_by_value() -> None:
    memo: DocMemo[int] = DocMemo()
    doc = object()
    memo.put(doc, 1, ("A", 3))
    assert memo.get(doc, ("A", 3)) == 1
    assert memo.get(doc, ("A", 4)) is None and memo.get(doc) is None


def test_the_oldest_used_entry_goes_first() -> None:
    memo: DocMemo[int] = DocMemo(size=2)
    a, b, c = object(), object(), object()
    memo.put(a, 1)
    memo.put(b, 2)
    assert memo.get(a) == 1  # a used last: b is the oldest now
    memo.put(c, 3)
    assert len(memo) == 2 and memo.get(b) is None and memo.get(a) == 1 and memo.get(c) == 3
    memo.clear()
    assert len(memo) == 0 and memo.get(a) is None


def test_a_memo_of_no_entries_is_refused() -> None:
    with pytest.raises(ValueError, match="size: must be >= 1, got 0"):
        DocMemo(size=0)


def test_the_bound_is_size_entries_in_all_not_per_plan_or_point() -> None:
    """Plans times points tags stay within ``size`` entries: the memory does not grow with
    them (one entry per (plan, tag) pair, a put again replaces it)."""
    memo: DocMemo[int] = DocMemo(size=8)
    plans = [object() for _ in range(5)]
    for plan in plans:
        for point in "ABCDEFGH":
            memo.put(plan, 1, (point, 0))
            memo.put(plan, 2, (point, 0))  # the same pair: replaced, not added
        assert len(memo) == 8
    assert [memo.get(plans[-1], (p, 0)) for p in "ABCDEFGH"] == [2] * 8  # the last plan's
    assert all(memo.get(plan, ("A", 0)) is None for plan in plans[:-1])  # the older ones gone
