"""Robots as ROS packages (issue 25, part 2): xacro files, ``$(find pkg)``, ``package://``.

The reference package is ROS-Industrial's ``abb_irb2400_support`` with ``abb_resources``
(``../shared/reference/ros``): ``urdf/irb2400.xacro`` includes a macro file that includes
``abb_resources``; ``urdf/irb2400.urdf`` is the package's own expansion. The xacro robot must
check exactly like it. Each bad input of ``docs/bad_inputs.md``'s xacro rows is a case here.
"""

from __future__ import annotations

import io
import json
import os
import re
import zipfile
from pathlib import Path
from typing import Any

import pytest
import trimesh

from calib.errors import InputError, PlanError
from calib.plan.file import load_plan
from planner.cli.main import main
from planner.errors import URDFError
from planner.plan_cell import plan_robot_urdf
from planner.robot.description import robot_description
from planner.robot.prepared import write_prepared
from planner.robot.ros_packages import PATH_ENV, find_packages, split_path
from planner.robot.urdf import load_urdf

REPO = Path(__file__).resolve().parents[3]
ROS = Path(__file__).resolve().parents[4] / "shared" / "reference" / "ros"
BASE_PLAN = REPO / "tests" / "data" / "plans" / "valid_three_two_one.json"
pytestmark = pytest.mark.skipif(
    not ROS.is_dir(), reason=f"reference ROS packages not found at {ROS}"
)
SUPPORT = ROS / "abb_irb2400_support"
XACRO = SUPPORT / "urdf" / "irb2400.xacro"
URDF = SUPPORT / "urdf" / "irb2400.urdf"
#: Probe points on a 0.25 x 0.6 x 0.3 m box (wobj frame, m) in front of the IRB 2400.
POINTS = {
    "P1": [0.0, -0.5, -0.15],
    "P2": [0.0, -0.1, -0.15],
    "P3": [0.0, -0.3, -0.05],
    "S1": [-0.05, 0.0, -0.05],
    "S2": [-0.15, 0.0, -0.15],
    "T1": [0.0, -0.3, 0.0],
}


@pytest.fixture(autouse=True)
def _no_ros_env(monkeypatch: pytest.MonkeyPatch) -> None:
    """A developer's own ``ROS_PACKAGE_PATH`` must not change what these tests see."""
    monkeypatch.delenv(PATH_ENV, raising=False)


def _plan(folder: Path, urdf: str | Path, **robot: Any) -> Path:
    """A 3-2-1 plan on a box 0.9-1.15 m in front of the robot, its faces towards it."""
    raw = json.loads(BASE_PLAN.read_text())
    box = trimesh.creation.box(extents=[0.25, 0.6, 0.3])
    box.apply_translation([-0.125, -0.3, -0.15])
    box.export(folder / "box.stl")
    raw["work_object"].update(
        mesh="box.stl",
        units="m",
        T_world_wobj={"position_m": [0.9, 0.3, 0.5], "quat_wxyz": [0.0, 0.0, 0.0, 1.0]},
    )
    raw["validation"]["misplacement"] = {"max_angle_rad": 0.005, "max_translation_m": 0.003}
    for p in raw["points"]:
        p["position_m"] = POINTS[p["id"]]
        p["search"]["overtravel_m"] = 0.03
    raw["cell"]["robot"].update(urdf=str(urdf), **robot)
    path = folder / f"plan_{len(list(folder.glob('plan_*.json')))}.json"
    path.write_text(json.dumps(raw, indent=2))
    return path


def _check(capsys: pytest.CaptureFixture[str], plan: Path) -> tuple[int, str, str]:
    code = main(["check", str(plan), "--json"])
    out, err = capsys.readouterr()
    return code, out, err


