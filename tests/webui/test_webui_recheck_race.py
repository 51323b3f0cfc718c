"""A check that arrives late is not shown for a plan the user has left (review of stop 34):
an undo during a sensor change's recheck brings back the earlier sensor's checks, and the
slower recheck for the undone sensor must not overwrite them."""

from __future__ import annotations

import threading
from typing import Any

from webui.app import WobjcalApp
from webui.cell_setup_edits import sensor_fields, with_sensor
from webui.testing import wait_until

TIMEOUT_S = 120.0


def test_an_undo_during_a_sensor_recheck_keeps_the_earlier_sensors_checks(
    demo_app: WobjcalApp,
) -> None:
    app = demo_app
    wait_until(lambda: len(app.checks()) == len(app.state.doc.points), "the first checks")
    before = app.checks()
    sensor0 = app.state.doc.source.validation.sensor
    fields = sensor_fields(app.state.doc)
    wide = type(fields)(
        fields.kind, fields.diameter_mm * 2.0, fields.range_mm, fields.noise_mm, None
    )
    session = app.worker.call(lambda s: s)
    check_points = session.check_points
    entered, release = threading.Event(), threading.Event()

    def held(points: Any, plan: Any) -> Any:
        if plan is not None and plan.validation.sensor != sensor0:  # the wide sensor's
            entered.set()
            release.wait(TIMEOUT_S)
        return check_points(points, plan)

    session.check_points = held
    try:
        change = threading.Thread(
            target=app.state.update, args=(lambda d: with_sensor(d, wide), "sensor")
        )
        change.start()
        assert entered.wait(TIMEOUT_S), "the recheck for the wide sensor did not start"
        undo = threading.Thread(target=app.state.undo)
        undo.start()
        wait_until(
            lambda: all(app.check_of(pid) is c for pid, c in before.items()),
            "the earlier sensor's checks back (undo)",
        )
        release.set()
        change.join(TIMEOUT_S)
        undo.join(TIMEOUT_S)
    finally:
        release.set()
        del session.check_points
    assert app.state.doc.source.validation.sensor == sensor0
    late = [pid for pid, c in before.items() if app.check_of(pid) is not c]
    assert not late, f"the undone sensor's checks shown for {late}"
