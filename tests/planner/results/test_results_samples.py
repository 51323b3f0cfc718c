"""``wobjcal calibrate PLAN RESULTS`` on the results files each controller leaves
(``tests/data/results/``, written by :mod:`tests.make_results_samples` from one simulated run of
the plate 3-2-1 plan's four programs): the kind is detected, the registers and frames
converted, and each gives the simulated part's frame to the sensor's noise; ``--from`` names a
wrong kind; a plan other than the one the program came from is refused."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from calib.plan.file import load_plan
from planner.cli.main import main
from planner.plan_cell import nominal_T_base_wobj

#: every test here runs a shipped plate plan, whose mesh is in ../shared/reference
pytestmark = pytest.mark.reference

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "tests" / "data" / "results"
PLAN = str(ROOT / "assets" / "plans" / "plate_holes_321.json")
SAMPLES = {
    "rapid": [DATA / "wobjcal_measured.json"],
    "krl": [DATA / "WOBJCALPLATEHOLES321.dat"],
    "urscript": [DATA / "log_history.txt"],
    "fanuc": [DATA / "fanuc" / "POSREG.VA", DATA / "fanuc" / "NUMREG.VA"],
}


def _truth() -> np.ndarray:
    return np.asarray(json.loads((DATA / "truth.json").read_text())["T_base_wobj"])


def _angle_deg(T: np.ndarray, U: np.ndarray) -> float:
    dR = T[:3, :3].T @ U[:3, :3]
    return float(np.degrees(np.arccos(np.clip((np.trace(dR) - 1) / 2, -1, 1))))


def test_calibrate_reads_each_controllers_results(capsys: pytest.CaptureFixture[str]) -> None:
    frames = {}
    for kind, paths in SAMPLES.items():
        files = [str(f) for f in paths]
        for extra in ([], ["--from", kind]):
            code = main(["calibrate", PLAN, *files, "--json", *extra])
            out, err = capsys.readouterr()
            assert code == 0, (kind, err)
            frames[kind] = np.asarray(json.loads(out)["T_base_wobj"])
    T_true = _truth()
    nominal = nominal_T_base_wobj(load_plan(PLAN))
    # the four programs measured the same simulated part, searches drawing the same noise:
    # their frames agree to the files' resolution (FANUC: a micrometre)
    for kind, T in frames.items():
        assert np.abs(T[:3, 3] - frames["krl"][:3, 3]).max() < 5e-6, kind
        assert _angle_deg(T, frames["krl"]) < 1e-3, kind
        # and find the part, misplaced from the nominal by millimetres, to the sensor's and
        # the robot's noise
        assert np.abs(T[:3, 3] - T_true[:3, 3]).max() < 0.3e-3, kind
        assert _angle_deg(T, T_true) < 0.05, kind
    assert np.abs(nominal[:3, 3] - T_true[:3, 3]).max() > 1e-3


def test_the_fanuc_folder_and_a_wrong_kind(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["calibrate", PLAN, str(DATA / "fanuc")]) == 0
    capsys.readouterr()
    assert main(["calibrate", PLAN, str(SAMPLES["krl"][0]), "--from", "urscript"]) == 2
    err = capsys.readouterr().err
    assert "--from urscript expects" in err and "Traceback" not in err


def test_another_plans_results_are_refused(capsys: pytest.CaptureFixture[str]) -> None:
    other = str(ROOT / "assets" / "plans" / "plate_holes_best_fit.json")
    for kind in ("krl", "urscript"):
        assert main(["calibrate", other, *map(str, SAMPLES[kind])]) == 2
        err = capsys.readouterr().err
        assert "not of this plan" in err, err
