"""A plan with its files as one ZIP (:mod:`calib.plan.bundle`): unpacked anywhere it loads, its
references resolve inside it to the same bytes, it is deterministic, and it refuses clearly."""

from __future__ import annotations

import io
import os
import re
import shutil
import zipfile
from pathlib import Path

import msgspec
import pytest

from calib.errors import PlanError
from calib.plan import bundle
from calib.plan.base import resolve_ref
from calib.plan.bundle import (
    file_refs,
    plan_bundle,
    rebased_plan,
    save_plan_bundle,
    with_refs,
)
from calib.plan.cell import FixtureSpec
from calib.plan.file import Plan, load_plan, plan_to_json

REPO = Path(__file__).resolve().parents[3]
PLATE_PLAN = REPO / "assets" / "plans" / "plate_holes_best_fit.json"
CABLE_FEEDER = REPO / "assets" / "tools" / "cable_feeder"


def _unpack(data: bytes, folder: Path, stem: str) -> tuple[Plan, Path]:
    """Extract ``data`` into ``folder`` (fresh) and load its plan, digests checked."""
    folder.mkdir()
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        assert archive.testzip() is None
        archive.extractall(folder)
    return load_plan(folder / stem / f"{stem}.json"), folder / stem


def _assert_same_files(plan: Plan, plan_dir: Path, unpacked: Plan, bundle_dir: Path) -> None:
    """Every file reference of ``unpacked`` is relative, lies in ``bundle_dir`` and holds the
    bytes of the original's; ``builtin:`` ones unchanged."""
    before, after = dict(file_refs(plan)), dict(file_refs(unpacked))
    assert after.keys() == before.keys()
    for where, ref in after.items():
        assert not Path(ref).is_absolute(), where
        path = Path(resolve_ref(ref, bundle_dir)).resolve()
        assert path.is_relative_to(bundle_dir.resolve()), (where, path)
        original = Path(resolve_ref(before[where], plan_dir))
        assert path.read_bytes() == original.read_bytes(), where
    builtins = {k for k, _ in file_refs(plan)}
    assert plan.cell.robot.urdf == unpacked.cell.robot.urdf or "cell.robot.urdf" in builtins
    assert plan.cell.tool.name == unpacked.cell.tool.name or "cell.tool.name" in builtins


@pytest.fixture
def ur5_plan(tmp_path: Path, reference_dir: Path) -> tuple[Plan, Path]:
    """The plate plan moved into ``tmp_path/plans``, on the UR5 (its folder copied into
    ``tmp_path/robots``), the cable feeder as a file tool, the part's mesh outside the plan's
    folder (absolute), and two fixtures whose meshes share a file name."""
    plans, robots, parts = tmp_path / "plans", tmp_path / "robots", tmp_path / "parts"
    plans.mkdir()
    shutil.copytree(reference_dir / "robots" / "ur5", robots / "ur5")
    shutil.copytree(CABLE_FEEDER, tmp_path / "tools" / "feeder")
    parts.mkdir()
    mesh = parts / "plate_holes.STL"
    shutil.copyfile(reference_dir / "parts" / "plate_holes.STL", mesh)
    for sub, text in (("a", "solid a\nendsolid a\n"), ("b", "solid b\nendsolid b\n")):
        (parts / sub).mkdir()
        (parts / sub / "block.stl").write_text(text)
    plan = load_plan(PLATE_PLAN)
    fixtures = [
        FixtureSpec(name="left", mesh="../parts/a/block.stl"),
        FixtureSpec(name="right", mesh=str(parts / "b" / "block.stl")),
        *plan.cell.fixtures,
    ]
    cell = msgspec.structs.replace(plan.cell, fixtures=fixtures)
    plan = msgspec.structs.replace(plan, cell=cell)
    plan = with_refs(
        plan,
        {
            "cell.robot.urdf": "../robots/ur5/ur5.urdf",
            "cell.tool.name": "../tools/feeder/tool.json",
            "work_object.mesh": str(mesh),
        },
    )
    (plans / "ur5.json").write_text(plan_to_json(plan))
    return load_plan(plans / "ur5.json"), plans


