"""Results back from every controller: each exported program, run in this project's interpreter
of its language against the simulated sensor of one validate trial, leaves its results where
that controller keeps them (:mod:`tests.controller_files`); ``wobjcal calibrate`` reads that
file (:func:`planner.results.read_results`, the kind detected) and computes the frame.

What is held:

- reading adds nothing: the frame from the file is the frame of the points the program
  recorded, as the file writes them, to 1e-9 m (1e-6 mm) and 1e-9 rad; the file's own
  resolution is the controller's (URScript: integer nanometres; FANUC ``POSREG.VA``: 3
  decimals of mm; KRL: the interpreter's values at full precision, a controller's 32-bit REAL);
- and that frame is the one the controller computed (adaptive programs: ``BASE_DATA[10]``,
  ``wobj``) or the trial's (FANUC, nominal), within the replay tests' tolerances plus the
  file's resolution.

Then what a partial or foreign file does: one message naming the slot, point or register.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from calib.plan.file import Plan, load_plan, plan_digest
from calib.plan.measurements import Measurements
from planner.calibrate.job import calibrate_plan
from planner.export import export_files
from planner.export.job import ToolData, build_job
from planner.program import execute
from planner.results import ResultsError, read_results
from tests.controller_files import fanuc_va, krl_saved_dat, ur_log
from tests.fanuc_interp import TPMachine
from tests.krl_interp import KrlMachine
from tests.planner.export.test_fanuc_program_replay import tp_text
from tests.planner.export.test_krl_program_runs import base_m
from tests.planner.export.test_urscript_adaptive_replay import angle_rad
from tests.planner.validate.test_program_trial_replay import (
    A_H_TOL_M,
    A_H_TOL_RAD,
    _search_callback,
    _trial,
    _vec,
)
from tests.rapid_interp import Machine
from tests.reference_data import plate_case
from tests.urscript_interp import UrMachine

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"


def _frame(plan: Plan, m: Measurements) -> np.ndarray:
    out = calibrate_plan(plan, m)
    return out.T_base_wobj


def _close(T: np.ndarray, want: np.ndarray, tol_m: float, tol_rad: float) -> None:
    assert np.abs(T[:3, 3] - want[:3, 3]).max() < tol_m, (T[:3, 3], want[:3, 3])
    assert angle_rad(T, want) < tol_rad


def _job(plan: Plan, T_nom: np.ndarray):  # type: ignore[no-untyped-def]
    return build_job(plan, T_nom, ToolData(T_flange_tcp=np.eye(4)))


# ------------------------------------------------------------------ RAPID
@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "seed"), [plate_case("plate_holes_best_fit.json", 1), ("stator_section_ah.json", 3)]
)
@pytest.mark.reference
def test_the_rapid_json_gives_the_frame_the_controller_computed(
    tmp_path: Path, name: str, seed: int
) -> None:
    plan, setup, probe, _ = _trial(PLANS / name, "rapid", seed)
    m = Machine(
        export_files(_job(plan, setup.T_base_wobj_nominal), "rapid")[".mod"],
        _search_callback(probe()),
    )
    m.main()
    f = tmp_path / "wobjcal_measured.json"
    f.write_text(m.files["wobjcal_measured.json"])
    res = read_results(plan, [f])
    assert res.kind == "rapid" and res.notes == []  # the digest is the plan's
    meas = res.measurements
    assert meas.plan_digest == plan_digest(plan) and not meas.failed
    # reading adds nothing: the points are the program's, to the 4 decimals of mm it writes
    ids = [t.point_id for t in _job(plan, setup.T_base_wobj_nominal).targets]
    for k, pid in enumerate(ids):
        kept = _vec(m.globals["measured"][k])
        assert np.abs(np.asarray(meas.points[pid]) - kept).max() <= 0.5e-4 + 1e-9, pid
    T = _frame(plan, meas)
    # and the controller's frame, to the file's 0.1 um (A-H: and the replay's tolerance)
    tol_m, tol_rad = (1e-6, 1e-6) if plan.method != "hultman2013" else (A_H_TOL_M, A_H_TOL_RAD)
    _close(T, m.wobj_matrix_m("wobjCal"), tol_m, tol_rad)


# ------------------------------------------------------------------ KRL
@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "seed"), [plate_case("plate_holes_321.json", 2), ("stator_section_ah.json", 3)]
)
@pytest.mark.reference
def test_the_krl_dat_gives_the_frame_the_controller_computed(
    tmp_path: Path, name: str, seed: int
) -> None:
    plan, setup, probe, _ = _trial(PLANS / name, "krl", seed)
    files = export_files(_job(plan, setup.T_base_wobj_nominal), "krl")
    assert f"plan digest {plan_digest(plan)}" in files[".dat"]
    m = KrlMachine(files, _search_callback(probe())).run()
    assert m.value("nResult") == 1
    dat = tmp_path / "WOBJCAL.dat"
    dat.write_text(krl_saved_dat(files[".dat"], m))
    res = read_results(plan, [dat])
    assert res.kind == "krl" and res.notes == []
    meas = res.measurements
    assert not meas.failed and set(meas.points) == {p.id for p in plan.points}
    if plan.method == "hultman2013":
        assert set(meas.retakes) == {"C", "D"}  # the A-H retakes, from the slots after the points
    # reading adds nothing: the points are the program's
    got = meas.points_m()
    recorded = m.measured_m()
    for i, pid in enumerate(p.id for p in plan.points):
        assert np.abs(got[pid] - recorded[i + 1]).max() < 1e-12, pid
    T = _frame(plan, meas)
    tol_m, tol_rad = (1e-6, 1e-8) if plan.method != "hultman2013" else (A_H_TOL_M, A_H_TOL_RAD)
    _close(T, base_m(m), tol_m, tol_rad)


@pytest.mark.reference
def test_a_krl_dat_of_a_stopped_run_names_what_was_not_measured(tmp_path: Path) -> None:
    plan, setup, probe, _ = _trial(PLANS / "plate_holes_321.json", "krl", 2)
    files = export_files(_job(plan, setup.T_base_wobj_nominal), "krl")
    search = _search_callback(probe())
    calls = [0]

    def failing_third(start, end, axis, neg):  # type: ignore[no-untyped-def]
        calls[0] += 1
        return "ERR_WHLSEARCH" if calls[0] == 3 else search(start, end, axis, neg)

    m = KrlMachine(files, failing_third).run()
    assert m.value("nResult") == 2
    dat = tmp_path / "run.dat"
    dat.write_text(krl_saved_dat(files[".dat"], m))
    res = read_results(plan, [dat], "krl")
    ids = [p.id for p in plan.points]
    assert list(res.measurements.points) == ids[:2]
    assert "no detection" in res.measurements.failed[ids[2]]
    assert all("not run" in res.measurements.failed[i] for i in ids[3:])
    assert any("nResult = 2" in n and ids[2] in n for n in res.notes)


@pytest.mark.reference
def test_a_krl_dat_copied_before_the_run_is_refused(tmp_path: Path) -> None:
    plan = load_plan(PLANS / "plate_holes_321.json")
    files = export_files(_job(plan, np.eye(4)), "krl")
    dat = tmp_path / "fresh.dat"
    dat.write_text(files[".dat"])
    with pytest.raises(ResultsError, match=r"slot 1 \(point [^)]+\): nFail\[1\] has no value"):
        read_results(plan, [dat])


@pytest.mark.reference
def test_a_krl_dat_of_another_plan_is_refused(tmp_path: Path) -> None:
    plan = load_plan(PLANS / "plate_holes_321.json")
    other = load_plan(PLANS / "plate_holes_best_fit.json")
    dat = tmp_path / "other.dat"
    dat.write_text(export_files(_job(other, np.eye(4)), "krl")[".dat"])
    with pytest.raises(ResultsError, match=f"plan digest {plan_digest(other)}"):
        read_results(plan, [dat])


@pytest.mark.reference
def test_a_measured_slot_without_its_point_is_named(tmp_path: Path) -> None:
    plan = load_plan(PLANS / "plate_holes_321.json")
    text = export_files(_job(plan, np.eye(4)), "krl")[".dat"]
    n = len(plan.points)
    lines = [f"nFail[{i}]=0" for i in range(1, n + 1)]
    text = text.replace(f"DECL INT nFail[{n}]", f"DECL INT nFail[{n}]\n" + "\n".join(lines))
    dat = tmp_path / "x.dat"
    dat.write_text(text)
    first = plan.points[0].id
    with pytest.raises(ResultsError, match=rf"slot 1 \(point {first}\).*xMeas\[1\] is empty"):
        read_results(plan, [dat])
    dat.write_text(text.replace("nFail[2]=0", "nFail[2]=0\nnFail[2]=1"))
    with pytest.raises(ResultsError, match=r"x.dat:\d+: nFail\[2\]: given twice"):
        read_results(plan, [dat])


# ------------------------------------------------------------------ URScript
@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "seed"), [plate_case("plate_holes_best_fit.json", 1), ("stator_section_ah.json", 3)]
)
@pytest.mark.reference
def test_the_ur_log_gives_the_frame_the_controller_computed(
    tmp_path: Path, name: str, seed: int
) -> None:
    plan, setup, probe, _ = _trial(PLANS / name, "urscript", seed)
    text = export_files(_job(plan, setup.T_base_wobj_nominal), "urscript")[".script"]
    m = UrMachine(text, _search_callback(probe())).run()
    assert m.finished and not m.halted
    log = tmp_path / "log_history.txt"
    # an earlier, stopped run of the same program before the one to read
    earlier = [f"wobjcal/1 start {plan_digest(plan)}", m.messages[1]]
    log.write_text(ur_log(earlier + m.messages))
    res = read_results(plan, [log])
    assert res.kind == "urscript"
    assert any("2 runs" in n for n in res.notes)
    meas = res.measurements
    assert not meas.failed and set(meas.points) == {p.id for p in plan.points}
    # the points to the log's nanometre
    xyz = np.asarray(m.variables["measured"], dtype=float).reshape(-1, 3)
    for k, p in enumerate(plan.points):
        assert np.abs(meas.points_m()[p.id] - xyz[k]).max() <= 0.5e-9 + 1e-15, p.id
    T = _frame(plan, meas)
    exact = Measurements.from_points_m(
        {p.id: np.round(xyz[k] * 1e9) / 1e9 for k, p in enumerate(plan.points)}
    )
    if not meas.retakes:
        _close(T, _frame(plan, exact), 1e-12, 1e-12)
    tol_m, tol_rad = (1e-6, 1e-8) if plan.method != "hultman2013" else (A_H_TOL_M, A_H_TOL_RAD)
    _close(T, m.frame("wobj"), tol_m, tol_rad)


@pytest.mark.reference
def test_a_ur_log_cut_before_the_end_is_refused(tmp_path: Path) -> None:
    plan = load_plan(PLANS / "plate_holes_321.json")
    digest = plan_digest(plan)
    pid = plan.points[0].id
    log = tmp_path / "log.txt"
    log.write_text(ur_log([f"wobjcal/1 start {digest}", f"wobjcal/1 point {pid} 0 1 2 3"]))
    with pytest.raises(ResultsError, match=rf"no 'wobjcal/1 end'.*last point: {pid}"):
        read_results(plan, [log])
    log.write_text(ur_log([f"wobjcal/1 point {pid} 0 1 2 3", "wobjcal/1 end"]))
    with pytest.raises(ResultsError, match=r"no 'wobjcal/1 start' line \(result lines from"):
        read_results(plan, [log])
    log.write_text(ur_log(["wobjcal/1 start 0123456789abcdef", "wobjcal/1 end"]))
    with pytest.raises(ResultsError, match="plan digest 0123456789abcdef, not of this plan"):
        read_results(plan, [log])
    log.write_text(ur_log([f"wobjcal/1 start {digest}", "wobjcal/1 point ZZ 0 1 2 3"]))
    with pytest.raises(ResultsError, match=r"log.txt:\d+: point 'ZZ' is not in the plan"):
        read_results(plan, [log])


# ------------------------------------------------------------------ FANUC
@pytest.mark.reference
def test_the_fanuc_register_backups_give_the_trials_frame(tmp_path: Path) -> None:
    plan, setup, probe, _ = _trial(PLANS / "plate_holes_321.json", "fanuc", 2)
    T_nom = setup.T_base_wobj_nominal
    run = execute(setup.program, T_nom, probe())
    job, text = tp_text(_job(plan, T_nom))
    tp = TPMachine(text, _search_callback(probe())).run()
    posreg, numreg = fanuc_va(tp)
    (tmp_path / "POSREG.VA").write_text(posreg)
    (tmp_path / "NUMREG.VA").write_text(numreg)
    res = read_results(plan, [tmp_path])  # the backup folder
    assert res.kind == "fanuc"
    meas = res.measurements
    n = len(job.targets)
    # reading adds nothing: the points are PR[11..] as the file writes them (3 decimals of mm)
    pr_mm = np.array([[round(v, 3) for v in tp.PR[10 + i][:3]] for i in range(1, n + 1)])
    base = pr_mm / 1e3 @ T_nom[:3, :3].T + T_nom[:3, 3]
    exact = Measurements.from_points_m({t.point_id: base[k] for k, t in enumerate(job.targets)})
    T = _frame(plan, meas)
    _close(T, _frame(plan, exact), 1e-9, 1e-9)
    # and the trial's frame, to the file's micrometre: half a micrometre per coordinate, over
    # the 3-2-1 layout's baselines of some 0.1 m, turns the frame by a few microradians
    _close(T, run.T_base_wobj, 5e-6, 1e-5)


@pytest.mark.reference
def test_fanuc_registers_of_another_frame_or_a_failed_point_are_named(tmp_path: Path) -> None:
    plan, setup, probe, _ = _trial(PLANS / "plate_holes_321.json", "fanuc", 2)
    T_nom = setup.T_base_wobj_nominal
    job, text = tp_text(_job(plan, T_nom))
    tp = TPMachine(text, _search_callback(probe())).run()
    tp.R[12] = 1.0  # point 2: no detection
    posreg, numreg = fanuc_va(tp)
    pos, num = tmp_path / "POSREG.VA", tmp_path / "NUMREG.VA"
    pos.write_text(posreg)
    num.write_text(numreg)
    res = read_results(plan, [pos, num], "fanuc")
    second = job.targets[1].point_id
    assert "R[12] = 1: no detection" in res.measurements.failed[second]
    with pytest.raises(ResultsError, match="FANUC results are two files"):
        read_results(plan, [pos])
    tp.PR[1] = tp.PR[1] + np.array([0.5, 0, 0, 0, 0, 0])
    pos.write_text(fanuc_va(tp)[0])
    with pytest.raises(ResultsError, match=r"PR\[1\] \(the user frame the program set\)"):
        read_results(plan, [pos, num])
    tp.PR[1] = tp.PR[1] - np.array([0.5, 0, 0, 0, 0, 0])
    del tp.PR[13]
    pos.write_text(fanuc_va(tp)[0])
    third = job.targets[2].point_id
    with pytest.raises(ResultsError, match=rf"PR\[13\] \(point {third}\) is uninitialized"):
        read_results(plan, [pos, num])


# ------------------------------------------------------------------ any
@pytest.mark.reference
def test_a_file_of_no_controller_is_named(tmp_path: Path) -> None:
    plan = load_plan(PLANS / "plate_holes_321.json")
    f = tmp_path / "notes.txt"
    f.write_text("measured A at 1510.2 -402.7 731.9\n")
    with pytest.raises(ResultsError, match=r"notes\.txt: cannot tell which controller wrote it"):
        read_results(plan, [f])
    with pytest.raises(ResultsError, match="--from krl expects"):
        log = tmp_path / "log.txt"
        log.write_text("wobjcal/1 start x\n")
        read_results(plan, [log], "krl")
