"""Fixtures of the UI's in-process tests (no browser)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from webui.app import WobjcalApp


@pytest.fixture(scope="module")
def app(tmp_path_factory: pytest.TempPathFactory) -> Iterator[WobjcalApp]:
    """The UI on the 3-2-1 box plan, autosaving into a folder of its own (one per module; a
    module that needs another plan or upload folder defines its own ``app``)."""
    from webui.server import run
    from webui.testing import box_plan, free_port

    folder = tmp_path_factory.mktemp("ui")
    a = run(box_plan(folder), port=free_port(), block=False, autosave_path=folder / "auto.json")
    yield a
    a.stop()


@pytest.fixture(scope="module")
def demo_app(tmp_path_factory: pytest.TempPathFactory) -> Iterator[WobjcalApp]:
    """The UI on the built-in stator demo (``wobjcal ui`` with no plan), fresh, autosaving
    into a folder of its own (one per module)."""
    from webui.server import run
    from webui.testing import free_port

    folder = tmp_path_factory.mktemp("demo")
    a = run(None, port=free_port(), block=False, autosave_path=folder / "auto.json", fresh=True)
    yield a
    a.stop()
