"""URDF parsing and validation: bad files raise URDFError naming the file and the element."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from planner.errors import URDFError
from planner.robot.urdf import URDFWarning, load_urdf, matrix_from_rpy, parse_urdf

IRB4400 = Path(__file__).resolve().parents[3] / "assets/robots/irb4400/irb4400.urdf"

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


# --- inertials, poses at zero, mass and centre of mass -------------------------------------

INERTIAL = """<robot name="r">
  <link name="a">
    <inertial><origin xyz="0.1 0 0"/><mass value="2"/>
      <inertia ixx="1" ixy="0.1" ixz="0.2" iyy="2" iyz="0.3" izz="3"/></inertial>
  </link>
  <link name="b">
    <inertial><origin xyz="0.3 0 0" rpy="0.4 0 0"/><mass value="1"/>
      <inertia ixx="0.5" ixy="0" ixz="0" iyy="0.5" iyz="0" izz="0.5"/></inertial>
  </link>
  <link name="c"/>
  <joint name="ab" type="revolute">
    <parent link="a"/><child link="b"/>
    <origin xyz="0 0 1" rpy="0 0 1.5707963267948966"/>
    <axis xyz="0 0 1"/>{limit}
  </joint>
  <joint name="bc" type="fixed"><parent link="b"/><child link="c"/></joint>
</robot>""".replace("{limit}", LIMIT)


def test_inertials_are_parsed() -> None:
    model = parse_urdf(INERTIAL)
    a, b = model.link("a").inertial, model.link("b").inertial
    assert a is not None and b is not None and model.link("c").inertial is None
    assert (a.mass, a.xyz, a.inertia) == (2.0, (0.1, 0.0, 0.0), (1.0, 0.1, 0.2, 2.0, 0.3, 3.0))
    np.testing.assert_array_equal(
        a.inertia_matrix, [[1.0, 0.1, 0.2], [0.1, 2.0, 0.3], [0.2, 0.3, 3.0]]
    )
    expected = np.eye(4)
    expected[:3, :3] = Rotation.from_euler("x", 0.4).as_matrix()
    expected[:3, 3] = [0.3, 0.0, 0.0]
    np.testing.assert_allclose(b.T_link_com, expected, atol=1e-15)


def test_mass_and_com_by_hand() -> None:
    """b hangs 1 m above a, turned 90 deg about z: b's x offset 0.3 lands on a's +y."""
    model = parse_urdf(INERTIAL)
    mass, com = model.mass_and_com()
    assert mass == 3.0
    # (2 kg * (0.1, 0, 0) + 1 kg * (0, 0.3, 1)) / 3 kg
    np.testing.assert_allclose(com, [0.2 / 3, 0.1, 1 / 3], atol=1e-15)
    mass_b, com_b = model.mass_and_com("b")
    assert mass_b == 1.0
    np.testing.assert_allclose(com_b, [0.3, 0.0, 0.0], atol=1e-15)
    assert model.mass_and_com("c") == (0.0, pytest.approx(np.zeros(3)))


def test_link_poses_at_zero_and_fixed_link_poses() -> None:
    model = parse_urdf(INERTIAL)
    poses = model.link_poses_at_zero()
    assert list(poses) == ["a", "b", "c"]
    np.testing.assert_allclose(poses["c"][:3, 3], [0.0, 0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(poses["c"][:3, 0], [0.0, 1.0, 0.0], atol=1e-15)
    assert list(model.fixed_link_poses("b")) == ["b", "c"]
    with pytest.raises(URDFError, match=r"<joint name='ab'> is revolute, not fixed"):
        model.fixed_link_poses()
    with pytest.raises(URDFError, match=r"no link 'zz'"):
        model.link_poses_at_zero("zz")


def test_inertial_without_mass_warns_and_weighs_nothing() -> None:
    text = (
        '<robot name="r"><link name="a"><inertial><origin xyz="1 0 0"/></inertial></link></robot>'
    )
    with pytest.warns(URDFWarning, match=r"<link name='a'> <inertial> has no <mass>"):
        model = parse_urdf(text)
    assert model.mass_and_com()[0] == 0.0


def test_origin_rpy_is_an_equivalent_triple(rng: np.random.Generator) -> None:
    """rpy comes back from yourdfpy's matrix: maybe another triple, always the same frame."""
    rpys = [*rng.uniform(-4, 4, (30, 3)), (0.3, np.pi / 2, -1.0), (2.0, -np.pi / 2, 0.5)]
    for rpy in [tuple(float(v) for v in r) for r in rpys]:
        xyz = tuple(float(v) for v in rng.uniform(-1, 1, 3))
        text = _urdf().replace(
            '<axis xyz="0 0 2"/>',
            f'<origin xyz="{" ".join(map(repr, xyz))}" '
            f'rpy="{" ".join(map(repr, rpy))}"/><axis xyz="0 0 2"/>',
        )
        j = parse_urdf(text).joints[0]
        assert j.xyz == xyz
        T = np.eye(4)
        T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
        T[:3, 3] = xyz
        np.testing.assert_allclose(j.T_parent_joint, T, atol=1e-14)


