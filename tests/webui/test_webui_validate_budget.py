"""The validate panel's memory budget: a server already holding most of the 2 GB refuses a run,
naming what it holds, before anything runs."""

from __future__ import annotations

from typing import Any

import pytest

from calib.errors import InputError
from calib.plan.file import PlanError


def test_a_server_holding_most_of_the_budget_refuses_a_validation(
    app: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    from webui import validate_panel

    panel = app.validate_panel
    monkeypatch.setattr(validate_panel, "_rss_bytes", lambda: 3_300_000_000)
    with pytest.raises(InputError, match=r"the server \(3,147 MiB\)"):
        panel.start(40)
    assert not panel.running and panel.last_report is None
    monkeypatch.setattr(validate_panel, "_rss_bytes", lambda: 300_000_000)
    # beside a 286 MiB server the same run fits: it starts, and the box plan's own problem (its
    # searches are too short for its misplacement) is what stops it
    done = panel.start(40)
    with pytest.raises(PlanError, match="overtravel at least"):
        done.result(timeout=120)