def test_the_plate_plan_unpacks_anywhere(tmp_path: Path, reference_dir: Path) -> None:
    plan = load_plan(PLATE_PLAN)
    data = plan_bundle(plan, PLATE_PLAN.parent, "plate")
    unpacked, folder = _unpack(data, tmp_path / "x", "plate")
    _assert_same_files(plan, PLATE_PLAN.parent, unpacked, folder)
    assert unpacked.work_object.mesh == "files/work_object/plate_holes.STL"
    assert unpacked.work_object.sha256 == plan.work_object.sha256
    assert unpacked.cell.robot.urdf == "builtin:irb4400"  # built-ins: unchanged, no file
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        assert archive.namelist() == ["plate/files/work_object/plate_holes.STL", "plate/plate.json"]
    assert msgspec.structs.replace(unpacked, work_object=plan.work_object) == plan


def test_a_plan_with_files_elsewhere_unpacks_anywhere(
    tmp_path: Path, ur5_plan: tuple[Plan, Path]
) -> None:
    from planner.robot.urdf import load_urdf

    plan, plan_dir = ur5_plan
    data = plan_bundle(plan, plan_dir, "ur5")
    unpacked, folder = _unpack(data, tmp_path / "elsewhere", "ur5")
    _assert_same_files(plan, plan_dir, unpacked, folder)
    assert unpacked.cell.robot.urdf == "files/robot/ur5/ur5.urdf"
    assert unpacked.cell.tool.name == "files/tool/feeder/tool.json"
    assert [f.mesh for f in unpacked.cell.fixtures] == [
        "files/fixtures/block.stl",
        "files/fixtures/block-2.stl",
        None,
    ]
    robot = tmp_path / "robots" / "ur5"
    copied = {p.relative_to(robot) for p in robot.rglob("*") if p.is_file()}
    assert {p.relative_to(folder / "files/robot/ur5") for p in folder.rglob("*") if p.is_file()
            and p.is_relative_to(folder / "files/robot/ur5")} == copied  # fmt: skip
    assert (folder / "files/tool/feeder/cable_feeder.urdf").is_file()  # beside tool.json
    model = load_urdf(folder / unpacked.cell.robot.urdf)  # every mesh found in the copy
    assert not model.missing_meshes()


def test_the_same_plan_gives_the_same_bytes(tmp_path: Path, ur5_plan: tuple[Plan, Path]) -> None:
    plan, plan_dir = ur5_plan
    first = plan_bundle(plan, plan_dir, "ur5")
    os.utime(tmp_path / "robots" / "ur5" / "ur5.urdf", (1e9, 1e9))  # time stamps do not count
    assert plan_bundle(plan, plan_dir, "ur5") == first
    with zipfile.ZipFile(io.BytesIO(first)) as archive:
        infos = archive.infolist()
    assert [i.filename for i in infos] == sorted(i.filename for i in infos)
    assert {i.date_time for i in infos} == {(1980, 1, 1, 0, 0, 0)}
    assert {i.compress_type for i in infos} == {zipfile.ZIP_DEFLATED}


def test_a_missing_file_is_named(tmp_path: Path, ur5_plan: tuple[Plan, Path]) -> None:
    plan, plan_dir = ur5_plan
    robot = with_refs(plan, {"cell.robot.urdf": "../robots/ur10/ur10.urdf"})
    with pytest.raises(PlanError, match=r"cell\.robot\.urdf: file not found: .*ur10\.urdf"):
        plan_bundle(robot, plan_dir, "ur5")
    gone = tmp_path / "parts" / "plate_holes.STL"
    gone.unlink()
    with pytest.raises(PlanError, match=re.escape(f"work_object.mesh: file not found: {gone}")):
        plan_bundle(plan, plan_dir, "ur5")


def test_too_many_bytes_name_the_limit(
    monkeypatch: pytest.MonkeyPatch, ur5_plan: tuple[Plan, Path]
) -> None:
    plan, plan_dir = ur5_plan
    monkeypatch.setattr(bundle, "MAX_BUNDLE_BYTES", 100_000)
    with pytest.raises(PlanError, match=r"limit of 100,000 bytes \(MAX_BUNDLE_BYTES\) at /"):
        plan_bundle(plan, plan_dir, "ur5")


