"""Session state: undo/redo, listeners, atomic autosave."""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path

import pytest

from webui.state import Change, SessionState, atomic_write_bytes


def _state(tmp_path: Path) -> SessionState[tuple[int, ...]]:
    return SessionState(
        (),
        serialize=lambda d: json.dumps(list(d)).encode(),
        autosave_path=tmp_path / "sub" / "autosave.json",
    )


def test_apply_undo_redo_round_trip(tmp_path: Path) -> None:
    s = _state(tmp_path)
    s.apply((1,), "add 1")
    s.apply((1, 2), "add 2")
    assert s.doc == (1, 2)
    ch = s.undo()
    assert ch is not None and ch.label == "undo add 2" and s.doc == (1,)
    assert s.can_redo
    s.redo()
    assert s.doc == (1, 2)
    s.undo()
    s.apply((1, 3), "add 3")
    assert not s.can_redo, "a new edit clears the redo stack"
    s.undo()
    s.undo()
    assert s.doc == () and s.undo() is None


def test_autosave_follows_every_change(tmp_path: Path) -> None:
    s = _state(tmp_path)
    s.apply((4, 5), "edit")
    path = tmp_path / "sub" / "autosave.json"
    assert json.loads(path.read_text()) == [4, 5]
    s.undo()
    assert json.loads(path.read_text()) == []
    assert not list(path.parent.glob("*.tmp")), "no temp files left behind"


def test_failed_edit_changes_nothing(tmp_path: Path) -> None:
    s = _state(tmp_path)
    s.apply((1,), "a")

    def bad(_d: tuple[int, ...]) -> tuple[int, ...]:
        raise ValueError("nope")

    with pytest.raises(ValueError):
        s.update(bad, "bad")
    assert s.doc == (1,) and s.undo() is not None and s.doc == ()


def test_listeners_see_changes_and_may_read_state(tmp_path: Path) -> None:
    s = _state(tmp_path)
    seen: list[tuple[str, tuple[int, ...]]] = []
    s.subscribe(lambda ch: seen.append((ch.label, s.doc)))
    s.apply((7,), "seven")
    s.undo()
    assert seen == [("seven", (7,)), ("undo seven", ())]


def test_concurrent_updates_are_not_lost(tmp_path: Path) -> None:
    s: SessionState[tuple[int, ...]] = SessionState(())

    def add(k: int) -> None:
        for i in range(50):
            s.update(lambda d, v=k * 100 + i: (*d, v), "add")

    threads = [threading.Thread(target=add, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(s.doc) == 200 and len(set(s.doc)) == 200


def test_atomic_write_replaces_whole_file(tmp_path: Path) -> None:
    path = tmp_path / "f.json"
    atomic_write_bytes(path, b"old contents that are long")
    atomic_write_bytes(path, b"new")
    assert path.read_bytes() == b"new"


def test_autosave_error_is_reported_not_raised(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    s: SessionState[int] = SessionState(0, serialize=lambda d: b"1", autosave_path=blocker / "a")
    s.apply(1, "edit")
    assert s.doc == 1 and s.last_autosave_error


def test_autosave_is_written_while_the_listeners_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The UI's listener checks and draws the edit; a slow disk does not hold it up, and the
    file holds the edit once the change returns."""
    import webui.state

    events: list[str] = []
    write = webui.state.atomic_write_bytes

    def slow_write(path: Path, data: bytes) -> None:
        time.sleep(0.3)  # an fsync on a busy disk
        write(path, data)
        events.append("written")

    monkeypatch.setattr(webui.state, "atomic_write_bytes", slow_write)
    s = _state(tmp_path)
    s.subscribe(lambda _change: events.append("listener"))
    s.apply((3,), "three")
    assert events == ["listener", "written"], "the listener waited for the disk"
    assert json.loads((tmp_path / "sub" / "autosave.json").read_text()) == [3]


def test_overlapping_changes_leave_the_latest_document_in_the_file(tmp_path: Path) -> None:
    s = _state(tmp_path)

    def add(k: int) -> None:
        for i in range(25):
            s.update(lambda d, v=k * 100 + i: (*d, v), "add")

    threads = [threading.Thread(target=add, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(s.doc) == 100 and not s.last_autosave_error
    assert json.loads((tmp_path / "sub" / "autosave.json").read_text()) == list(s.doc)


def test_a_reader_of_the_file_waits_for_the_write_of_the_shown_document(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``doc`` shows an edit before its autosave is on disk; ``wait_saved`` bridges the gap."""
    import webui.state

    write = webui.state.atomic_write_bytes
    release = threading.Event()

    def held_write(path: Path, data: bytes) -> None:
        release.wait(5.0)
        write(path, data)

    s = _state(tmp_path)
    s.apply((1,), "one")  # on disk before the slow disk
    monkeypatch.setattr(webui.state, "atomic_write_bytes", held_write)
    editor = threading.Thread(target=s.apply, args=((1, 2), "two"))
    editor.start()
    deadline = time.monotonic() + 5.0
    while s.doc != (1, 2) and time.monotonic() < deadline:
        time.sleep(0.005)
    assert s.doc == (1, 2)
    path = tmp_path / "sub" / "autosave.json"
    assert json.loads(path.read_text()) == [1], "the file held the edit before its write"
    assert not s.wait_saved(timeout=0.05)  # still being written
    release.set()
    assert s.wait_saved(timeout=5.0)
    assert json.loads(path.read_text()) == [1, 2]
    editor.join()


def test_the_autosave_status_speaks_of_the_newest_write(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """When an older change finishes after a newer one (its listeners were slower), the status
    still speaks of the newer write: here the newer write failed, so the file is not fine."""
    import webui.state

    write = webui.state.atomic_write_bytes

    def fail_on_two(path: Path, data: bytes) -> None:
        if data == b"[1, 2]":
            raise OSError("disk full")
        write(path, data)

    monkeypatch.setattr(webui.state, "atomic_write_bytes", fail_on_two)
    s = _state(tmp_path)
    slow_listener_may_end = threading.Event()
    in_slow_listener = threading.Event()

    def listener(change: Change[tuple[int, ...]]) -> None:
        if change.doc == (1,):
            in_slow_listener.set()
            slow_listener_may_end.wait(5.0)

    s.subscribe(listener)
    older = threading.Thread(target=s.apply, args=((1,), "one"))
    older.start()
    assert in_slow_listener.wait(5.0)
    s.apply((1, 2), "two")  # its write fails and it finishes first
    assert "disk full" in s.last_autosave_error
    slow_listener_may_end.set()
    older.join()
    assert "disk full" in s.last_autosave_error, "an older write's success hid the newer failure"
    assert not s.wait_saved(timeout=5.0)
