"""The "Add best point" button on the demo's A-H plan says why not in the page's words
(helper-56, M2: the message carried the command line's "--add:")."""

from __future__ import annotations

import pytest

from calib.errors import InputError
from webui.app import WobjcalApp


def test_add_best_point_on_the_ah_plan_is_refused_in_the_pages_words(demo_app: WobjcalApp) -> None:
    app = demo_app
    done = app.layout_panel.suggest(add=1)
    with pytest.raises(InputError) as info:
        done.result(120)
    text = str(info.value)
    assert text.startswith("Add best point: ") and "--add" not in text
    assert "x-offset run" in text
