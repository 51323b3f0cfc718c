"""URDF parsing and validation: bad files raise URDFError naming the file and the element."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from planner.errors import URDFError
from planner.robot.urdf import URDFWarning, load_urdf, matrix_from_rpy, parse_urdf

IRB4400 = Path(__file__).resolve().parent.parent / "assets/robots/irb4400/irb4400.urdf"

TWO_LINKS = """<robot name="r">
  <link name="a"/>
  <link name="b"><collision><geometry>{geom}</geometry></collision></link>
  <joint name="j" type="{jtype}">
    <parent link="a"/><child link="{child}"/>
    <axis xyz="0 0 2"/>{limit}
  </joint>
</robot>"""
LIMIT = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'


def _write(tmp_path: Path, text: str, name: str = "robot.urdf") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def _urdf(
    geom: str = '<box size="1 1 1"/>', jtype: str = "revolute", child: str = "b", limit: str = LIMIT
) -> str:
    return TWO_LINKS.format(geom=geom, jtype=jtype, child=child, limit=limit)


def test_builtin_robot_parses() -> None:
    model = load_urdf(IRB4400)
    assert model.root == "base_link"
    assert model.link_names == ("base_link", *(f"link_{i}" for i in range(1, 7)), "tool0")
    j2 = next(j for j in model.joints if j.name == "joint_2")
    assert (j2.parent, j2.child, j2.type, j2.axis) == ("link_1", "link_2", "revolute", (0, 1, 0))
    assert j2.xyz == (0.2, 0.0, 0.68)
    assert j2.limit is not None and np.isclose(np.rad2deg(j2.limit.lower), -70)
    kinds = {s.geometry.kind for link in model.links for s in link.collisions}
    assert kinds == {"box", "cylinder"}
    assert all(link.collisions for link in model.links if link.name != "tool0")


def test_rpy_matches_scipy_extrinsic_xyz(rng: np.random.Generator) -> None:
    for rpy in rng.uniform(-np.pi, np.pi, (20, 3)):
        np.testing.assert_allclose(
            matrix_from_rpy(tuple(rpy)), Rotation.from_euler("xyz", rpy).as_matrix(), atol=1e-12
        )


def test_axis_is_normalised(tmp_path: Path) -> None:
    model = load_urdf(_write(tmp_path, _urdf()))
    assert model.joints[0].axis == (0.0, 0.0, 1.0)


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(URDFError, match=r"URDF file not found: .*nope\.urdf"):
        load_urdf(tmp_path / "nope.urdf")


def test_malformed_xml_names_file(tmp_path: Path) -> None:
    p = _write(tmp_path, "<robot name='r'><link name='a'></robot>")
    with pytest.raises(URDFError, match=r"robot\.urdf: malformed XML"):
        load_urdf(p)


def test_no_robot_element(tmp_path: Path) -> None:
    with pytest.raises(URDFError, match=r"top element must be <robot>, got <sdf>"):
        load_urdf(_write(tmp_path, "<sdf/>"))


def test_unknown_link_names_joint(tmp_path: Path) -> None:
    p = _write(tmp_path, _urdf(child="c"))
    with pytest.raises(URDFError, match=r"robot\.urdf: <joint name='j'> child link 'c' is unknown"):
        load_urdf(p)


def test_revolute_without_limits(tmp_path: Path) -> None:
    p = _write(tmp_path, _urdf(limit=""))
    with pytest.raises(URDFError, match=r"<joint name='j'> is revolute but has no <limit"):
        load_urdf(p)


def test_continuous_without_limits_is_fine(tmp_path: Path) -> None:
    model = load_urdf(_write(tmp_path, _urdf(jtype="continuous", limit="")))
    assert model.joints[0].limit is None


def test_cycle_and_multiple_roots(tmp_path: Path) -> None:
    two_roots = '<robot name="r"><link name="a"/><link name="b"/></robot>'
    with pytest.raises(URDFError, match=r"several roots \['a', 'b'\]"):
        load_urdf(_write(tmp_path, two_roots))
    cycle = """<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="j1" type="fixed"><parent link="b"/><child link="c"/></joint>
      <joint name="j2" type="fixed"><parent link="c"/><child link="b"/></joint></robot>"""
    with pytest.raises(URDFError, match=r"\['b', 'c'\] form a cycle"):
        load_urdf(_write(tmp_path, cycle, "cycle.urdf"))
    two_parents = """<robot name="r"><link name="a"/><link name="b"/>
      <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
      <joint name="j2" type="fixed"><parent link="a"/><child link="b"/></joint></robot>"""
    with pytest.raises(URDFError, match=r"'b' is the child of two joints, 'j1' and 'j2'"):
        load_urdf(_write(tmp_path, two_parents, "two.urdf"))


def test_bad_numbers_name_the_element(tmp_path: Path) -> None:
    p = _write(tmp_path, _urdf(limit='<limit lower="x" upper="1"/>'))
    with pytest.raises(URDFError, match=r"<joint name='j'> <limit lower> must be 1 numbers"):
        load_urdf(p)


def test_mimic_is_ignored_with_a_warning(tmp_path: Path) -> None:
    text = _urdf(limit=LIMIT + '<mimic joint="x"/>')
    with pytest.warns(URDFWarning, match=r"<joint name='j'>: <mimic> is ignored"):
        load_urdf(_write(tmp_path, text))


def test_mesh_resolution(tmp_path: Path) -> None:
    pkg = tmp_path / "my_robot_description"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "urdf").mkdir()
    mesh = pkg / "meshes" / "b.stl"
    mesh.write_text("solid x\nendsolid x\n")
    for uri in (
        "package://my_robot_description/meshes/b.stl",
        "../meshes/b.stl",
        f"file://{mesh}",
    ):
        p = _write(pkg / "urdf", _urdf(geom=f'<mesh filename="{uri}" scale="2 2 2"/>'))
        g = load_urdf(p).link("b").collisions[0].geometry
        assert g.kind == "mesh" and g.mesh_path is not None
        assert g.mesh_path.resolve() == mesh.resolve() and g.scale == (2.0, 2.0, 2.0)


def test_missing_mesh_is_reported(tmp_path: Path) -> None:
    p = _write(tmp_path, _urdf(geom='<mesh filename="package://pkg/meshes/gone.stl"/>'))
    with pytest.raises(URDFError, match=r"mesh file\(s\) not found: link 'b'.*gone\.stl"):
        load_urdf(p)
    model = load_urdf(p, check_meshes=False)
    assert model.missing_meshes() == [("b", "package://pkg/meshes/gone.stl")]


def test_reference_ur5_meshes_resolve(reference_dir: Path) -> None:
    model = load_urdf(reference_dir / "robots/ur5/ur5.urdf")
    assert not model.missing_meshes()
    assert model.root == "base_link"


def test_parse_from_string_without_file() -> None:
    model = parse_urdf(_urdf())
    assert model.path is None and model.joints[0].name == "j"
