"""Tests of ``wobjcal sweep``: placements, rows serial and on Dask, resume, refusals, flags."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from calib.errors import InputError
from calib.frames import invert_transform
from calib.plan.file import load_plan
from planner.cli.main import main
from planner.sweep import job as sweep
from planner.sweep import run_sweep
from planner.sweep import task as sweep_task
from planner.sweep.files import COLUMNS, SweepMismatch, read_rows
from planner.sweep.space import Placement, SweepSpace, parse_range, placed_plan, placement

REPO = Path(__file__).resolve().parents[3]
PLATE = REPO / "assets" / "plans" / "plate_holes_321.json"
N = 4


@pytest.fixture(scope="module")
def serial_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 4-placement sweep of the plate run in this process."""
    out = tmp_path_factory.mktemp("serial")
    result = run_sweep(PLATE, out, samples=N, seed=3, workers=0)
    assert (result.kept, result.ran, result.samples) == (0, N, N)
    return out


def test_placement_is_a_function_of_seed_and_index() -> None:
    space = SweepSpace.default(part_dz_mm=(5.0, 5.0))
    a = [placement(space, 7, i) for i in range(50)]
    assert [placement(space, 7, i) for i in reversed(range(50))][::-1] == a
    assert placement(space, 8, 0) != a[0]
    for p in a:
        assert -200 <= p.base_dx_mm <= 200 and -15 <= p.part_dyaw_deg <= 15
        assert p.part_dz_mm == 5.0
    assert len({p.base_dx_mm for p in a}) == 50  # drawn, not constant


@pytest.mark.reference
def test_placed_plan_moves_base_part_and_fixtures_rigidly() -> None:
    plan = load_plan(PLATE)
    where = Placement(0, 100.0, -50.0, 90.0, 10.0, 20.0, 30.0, 45.0)
    moved = placed_plan(plan, where)
    T_b0, T_b1 = plan.cell.robot.T_world_base.matrix(), moved.cell.robot.T_world_base.matrix()
    np.testing.assert_allclose(T_b1[:3, 3] - T_b0[:3, 3], [0.1, -0.05, 0.0], atol=1e-12)
    np.testing.assert_allclose(T_b1[:3, 0], T_b0[:3, 1], atol=1e-9)  # x turned onto y
    T_w0, T_w1 = plan.work_object.T_world_wobj.matrix(), moved.work_object.T_world_wobj.matrix()
    np.testing.assert_allclose(T_w1[:3, 3] - T_w0[:3, 3], [0.01, 0.02, 0.03], atol=1e-12)
    assert plan.cell.fixtures
    for f0, f1 in zip(plan.cell.fixtures, moved.cell.fixtures, strict=True):
        rel0 = invert_transform(T_w0) @ f0.T_world_fixture.matrix()
        rel1 = invert_transform(T_w1) @ f1.T_world_fixture.matrix()
        np.testing.assert_allclose(rel1, rel0, atol=1e-9)  # the table moves with the part
    assert moved.points == plan.points


@pytest.mark.parametrize(
    ("text", "expected"), [("200", (-200.0, 200.0)), ("-5:7.5", (-5.0, 7.5)), ("0", (0.0, 0.0))]
)
def test_parse_range(text: str, expected: tuple[float, float]) -> None:
    assert parse_range(text, "base_dx_mm") == expected


@pytest.mark.reference
@pytest.mark.slow
def test_serial_and_distributed_rows_are_the_same(serial_dir: Path, tmp_path: Path) -> None:
    result = run_sweep(PLATE, tmp_path, samples=N, seed=3, workers=2)
    assert result.ran == N
    serial = (serial_dir / "sweep.csv").read_text().splitlines()
    distributed = (tmp_path / "sweep.csv").read_text().splitlines()
    assert len(serial) == N + 1 and serial[0] == ",".join(COLUMNS)
    for s, d in zip(serial, distributed, strict=True):
        assert s == d
    assert (tmp_path / "sweep.png").read_bytes()[:4] == b"\x89PNG"
    rows = read_rows(tmp_path / "sweep.csv")
    assert {r[COLUMNS.index("status")] for r in rows.values()} <= {"feasible", "infeasible"}
    assert all(float(r[COLUMNS.index("cycle_s")]) > 0 for r in rows.values())


