"""Fine jogging (issue 22, item 7): a typed value per joint and steps of 0.1/1/10 deg, within
the joint limits, with a clear message at a limit."""

from __future__ import annotations

import numpy as np
import pytest

from calib.errors import InputError
from webui.app import WobjcalApp
from webui.joint_jog import MINUS, PLUS, limits_deg, stepped_value_deg, typed_value_deg


def test_a_typed_value_is_taken_within_the_limits_and_refused_outside() -> None:
    assert typed_value_deg("J1", 12.3, -165.0, 165.0) == pytest.approx(12.3)
    assert typed_value_deg("J1", 165.0, -165.0, 165.0) == pytest.approx(165.0)
    with pytest.raises(InputError, match=r"J1: 200.0 deg is outside its limits \(-165.0 to 165.0"):
        typed_value_deg("J1", 200.0, -165.0, 165.0)
    with pytest.raises(InputError, match="type a number"):
        typed_value_deg("J1", float("nan"), -165.0, 165.0)


def test_a_step_stops_at_the_limit_and_a_step_beyond_it_is_refused() -> None:
    assert stepped_value_deg("J2", 10.0, 0.1, -70.0, 70.0) == (pytest.approx(10.1), "")
    assert stepped_value_deg("J2", 10.0, -10.0, -70.0, 70.0) == (pytest.approx(0.0), "")
    value, note = stepped_value_deg("J2", 65.0, 10.0, -70.0, 70.0)
    assert value == 70.0 and note == "J2 stopped at its upper limit (70.0 deg)"
    with pytest.raises(InputError, match=r"J2 is at its upper limit \(70.0 deg\)"):
        stepped_value_deg("J2", 70.0, 0.1, -70.0, 70.0)
    with pytest.raises(InputError, match="lower limit"):
        stepped_value_deg("J2", -70.0, -1.0, -70.0, 70.0)
    assert stepped_value_deg("J2", 70.0, -1.0, -70.0, 70.0) == (pytest.approx(69.0), "")


@pytest.mark.slow
def test_fine_jog_fields_and_steps_move_the_robot(demo_app: WobjcalApp) -> None:
    panel = demo_app.teach_panel
    fine = panel.fine
    chain = demo_app.view.chain
    lo, hi = limits_deg(chain)
    assert len(fine.fields) == chain.n_joints == 6
    for f, a, b in zip(fine.fields, lo, hi, strict=True):
        assert (f.min, f.max, f.step) == (pytest.approx(a), pytest.approx(b), 1.0)
    q = demo_app.check_of("A").q.copy()
    panel.jog(q)
    np.testing.assert_allclose([f.value for f in fine.fields], np.degrees(q), atol=0.005)
    fine.step.value = "0.1"
    assert all(f.step == pytest.approx(0.1) for f in fine.fields), "arrows step by it too"
    fine.step_joint(0, 0.1)
    assert np.degrees(panel.q[0] - q[0]) == pytest.approx(0.1, abs=1e-9)
    np.testing.assert_allclose(panel.q[1:], q[1:])
    np.testing.assert_allclose(demo_app.robot.q, panel.q)
    assert fine.fields[0].value == pytest.approx(round(np.degrees(panel.q[0]), 2))
    assert panel.sliders[0].value == pytest.approx(round(np.degrees(panel.q[0]), 3))
    fine.set_joint(2, 5.25)
    assert np.degrees(panel.q[2]) == pytest.approx(5.25)
    before = panel.q.copy()
    with pytest.raises(InputError, match="outside its limits"):
        fine.set_joint(2, float(hi[2]) + 5.0)
    np.testing.assert_array_equal(panel.q, before)
    fine.set_joint(2, float(hi[2]) - 0.5)
    fine.step_joint(2, 10.0)
    assert np.degrees(panel.q[2]) == pytest.approx(hi[2])
    assert "stopped at its upper limit" in fine.note_md.content
    with pytest.raises(InputError, match="at its upper limit"):
        fine.step_joint(2, 1.0)
    assert tuple(fine.buttons.options) == (MINUS, PLUS)
    panel.jog(q)
