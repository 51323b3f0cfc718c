"""One result type for a procedure run (calib.procedure_run): every registered procedure, the
step runners and the A-H procedure return a :class:`ProcedureRun` that keeps each search, each
update and every measurement under one key rule."""

from __future__ import annotations

import numpy as np
import pytest

from calib.estimators.runners import run_best_fit
from calib.paper.stator_layout import example_stator_points
from calib.paper.stator_procedure import run_stator_procedure
from calib.probing import SearchCommand
from calib.procedure_run import ProbeStep, ProcedureRun, measured_by_key
from calib.procedures import PROCEDURES
from tests.box_part import BoxProbe
from tests.calib.procedures.test_procedures_registry import T_NOM, T_TRUE, role_points


def test_measured_by_key_numbers_the_retakes() -> None:
    cmd = SearchCommand.from_point(example_stator_points()["A"], T_NOM)
    steps = [ProbeStep(pid, 0, cmd, np.full(3, k)) for k, pid in enumerate("ABAA")]
    keyed = measured_by_key(steps)
    assert list(keyed) == ["A", "B", "A#2", "A#3"]
    assert [float(v[0]) for v in keyed.values()] == [0.0, 1.0, 2.0, 3.0]


@pytest.mark.parametrize("method", list(PROCEDURES))
def test_every_procedure_returns_the_one_run(method: str) -> None:
    kind = PROCEDURES[method]
    run = kind.run(role_points(method), T_NOM, BoxProbe(T_TRUE), kind.settings_type())
    assert type(run) is ProcedureRun
    assert run.n_probes == len(run.probes) >= 6
    # every measurement under the one key rule, in the order taken
    assert list(run.measured_m) == list(measured_by_key(run.probes))
    for step, q in zip(run.probes, run.measured_m.values(), strict=True):
        np.testing.assert_array_equal(step.measured_m, q)
    # the updates end in the frame, and each search was commanded in an estimate of the run
    assert run.updates and np.array_equal(run.updates[-1].T_base_wobj, run.T_base_wobj)
    assert run.estimates.shape == (len(run.updates), 4, 4)
    seen = [T_NOM, *run.estimates]
    for step in run.probes:
        assert any(np.array_equal(step.command.T_base_wobj_estimate, T) for T in seen)
    assert set(run.used_ids) <= {rp.point.id for rp in role_points(method)}


def test_the_runners_keep_their_fit_and_a_h_its_constructed_point() -> None:
    pts = [rp.point for rp in role_points("best_fit")]
    run = run_best_fit(pts, BoxProbe(T_TRUE), T_NOM, rounds=2)
    assert run.fit is not None and run.fit.rms_m < 1e-9
    assert run.measured_base.shape == (len(pts), 3)
    assert [u.name for u in run.updates][-1] == "best fit"
    ah = run_stator_procedure(example_stator_points(), T_NOM, BoxProbe(T_TRUE))
    assert ah.fit is None and ah.constructed_m["P3"].shape == (3,)
    assert [(s.point_id, s.round, s.command.point_id) for s in ah.probes][-2:] == [
        ("C", 1, "C2"),
        ("D", 1, "D2"),
    ]
    assert list(ah.commands) == list(ah.measured_m)  # the A-H keys, "C2" and "D2"
