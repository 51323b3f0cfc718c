"""Bounded file reads (issue 10, items 7 and 8): devices, pipes, directories and huge files are
refused with a message naming the file before anything is read."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from calib.errors import InputError
from calib.plan.file import PlanError, load_plan
from calib.plan.measurements import MeasurementsError, load_measurements
from calib.reading import MAX_JSON_BYTES, check_regular_file, read_bytes_capped


def test_dev_zero_a_directory_and_a_pipe_are_refused(tmp_path: Path) -> None:
    """Item 7: a plan path to /dev/zero read until memory ran out; item 8: a directory was
    'file not found'."""
    with pytest.raises(PlanError, match=r"/dev/zero: not a regular file .* so not a plan file"):
        load_plan("/dev/zero")
    with pytest.raises(PlanError, match=r"is a directory, not a plan file"):
        load_plan(tmp_path)
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)
    with pytest.raises(MeasurementsError, match=r"pipe\.json: not a regular file"):
        load_measurements(fifo)  # would block forever if opened
    with pytest.raises(FileNotFoundError) as info:
        load_plan(tmp_path / "missing.json")
    assert info.value.filename == str(tmp_path / "missing.json")


def test_a_huge_file_is_refused_from_its_size(tmp_path: Path) -> None:
    big = tmp_path / "big.json"
    with big.open("wb") as handle:  # sparse: 2 GiB without writing them
        handle.truncate(2 << 30)
    with pytest.raises(PlanError, match=r"big\.json: 2048\.0 MiB is more than a plan file may"):
        load_plan(big)
    small = tmp_path / "small.bin"
    small.write_bytes(b"x" * 10)
    assert read_bytes_capped(small, 10, "thing") == b"x" * 10
    with pytest.raises(InputError, match=r"more than a thing may have"):
        check_regular_file(small, 9, "thing")
    assert MAX_JSON_BYTES == 16 << 20


def test_a_mesh_path_that_is_a_directory_is_named(tmp_path: Path) -> None:
    """Item 8: a directory was reported as 'file not found'."""
    import json

    from calib.plan.file import check_plan_files, plan_from_json

    doc = json.loads(
        (Path(__file__).resolve().parents[1] / "data/plans/valid_three_two_one.json").read_text()
    )
    doc["work_object"]["mesh"] = str(tmp_path)
    doc["work_object"]["sha256"] = None
    plan = plan_from_json(json.dumps(doc))
    with pytest.raises(PlanError, match=r"work_object\.mesh: .* is a directory, not a mesh file"):
        check_plan_files(plan, tmp_path)
