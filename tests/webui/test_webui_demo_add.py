"""The "Add best point" button on the demo's A-H plan says why not in the page's words
(helper-56, M2: the message carried the command line's "--add:")."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from calib.errors import InputError
from webui.app import WobjcalApp


@pytest.fixture(scope="module")
def app(tmp_path_factory: pytest.TempPathFactory) -> Iterator[WobjcalApp]:
    from webui.server import run
    from webui.testing import free_port

    folder = tmp_path_factory.mktemp("demo_add")
    a = run(None, port=free_port(), block=False, autosave_path=folder / "auto.json", fresh=True)
    yield a
    a.stop()


def test_add_best_point_on_the_ah_plan_is_refused_in_the_pages_words(app: WobjcalApp) -> None:
    done = app.layout_panel.suggest(add=1)
    with pytest.raises(InputError) as info:
        done.result(120)
    text = str(info.value)
    assert text.startswith("Add best point: ") and "--add" not in text
    assert "x-offset run" in text
