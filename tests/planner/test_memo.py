"""planner.memo: a bounded memo, safe across threads."""

from __future__ import annotations

import threading

import pytest

from planner.memo import Memo


def test_the_oldest_value_goes_first_and_the_first_stored_stays() -> None:
    memo: Memo[str, int] = Memo(2)
    assert memo.get("a") is None
    assert memo.put("a", 1) == 1 and memo.put("b", 2) == 2
    assert memo.put("a", 10) == 1  # another thread's value for the same content: the first kept
    memo.put("c", 3)
    assert (memo.get("a"), memo.get("b"), memo.get("c"), len(memo)) == (None, 2, 3, 2)
    memo.clear()
    assert len(memo) == 0 and memo.get("b") is None
    with pytest.raises(ValueError, match="at least one"):
        Memo(0)


def test_threads_storing_at_once_keep_it_bounded_and_agree() -> None:
    """Eight threads storing 2,000 keys each into a memo of 50, half of them the same keys:
    no error, never more than 50 values, and a key no other thread stores keeps its own
    value."""
    memo: Memo[int, object] = Memo(50)
    errors: list[BaseException] = []

    def work(t: int) -> None:
        try:
            for i in range(2000):
                key = i if i % 2 else 10_000 * (t + 1) + i
                value = object()
                kept = memo.put(key, value)
                assert kept is value or key % 2 == 1
                assert len(memo) <= 50
        except BaseException as e:  # reported by the main thread
            errors.append(e)

    threads = [threading.Thread(target=work, args=(t,)) for t in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert errors == [] and len(memo) == 50