@pytest.mark.reference
@pytest.mark.slow
def test_resume_runs_only_the_missing_placements(
    serial_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "resume"
    shutil.copytree(serial_dir, out)
    full = (serial_dir / "sweep.csv").read_text()
    lines = full.splitlines(keepends=True)
    # rows 0 and 2 finished (out of order, as workers finish), row 3 torn by a kill
    (out / "sweep.csv").write_text(lines[0] + lines[3] + lines[1] + lines[4][:20])
    ran: list[int] = []
    real = sweep.check_placement

    def counted(text: str, folder: str, fmt: str | None, where: Placement) -> object:
        ran.append(where.index)
        return real(text, folder, fmt, where)

    monkeypatch.setattr(sweep, "check_placement", counted)
    result = run_sweep(PLATE, out, samples=N, seed=3, workers=0)
    assert sorted(ran) == [1, 3] and (result.kept, result.ran) == (2, 2)
    assert (out / "sweep.csv").read_text() == full
    ran.clear()
    run_sweep(PLATE, out, samples=N, seed=3, workers=0)  # complete: nothing to do
    assert ran == []


@pytest.mark.reference
@pytest.mark.slow
def test_other_arguments_are_refused_naming_them(serial_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "other"
    shutil.copytree(serial_dir, out)
    before = (out / "sweep.csv").read_text()
    with pytest.raises(SweepMismatch, match=r"--seed 3 \(now 4\)"):
        run_sweep(PLATE, out, samples=N, seed=4, workers=0)
    space = SweepSpace.default(base_dx_mm=(-100.0, 100.0))
    with pytest.raises(SweepMismatch, match=r"--base-x -200:200 \(now -100:100\)"):
        run_sweep(PLATE, out, samples=N, seed=3, space=space, workers=0)
    with pytest.raises(SweepMismatch, match=r"--samples 4 \(now 2: fewer\)"):
        run_sweep(PLATE, out, samples=2, seed=3, workers=0)
    assert (out / "sweep.csv").read_text() == before  # refused before anything was touched
    (out / "sweep.json").unlink()
    with pytest.raises(InputError, match=r"without sweep\.json"):
        run_sweep(PLATE, out, samples=N, seed=3, workers=0)


@pytest.mark.reference
def test_cli_refuses_another_sweep_with_exit_2(
    serial_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "cli"
    shutil.copytree(serial_dir, out)
    argv = ["sweep", str(PLATE), "--samples", str(N), "-o", str(out), "--workers", "0"]
    assert main([*argv, "--format", "krl", "--seed", "3"]) == 2
    err = capsys.readouterr().err
    assert "--format rapid (now krl)" in err and "Traceback" not in err


@pytest.mark.slow
@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--samples", "0"], "--samples: must be >= 1"),
        (["--samples", "100001"], "--samples: must be at most 100,000"),
        (["--base-x", "1:0"], "--base-x: MIN must be <= MAX"),
        (["--base-y", "abc"], "--base-y: expected MIN:MAX or a half width"),
        (["--part-yaw", "200"], "--part-yaw: must lie within +-180 deg"),
        (["--part-z", "nan"], "--part-z: expected MIN:MAX"),
        (["--base-yaw", "-3"], "written --base-yaw=MIN:MAX"),
        (["--workers", "65"], "--workers: must be at most 64"),
        (["--scheduler", "my cluster"], "expected a scheduler address"),
        (["--scheduler", "tcp://h:8786", "--workers", "2"], "--workers applies to the local"),
        (["--seed", "-1"], "--seed: must be >= 0"),
        (["--memory-limit", "100"], "--memory-limit: must be >= 512"),
        (["--scheduler", "tcp://h:8786", "--memory-limit", "2048"], "each worker's own"),
        (["--format", "cobol"], "invalid choice: 'cobol'"),
    ],
)
def test_bad_flags_exit_2_with_one_clear_error(
    extra: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["sweep", str(PLATE), "-o", str(tmp_path / "x")]
    if "--samples" not in extra:
        argv += ["--samples", "2"]
    if "--seed" in extra:  # "-1" must reach the flag's own check, not look like an option
        i = extra.index("--seed")
        extra = [*extra[:i], f"--seed={extra[i + 1]}", *extra[i + 2 :]]
    assert main(argv + extra) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "x").exists()  # nothing written


@pytest.mark.reference
@pytest.mark.slow
def test_part_out_of_reach_is_a_row_with_its_reason(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["sweep", str(PLATE), "--samples", "1", "-o", str(tmp_path), "--workers", "0"]
    assert main([*argv, "--part-x=5000:5000", "--part-y", "0", "--base-x", "0"]) == 0
    assert "1 placements (0 kept from before, 1 checked): 0 feasible" in capsys.readouterr().out
    (row,) = read_rows(tmp_path / "sweep.csv").values()
    cell = dict(zip(COLUMNS, row, strict=True))
    assert cell["part_dx_mm"] == "5000.000" and cell["status"] in ("infeasible", "error")
    assert cell["points_feasible"] == "0" and cell["reason"]
    side = json.loads((tmp_path / "sweep.json").read_text())
    assert side["ranges"]["part_dx_mm"] == [5000.0, 5000.0] and side["samples"] == 1


@pytest.mark.reference
def test_a_check_that_raises_becomes_an_error_row(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: object, **kwargs: object) -> None:
        raise InputError("work object: 2 triangles\nout of the cell")

    monkeypatch.setattr(sweep_task, "check_plan", refuse)
    row = sweep_task.check_placement(
        PLATE.read_text(), str(PLATE.parent), None, Placement(0, *[0.0] * 7)
    )
    assert row.status == "error" and row.reason == "error: work object: 2 triangles out of the cell"
    assert row.points_total == len(load_plan(PLATE).points) and math.isnan(row.accuracy_mm)


@pytest.mark.reference
@pytest.mark.slow
def test_a_running_scheduler_runs_the_same_rows(
    serial_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--scheduler ADDRESS``: the workers of a cluster started elsewhere (here a local one of
    one worker process) give the serial rows."""
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
    ) as cluster:
        argv = ["sweep", str(PLATE), "--samples", str(N), "-o", str(tmp_path), "--seed", "3"]
        assert main([*argv, "--scheduler", cluster.scheduler_address]) == 0
    assert f"{N} placements (0 kept from before, {N} checked)" in capsys.readouterr().out
    assert (tmp_path / "sweep.csv").read_text() == (serial_dir / "sweep.csv").read_text()