def test_named_materials_give_the_visual_colour() -> None:
    text = """<robot name="r"><material name="orange"><color rgba="1 0.5 0 1"/></material>
      <link name="a">
        <visual><geometry><sphere radius="1"/></geometry><material name="orange"/></visual>
        <visual><geometry><sphere radius="1"/></geometry>
          <material name="x"><color rgba="0 0 1 1"/></material></visual>
        <visual><geometry><sphere radius="1"/></geometry><material name="unknown"/></visual>
      </link></robot>"""
    colours = [v.rgba for v in parse_urdf(text).link("a").visuals]
    assert colours == [(1.0, 0.5, 0.0, 1.0), (0.0, 0.0, 1.0, 1.0), None]


# --- odd but valid inputs ------------------------------------------------------------------


def test_single_link_is_valid_but_not_a_robot_chain(tmp_path: Path) -> None:
    """One link, no joints: a valid URDF (a tool or a fixed body); a robot chain refuses it."""
    from planner.robot.kinematics.chain import KinematicChain

    p = _write(tmp_path, '<robot name="r"><link name="a"/></robot>', "one.urdf")
    model = load_urdf(p)
    assert (model.root, model.joints) == ("a", ())
    assert list(model.fixed_link_poses()) == ["a"]
    with pytest.raises(URDFError, match=r"one\.urdf: no moving joint between base link 'a'"):
        KinematicChain.from_model(model)


def test_text_with_an_xml_declaration_and_bytes() -> None:
    declared = '<?xml version="1.0" encoding="utf-8"?>\n' + _urdf()
    assert parse_urdf(declared).joints[0].name == "j"
    latin1 = (
        '<?xml version="1.0" encoding="iso-8859-1"?><robot name="r"><link name="\xe9"/></robot>'
    )
    assert parse_urdf(latin1.encode("latin-1")).root == "\xe9"


# --- every error names the file and the element, never a raw yourdfpy/lxml error ----------