def test_a_link_out_of_the_robot_folder_is_not_followed(
    tmp_path: Path, ur5_plan: tuple[Plan, Path]
) -> None:
    plan, plan_dir = ur5_plan
    robot = tmp_path / "robots" / "ur5"
    secret = tmp_path / "secret"
    secret.mkdir()
    (secret / "key.txt").write_text("not for the bundle")
    try:
        (robot / "key.txt").symlink_to(secret / "key.txt")
        (robot / "outside").symlink_to(secret, target_is_directory=True)
        (robot / "meshes" / "again").symlink_to(robot / "meshes", target_is_directory=True)
        (robot / "shared").symlink_to(robot / "meshes" / "collision", target_is_directory=True)
        (robot / "base.stl").symlink_to(robot / "meshes" / "collision" / "base.stl")
    except OSError as exc:  # no symbolic links here (Windows without the privilege)
        pytest.skip(f"cannot make symbolic links: {exc}")
    (robot / ".git").mkdir()
    (robot / ".git" / "HEAD").write_text("ref: refs/heads/main\n")
    (robot / "ur5.zip").write_bytes(plan_bundle(plan, plan_dir, "ur5"))  # an earlier bundle
    with zipfile.ZipFile(io.BytesIO(plan_bundle(plan, plan_dir, "ur5"))) as archive:
        names = archive.namelist()
    assert not [n for n in names if "key.txt" in n or "/outside" in n or ".git" in n]
    assert not [n for n in names if n.endswith(".zip")], "no bundle inside the next one"
    assert "ur5/files/robot/ur5/base.stl" in names  # a link inside: its file is copied
    assert "ur5/files/robot/ur5/shared/base.stl" in names  # and a folder's files
    assert not [n for n in names if "/again" in n]  # a link to a folder above it: a loop


def test_a_package_path_is_bundled(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, reference_dir: Path
) -> None:
    """A xacro robot in a ROS package found on the package path: the path's folder is copied
    once (the robot points into it) and the unpacked plan expands with meshes in the copy."""
    from planner.robot.description import prepared_urdf
    from planner.robot.ros_packages import package_path

    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    ros = reference_dir / "ros"
    xacro = ros / "abb_irb2400_support" / "urdf" / "irb2400.xacro"
    spec = msgspec.structs.replace(
        load_plan(PLATE_PLAN).cell.robot,
        urdf=str(xacro),
        package_path=f"{ros}: {tmp_path / 'missing'} :",
    )
    plan = load_plan(PLATE_PLAN)
    plan = msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, robot=spec))
    unpacked, folder = _unpack(plan_bundle(plan, PLATE_PLAN.parent, "abb"), tmp_path / "x", "abb")
    _assert_same_files(plan, PLATE_PLAN.parent, unpacked, folder)
    robot = unpacked.cell.robot
    assert robot.packages == "files/packages/0/ros"  # the missing folder left out
    assert robot.urdf == "files/packages/0/ros/abb_irb2400_support/urdf/irb2400.xacro"
    assert not (folder / "files" / "robot").exists()
    source = folder / robot.urdf
    urdf, roots = prepared_urdf(source, package_path(robot.packages, folder))
    assert roots and all(r.is_relative_to(folder.resolve()) for r in roots)
    meshes = re.findall(rb'filename="([^"]+)"', urdf)
    assert meshes and all(Path(m.decode()).is_relative_to(folder.resolve()) for m in meshes)


def test_a_xacro_without_package_path_is_said(
    caplog: pytest.LogCaptureFixture, reference_dir: Path
) -> None:
    """Its packages are then found where the bundle is used, not bundled: a warning says so."""
    xacro = reference_dir / "ros" / "abb_irb2400_support" / "urdf" / "irb2400.xacro"
    plan = load_plan(PLATE_PLAN)
    robot = msgspec.structs.replace(plan.cell.robot, urdf=str(xacro))
    plan = msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, robot=robot))
    with caplog.at_level("WARNING", logger="calib.plan.bundle"):
        data = plan_bundle(plan, PLATE_PLAN.parent, "abb")
    assert "ROS_PACKAGE_PATH" in caplog.text and str(xacro) in caplog.text
    with zipfile.ZipFile(io.BytesIO(data)) as archive:  # its own package, whole
        assert "abb/files/robot/abb_irb2400_support/package.xml" in archive.namelist()


def test_the_robot_folder_is_the_one_the_urdf_reads(tmp_path: Path) -> None:
    """The folder copied for a URDF is :func:`planner.robot.urdf_meshes.package_root`'s."""
    from planner.robot.urdf_meshes import package_root

    for layout in ("pkg/urdf", "pkg/robots/urdf", "plain/robot", "other/urdf"):
        (tmp_path / layout).mkdir(parents=True)
    (tmp_path / "pkg" / "package.xml").write_text("<package><name>pkg</name></package>")
    for layout in ("pkg/urdf", "pkg/robots/urdf", "plain/robot", "other/urdf"):
        folder = tmp_path / layout
        assert bundle._package_root(folder) == package_root(folder), layout