def _xacro(folder: Path, body: str, name: str = "robot.xacro") -> Path:
    """A xacro file ``name`` in package ``mypkg`` (in ``folder``) holding ``body``."""
    pkg = folder / "mypkg"
    (pkg / "urdf").mkdir(parents=True, exist_ok=True)
    (pkg / "package.xml").write_text("<package format='2'><name>mypkg</name></package>")
    path = pkg / "urdf" / name
    path.write_text(
        '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">\n'
        f"{body}\n</robot>\n"
    )
    return path


# ---- the xacro robot checks exactly like the package's own URDF --------------------------------
@pytest.mark.slow
def test_xacro_robot_checks_exactly_like_the_packages_own_urdf(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    by_env = _plan(tmp_path, XACRO)  # the packages from ROS_PACKAGE_PATH
    monkeypatch.setenv(PATH_ENV, str(ROS))
    code_x, out_x, err_x = _check(capsys, by_env)
    monkeypatch.delenv(PATH_ENV)
    by_plan = _plan(tmp_path, URDF, package_path=os.path.relpath(ROS, tmp_path))
    code_u, out_u, err_u = _check(capsys, by_plan)
    assert code_x in (0, 1) and code_u in (0, 1), err_x + err_u
    x, u = json.loads(out_x), json.loads(out_u)
    assert x.pop("plan") != u.pop("plan")
    assert x == u
    rows = x["points"]
    assert [r["id"] for r in rows] == list(POINTS)
    assert sum(r["pose_status"] == "feasible" for r in rows) >= 5  # a real, reachable layout
    assert all(len(r["confdata"]) == 4 for r in rows if r["pose_status"] == "feasible")


def test_the_expanded_xacro_has_the_urdfs_links_joints_and_meshes() -> None:
    packages = find_packages((ROS,), PATH_ENV)
    x = load_urdf(robot_description(XACRO, packages))
    u = load_urdf(robot_description(URDF, packages))
    assert x.links == u.links and x.joints == u.joints
    meshes = {g.geometry.mesh_path for link in x.links for g in link.collisions}
    assert all(m is not None and SUPPORT in m.parents for m in meshes)


def test_packages_are_found_by_manifest_name_and_folder_name(tmp_path: Path) -> None:
    (tmp_path / "ws" / "src" / "renamed").mkdir(parents=True)
    (tmp_path / "ws" / "src" / "renamed" / "package.xml").write_text(
        "<package><name>real_name</name></package>"
    )
    (tmp_path / "ws" / "src" / "ignored").mkdir()
    (tmp_path / "ws" / "src" / "ignored" / "CATKIN_IGNORE").write_text("")
    (tmp_path / "ws" / "src" / "ignored" / "inner").mkdir()
    (tmp_path / "ws" / "src" / "ignored" / "inner" / "package.xml").write_text(
        "<package><name>hidden</name></package>"
    )
    found = find_packages(split_path(f"ws:{ROS}:nowhere", tmp_path), "test")
    assert found.find("real_name") == found.find("renamed") == tmp_path / "ws/src/renamed"
    assert found.find("abb_resources") == ROS / "abb_resources"
    with pytest.raises(URDFError, match=r"'hidden' not found in test \(.*nowhere \(missing\)\)"):
        found.find("hidden")


# ---- arguments ---------------------------------------------------------------------------------
def test_xacro_arguments_are_applied_and_unknown_ones_refused(tmp_path: Path) -> None:
    xacro = _xacro(
        tmp_path,
        '<xacro:arg name="prefix" default="a_"/>\n'
        '<xacro:include filename="$(find abb_irb2400_support)/urdf/irb2400_macro.xacro"/>\n'
        '<xacro:abb_irb2400 prefix="$(arg prefix)"/>',
    )
    packages = find_packages((ROS, tmp_path), PATH_ENV)
    default = load_urdf(robot_description(xacro, packages))
    given = load_urdf(robot_description(xacro, packages, {"prefix": "r1_"}))
    assert default.root == "a_base_link" and given.root == "r1_base_link"
    assert {j.name for j in given.joints} >= {"r1_joint_1", "r1_joint_6"}
    with pytest.raises(URDFError, match=r"xacro_args gives colour, which no <xacro:arg>.*prefix"):
        robot_description(xacro, packages, {"colour": "red"})


def test_xacro_arguments_in_the_plan_are_checked_on_load(tmp_path: Path) -> None:
    ok = load_plan(_plan(tmp_path, "r.xacro", xacro_args={"prefix": "r1_"}))
    assert ok.cell.robot.args == {"prefix": "r1_"}
    with pytest.raises(PlanError, match=r"cell\.robot.*xacro_args: given, but urdf 'r\.urdf'"):
        load_plan(_plan(tmp_path, "r.urdf", xacro_args={"prefix": "r1_"}))
    with pytest.raises(PlanError, match=r"xacro_args: '1x' is not an argument name"):
        load_plan(_plan(tmp_path, "r.xacro", xacro_args={"1x": "a"}))


def test_plan_package_path_is_relative_to_the_plan(tmp_path: Path) -> None:
    rel = os.path.relpath(ROS, tmp_path)
    plan = load_plan(_plan(tmp_path, os.path.relpath(XACRO, tmp_path), package_path=rel))
    prepared = plan_robot_urdf(plan, tmp_path)
    assert prepared != XACRO and load_urdf(prepared).name == "abb_irb2400"
    plain = load_plan(_plan(tmp_path, URDF))  # no package path: the URDF as it is, as before
    assert plan_robot_urdf(plain, tmp_path) == URDF


# ---- bad inputs: one line, exit 2 --------------------------------------------------------------
BAD_XACROS = {
    "missing package": (
        '<xacro:include filename="$(find no_such_pkg)/urdf/x.xacro"/>',
        r"\$\(find no_such_pkg\): ROS package 'no_such_pkg' not found in "
        r"cell\.robot\.package_path \(.*\): add the folder",
    ),
    "missing include": (
        '<xacro:include filename="$(find mypkg)/urdf/nope.xacro"/>',
        r"robot\.xacro: xacro include file not found: .*mypkg/urdf/nope\.xacro",
    ),
    "undefined macro": (
        "<xacro:no_such_macro/>",
        r"robot\.xacro: undefined xacro macro <xacro:no_such_macro>",
    ),
    "missing argument": (
        '<link name="$(arg nope)"/>',
        r"xacro argument 'nope' is used \(\$\(arg nope\)\) but neither declared",
    ),
    "include escaping its package": (
        '<xacro:include filename="$(find abb_resources)/../../../../../../../etc/passwd"/>',
        r"robot\.xacro: xacro would read .*abb_resources/\.\./.*etc/passwd, which resolves to "
        r"/etc/passwd, outside the robot's package and the ROS packages given",
    ),
    "package:// escaping its package": (
        '<link name="a"><visual><geometry>'
        '<mesh filename="package://abb_resources/../../../../../../etc/passwd"/>'
        "</geometry></visual></link>",
        r"<link name='a'>: mesh 'package://abb_resources/\.\./.*etc/passwd' climbs out of its "
        r"package with '\.\.'",
    ),
    "malformed XML": ("<link name='a'>", r"robot\.xacro: malformed XML"),
}


@pytest.mark.parametrize("case", list(BAD_XACROS))
def test_bad_xacro_is_one_line_naming_the_cause(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    body, expected = BAD_XACROS[case]
    xacro = _xacro(tmp_path, body)
    plan = _plan(tmp_path, xacro, package_path=f"{ROS}:{tmp_path}")
    code, out, err = _check(capsys, plan)
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("wobjcal check: error: "), err
    assert "Traceback" not in err
    assert re.search(expected, lines[0]), lines[0]


def test_unknown_argument_from_the_plan_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = _plan(tmp_path, XACRO, package_path=str(ROS), xacro_args={"prefix": "r1_"})
    code, _, err = _check(capsys, plan)
    assert code == 2
    assert "xacro_args gives prefix, which no <xacro:arg> of the files read declares" in err


@pytest.mark.parametrize("where", ["plan", "env"])
def test_a_package_path_of_the_root_folder_is_refused(
    where: str, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Was: ``/`` was crawled (4 levels, 1.4 s) and ``$(find abb_irb2400_support)`` took the
    first copy found anywhere on the disk (another user's temporary folder), every package
    found becoming a folder the robot may read."""
    if where == "env":
        monkeypatch.setenv(PATH_ENV, f"{ROS}:/")
        plan = _plan(tmp_path, XACRO)
    else:
        plan = _plan(tmp_path, XACRO, package_path=f"{ROS}:/")
    code, out, err = _check(capsys, plan)
    assert code == 2 and out == ""
    source = PATH_ENV if where == "env" else r"cell\.robot\.package_path"
    assert re.fullmatch(
        f"wobjcal check: error: {source}: the entry / is the file system's root; name the "
        r"folders that hold the ROS packages \(.*\), not a folder above them\n",
        err,
    ), err


def test_find_without_a_package_path_says_how_to_set_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = _check(capsys, _plan(tmp_path, XACRO))
    assert code == 2
    assert "$(find abb_irb2400_support) needs a ROS package path: set" in err
    assert "cell.robot.package_path" in err and "ROS_PACKAGE_PATH" in err


def test_package_uri_escaping_in_a_urdf_and_symbolic_links_out_are_refused(
    tmp_path: Path,
) -> None:
    pkg = tmp_path / "evil"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>evil</name></package>")
    (pkg / "link.stl").symlink_to("/etc/passwd")
    packages = find_packages((tmp_path,), PATH_ENV)
    for uri, expected in (
        ("package://evil/../../../../etc/passwd", "climbs out of its package with '..'"),
        ("package://evil/link.stl", "resolves to /etc/passwd, outside package"),
    ):
        urdf = pkg / "urdf" / "r.urdf"
        urdf.write_text(
            f"<robot name='r'><link name='a'><visual><geometry><mesh filename='{uri}'/>"
            "</geometry></visual></link></robot>"
        )
        with pytest.raises(URDFError, match=expected):
            robot_description(urdf, packages)


def test_a_prepared_file_reads_meshes_only_in_its_listed_packages(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(tmp_path))
    text = (
        "<robot name='r'><link name='a'><visual><geometry><mesh filename='{}'/></geometry>"
        "</visual></link></robot>"
    )
    mesh = SUPPORT / "meshes" / "irb2400" / "collision" / "link_1.stl"
    good = write_prepared(text.format(mesh).encode(), (SUPPORT,))
    assert load_urdf(good).links[0].visuals[0].geometry.mesh_path == mesh
    bad = write_prepared(text.format("/etc/passwd").encode(), (SUPPORT,))
    with pytest.raises(URDFError, match=r"mesh '/etc/passwd' resolves to /etc/passwd, outside"):
        load_urdf(bad)


# ---- the web UI's robot zip --------------------------------------------------------------------
def _zip(*folders: Path, drop: str = "") -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        for folder in folders:
            for f in sorted(folder.rglob("*")):
                rel = f.relative_to(folder.parent).as_posix()
                if f.is_file() and not (drop and rel.endswith(drop)):
                    z.write(f, rel)
    return buf.getvalue()


def test_a_zip_of_ros_packages_expands_its_xacro_within_the_zip(tmp_path: Path) -> None:
    from webui.urdf_zip import unpack_robot_zip

    data = _zip(SUPPORT, ROS / "abb_resources")
    with pytest.raises(InputError, match=r"found [^;]*/irb2400_12_155\.xacro[^;]*; ") as err:
        unpack_robot_zip("abb.zip", data, tmp_path / "a")
    assert "urdf/irb2400.xacro" in str(err.value) and "irb2400.urdf" not in str(err.value)
    assert not (tmp_path / "a").exists()  # refused before unpacking
    urdf = unpack_robot_zip("irb2400.zip", data, tmp_path / "b")
    assert urdf == tmp_path / "b" / "irb2400.expanded.urdf"
    model = load_urdf(urdf)
    own = load_urdf(robot_description(URDF, find_packages((ROS,), "t")))
    assert model.joints == own.joints
    assert [link.name for link in model.links] == [link.name for link in own.links]
    meshes = [g.geometry.mesh_path for link in model.links for g in link.collisions]
    assert meshes and all((tmp_path / "b").resolve() in m.parents for m in meshes if m)


def test_a_zip_without_a_needed_package_names_it(tmp_path: Path) -> None:
    from webui.urdf_zip import unpack_robot_zip

    expected = r"irb2400\.zip: .*'abb_resources' not found in the packages in irb2400\.zip \("
    with pytest.raises(URDFError, match=expected + r"irb2400\.zip\): put that package's"):
        unpack_robot_zip("irb2400.zip", _zip(SUPPORT), tmp_path / "a")


@pytest.mark.slow
def test_the_ui_takes_a_zip_of_ros_packages_as_the_robot(tmp_path: Path) -> None:
    from webui.server import run
    from webui.testing import box_plan, free_port

    app = run(box_plan(tmp_path), port=free_port(), block=False, autosave_path=tmp_path / "a.json")
    try:
        files = app.files_panel
        files.upload_dir = tmp_path / "kept"
        files.upload_urdf("irb2400.zip", _zip(SUPPORT, ROS / "abb_resources"))
        urdf = Path(app.state.doc.source.cell.robot.urdf)
        assert urdf.name == "irb2400.expanded.urdf" and files.upload_dir in urdf.parents
        assert app.view.chain is not None and app.view.chain.n_joints == 6
        assert app.robot is not None, "the robot is drawn from the zip's meshes"
    finally:
        app.stop()


# ---- the prepared file's cache is optional; a moved plan keeps its packages ---------------------
def test_an_unwritable_cache_prepares_the_robot_in_a_temporary_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """Was: exit 2 'cannot write the prepared robot description' when the cache folder was
    read-only or full, though a cache only saves time (issue 27)."""
    blocked = tmp_path / "cache"
    blocked.write_text("a file where the cache folder should be")  # mkdir fails as on a full disk
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(blocked))
    rel = os.path.relpath(ROS, tmp_path)
    plan = load_plan(_plan(tmp_path, os.path.relpath(XACRO, tmp_path), package_path=rel))
    with caplog.at_level("WARNING"):
        prepared = plan_robot_urdf(plan, tmp_path)
    assert not prepared.is_relative_to(blocked) and prepared.is_file()
    assert "using a temporary folder" in caplog.text and str(blocked) in caplog.text
    model = load_urdf(prepared)  # its meshes still read only inside the listed packages
    assert model.name == "abb_irb2400"


def test_a_plan_written_elsewhere_keeps_its_package_path(tmp_path: Path) -> None:
    """Was: `suggest -o other/plan.json` moved the robot's path but not its package path."""
    from planner.suggest import moved_plan

    rel = os.path.relpath(ROS, tmp_path)
    plan = load_plan(_plan(tmp_path, os.path.relpath(XACRO, tmp_path), package_path=rel))
    other = tmp_path / "a" / "b"
    other.mkdir(parents=True)
    moved = moved_plan(plan, tmp_path, other)
    assert moved.cell.robot.packages == os.path.relpath(ROS, other)
    assert plan_robot_urdf(moved, other) == plan_robot_urdf(plan, tmp_path)


def test_a_moved_plan_keeps_a_package_path_from_home(tmp_path: Path) -> None:
    """Was: ``~/ws/src`` was taken for a folder relative to the plan: ``../~/ws/src``."""
    from planner.suggest import moved_plan

    rel = os.path.relpath(ROS, tmp_path)
    plan = load_plan(_plan(tmp_path, XACRO, package_path=f" ~/ws/src :{rel}:"))
    moved = moved_plan(plan, tmp_path, tmp_path / "a")
    assert moved.cell.robot.packages == f"~/ws/src:{os.path.relpath(ROS, tmp_path / 'a')}"