REV = '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>{}</joint>'
AB = '<link name="a"/><link name="b"/>'
BAD = {
    "not_xml": ("solid cube\n  facet normal 0 0 1\n", r"malformed XML"),
    "binary": ("\x00\x01\x02STL", r"malformed XML"),
    "empty": ("", r"malformed XML"),
    "truncated": ('<robot name="r"><link name="a">', r"malformed XML"),
    "no_links": ('<robot name="r"/>', r"<robot name='r'> has no <link>"),
    "link_no_name": ('<robot name="r"><link/></robot>', r"a <link> element has no name"),
    "dup_link": ('<robot name="r"><link name="a"/><link name="a"/></robot>', r"duplicate .*'a'"),
    "joint_no_name": (
        '<robot name="r">' + AB + '<joint type="fixed"><parent link="a"/><child link="b"/>'
        "</joint></robot>",
        r"a <joint> element has no name",
    ),
    "joint_type": (
        '<robot name="r">' + AB + REV.replace("revolute", "hinge").format("") + "</robot>",
        r"<joint name='j'> has type 'hinge'",
    ),
    "no_parent": (
        '<robot name="r">' + AB + '<joint name="j" type="fixed"><child link="b"/></joint></robot>',
        r"<joint name='j'> needs <parent link=...> and <child link=...>",
    ),
    "prismatic_no_limit": (
        '<robot name="r">' + AB + REV.replace("revolute", "prismatic").format("") + "</robot>",
        r"<joint name='j'> is prismatic but has no <limit",
    ),
    "lower_above_upper": (
        '<robot name="r">' + AB + REV.format('<limit lower="1" upper="0"/>') + "</robot>",
        r"<joint name='j'> <limit> has lower 1.0 > upper 0.0",
    ),
    "zero_axis": (
        '<robot name="r">' + AB + REV.format('<axis xyz="0 0 0"/>' + LIMIT) + "</robot>",
        r"<joint name='j'> has a zero <axis xyz>",
    ),
    "xyz_two": (
        '<robot name="r">' + AB + REV.format('<origin xyz="1 2"/>' + LIMIT) + "</robot>",
        r"<joint name='j'> <origin xyz> must be 3 finite numbers, got '1 2'",
    ),
    "xyz_four": (  # yourdfpy would silently drop the fourth number
        '<robot name="r">' + AB + REV.format('<origin xyz="1 2 3 4"/>' + LIMIT) + "</robot>",
        r"<joint name='j'> <origin xyz> must be 3 finite numbers",
    ),
    "rpy_nan": (  # yourdfpy would make the whole origin NaN
        '<robot name="r">' + AB + REV.format('<origin rpy="0 nan 0"/>' + LIMIT) + "</robot>",
        r"<joint name='j'> <origin rpy> must be 3 finite numbers",
    ),
    "axis_text": (
        '<robot name="r">' + AB + REV.format('<axis xyz="0 0 z"/>' + LIMIT) + "</robot>",
        r"<joint name='j'> <axis xyz> must be 3 numbers",
    ),
    "safety_controller": (  # not checked by us: yourdfpy's own ValueError, wrapped
        '<robot name="r">'
        + AB
        + REV.format(LIMIT + '<safety_controller k_velocity="fast"/>')
        + "</robot>",
        r"<joint name='j'> cannot be read: ValueError",
    ),
    "no_geometry": (
        '<robot name="r"><link name="a"><visual/></link></robot>',
        r"<link name='a'> <visual> has no <geometry>",
    ),
    "unknown_geometry": (
        '<robot name="r"><link name="a"><collision><geometry><cone/></geometry></collision>'
        "</link></robot>",
        r"<link name='a'> <collision> has unknown geometry <cone>",
    ),
    "box_no_size": (
        '<robot name="r"><link name="a"><collision><geometry><box/></geometry></collision>'
        "</link></robot>",
        r"<link name='a'> <collision> <box> has no size",
    ),
    "mesh_no_filename": (
        '<robot name="r"><link name="a"><visual><geometry><mesh/></geometry></visual>'
        "</link></robot>",
        r"<link name='a'> <visual> <mesh> has no filename",
    ),
    "rgba_three": (
        '<robot name="r"><link name="a"><visual><geometry><sphere radius="1"/></geometry>'
        '<material name="m"><color rgba="1 0 0"/></material></visual></link></robot>',
        r"<link name='a'> <visual> <color rgba> must be 4 finite numbers",
    ),
    "mass_text": (
        '<robot name="r"><link name="a"><inertial><mass value="heavy"/></inertial></link></robot>',
        r"<link name='a'> <inertial> <mass value> must be 1 numbers, got 'heavy'",
    ),
    "mass_negative": (
        '<robot name="r"><link name="a"><inertial><mass value="-1"/></inertial></link></robot>',
        r"<link name='a'> <inertial> <mass value> must be >= 0 kg",
    ),
    "inertia_inf": (
        '<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx="inf"/>'
        "</inertial></link></robot>",
        r"<link name='a'> <inertial> <inertia ixx> must be 1 finite numbers",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_every_error_names_the_file_and_the_element(tmp_path: Path, case: str) -> None:
    text, element = BAD[case]
    p = _write(tmp_path, text, f"{case}.urdf")
    with pytest.raises(URDFError, match=re.escape(f"{p}: ") + ".*" + element) as info:
        load_urdf(p)
    exc = info.value
    assert type(exc) is URDFError
    assert exc.__cause__ is None and (exc.__context__ is None or exc.__suppress_context__)