def test_a_bad_stem_is_refused(ur5_plan: tuple[Plan, Path]) -> None:
    plan, plan_dir = ur5_plan
    for stem in ("", "a/b", "..", ".hidden", "x" * 101, "a\\b", "end."):
        with pytest.raises(PlanError, match="stem"):
            plan_bundle(plan, plan_dir, stem)


def test_save_plan_bundle_writes_the_archive(tmp_path: Path, ur5_plan: tuple[Plan, Path]) -> None:
    plan, plan_dir = ur5_plan
    out = save_plan_bundle(plan, plan_dir, tmp_path / "cell_plan.zip")
    assert out.read_bytes() == plan_bundle(plan, plan_dir, "cell_plan")


@pytest.mark.reference
def test_file_refs_and_rebased_plan(tmp_path: Path) -> None:
    plan = load_plan(PLATE_PLAN)
    assert file_refs(plan) == [("work_object.mesh", plan.work_object.mesh)]  # built-ins left out
    with pytest.raises(PlanError, match="no file reference"):
        with_refs(plan, {"cell.fixtures[0].mesh": "table.stl"})  # a box: no reference
    robot = msgspec.structs.replace(
        plan.cell.robot, urdf="r/robot.urdf", package_path=" ~/ws/src : ros :"
    )
    plan = msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, robot=robot))
    moved = rebased_plan(plan, tmp_path, tmp_path / "a")
    assert Path(moved.cell.robot.urdf) == Path("..", "r", "robot.urdf")
    assert moved.cell.robot.package_path == f"~/ws/src:{Path('..', 'ros')}"
    assert moved.work_object.mesh == os.path.relpath(
        (tmp_path / plan.work_object.mesh).resolve(), (tmp_path / "a").resolve()
    )
    from planner.suggest import moved_plan

    assert moved_plan(plan, tmp_path, tmp_path / "a") == moved


@pytest.mark.slow
def test_check_gives_the_same_statuses_unpacked(tmp_path: Path, reference_dir: Path) -> None:
    from planner.check.job import check_plan

    plan = load_plan(PLATE_PLAN)
    unpacked, folder = _unpack(
        plan_bundle(plan, PLATE_PLAN.parent, "plate"), tmp_path / "x", "plate"
    )

    def statuses(result: object) -> list[tuple[str, str, str]]:
        return [(p.point_id, p.status, p.reason) for p in result.points]  # type: ignore[attr-defined]

    before = check_plan(plan, PLATE_PLAN.parent)
    after = check_plan(unpacked, folder)
    assert statuses(after) == statuses(before)
    assert after.error == before.error and after.part_units == before.part_units


def test_a_bundled_or_moved_plan_keeps_its_digest(
    tmp_path: Path, ur5_plan: tuple[Plan, Path]
) -> None:
    """helper-56 (D7): the plan in the UI's ZIP had another digest than the programs exported
    from it (its paths rewritten), so calibrate refused their results. Where the files lie is
    not the plan; its points are."""
    from calib.plan.file import plan_digest

    plan, plan_dir = ur5_plan
    unpacked, _ = _unpack(plan_bundle(plan, plan_dir, "ur5"), tmp_path / "elsewhere", "ur5")
    assert unpacked.cell.fixtures[1].mesh == "files/fixtures/block-2.stl"  # renamed too
    moved = rebased_plan(plan, plan_dir, tmp_path / "other")
    assert plan_digest(unpacked) == plan_digest(plan) == plan_digest(moved)
    p0 = plan.points[0]
    shifted = msgspec.structs.replace(p0, position_m=(p0.position_m[0] + 1e-4, *p0.position_m[1:]))
    other = msgspec.structs.replace(plan, points=[shifted, *plan.points[1:]])
    assert plan_digest(other) != plan_digest(plan)  # a point moved 0.1 mm: another plan
    # another robot file (its controller's base frame may be turned): another plan
    robot = msgspec.structs.replace(plan.cell.robot, urdf="../robots/irb2400/irb2400.urdf")
    swapped = msgspec.structs.replace(plan, cell=msgspec.structs.replace(plan.cell, robot=robot))
    assert plan_digest(swapped) != plan_digest(plan)
