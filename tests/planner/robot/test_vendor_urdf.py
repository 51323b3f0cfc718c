"""A vendor-style (ROS-Industrial) URDF of an OPW arm with STL meshes takes the analytic path.

The fixture writes, into ``tmp_path``, a package laid out as ROS-Industrial support packages are
(``abb_irb2400_support/urdf/irb2400.urdf``, ``meshes/collision/*.stl``, ``meshes/visual/*.stl``,
``package://`` URIs) for an arm with the published OPW parameters of the ABB IRB 2400/10
(ROS-Industrial ``opw_kinematics``: a1 0.100, a2 -0.135, b 0, c1 0.615, c2 0.705, c3 0.755,
c4 0.085 m, offsets (0, 0, -pi/2, 0, 0, 0), all signs +1). Authored here from those figures,
not copied from a vendor file. It is written in vendor style: ``base_link``, ``link_1`` ..
``link_6``, extra frames ``base``, ``flange`` and ``tool0``, rpy on some joint origins with
negative axes that compensate them, and collision and visual geometry that are STL meshes
(capsules, boxes, cylinders, a sphere exported with trimesh) whose wrist parts (``link_4``,
``link_5``, ``link_6``) overlap each other in every pose, as vendor wrist meshes do.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
import trimesh

from calib.frames import make_transform
from planner.cell.cell import Cell
from planner.robot.kinematics.chain import KinematicChain
from planner.robot.kinematics.solver import make_ik_solver
from planner.robot.urdf import load_urdf

PACKAGE = "abb_irb2400_support"
#: Published OPW parameters of the ABB IRB 2400/10 (a1, a2, b, c1, c2, c3, c4), m.
IRB2400_OPW = (0.100, -0.135, 0.0, 0.615, 0.705, 0.755, 0.085)
IRB2400_OFFSETS = (0.0, 0.0, -np.pi / 2, 0.0, 0.0, 0.0)
IRB2400_SIGNS = (1, 1, 1, 1, 1, 1)
#: Joint limits, deg (IRB 2400/10 datasheet-like).
LIMITS_DEG = ((-180, 180), (-100, 110), (-60, 65), (-200, 200), (-120, 120), (-400, 400))
HALF_PI = repr(np.pi / 2)
PI = repr(np.pi)


def _along(mesh: trimesh.Trimesh, axis: str, start: float, offset=(0.0, 0.0, 0.0)):
    """``mesh`` (built along +z from 0) turned to run along ``axis`` from ``start``, shifted."""
    turn = {
        "x": trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]),
        "y": trimesh.transformations.rotation_matrix(-np.pi / 2, [1, 0, 0]),
        "z": np.eye(4),
    }[axis]
    m = mesh.copy()
    m.apply_translation([0, 0, start - m.bounds[0][2]])
    m.apply_transform(turn)
    m.apply_translation(offset)
    return m


def _capsule(axis: str, start: float, end: float, radius: float, offset=(0.0, 0.0, 0.0)):
    """A capsule whose hemispheres end ``radius`` beyond ``start`` and ``end`` on ``axis``."""
    body = trimesh.creation.capsule(height=end - start, radius=radius, count=[16, 16])
    return _along(body, axis, start - radius, offset)


def _cylinder(axis: str, start: float, end: float, radius: float, offset=(0.0, 0.0, 0.0)):
    body = trimesh.creation.cylinder(radius=radius, height=end - start, sections=24)
    return _along(body, axis, start, offset)


def _link_meshes() -> dict[str, trimesh.Trimesh]:
    """Collision meshes in each link's frame (link_2 and link_5 frames are turned, see URDF)."""
    return {
        "base_link": trimesh.creation.box([0.45, 0.45, 0.25], _shift(0, 0, 0.125)),
        "link_1": _cylinder("z", 0.25, 0.70, 0.17),
        # link_2's frame is turned +90 deg about x: the upper arm runs along its +y
        "link_2": _capsule("y", 0.0, 0.705, 0.09, (0.0, 0.0, 0.13)),
        "link_3": trimesh.creation.box([0.24, 0.22, 0.26], _shift(0.0, 0.0, 0.08)),
        # the forearm ends in a half ball around the wrist centre (x = 0.755)
        "link_4": _capsule("x", 0.15, 0.755, 0.065),
        # link_5's frame is turned 180 deg about x; a ball on the wrist centre
        "link_5": trimesh.creation.icosphere(subdivisions=2, radius=0.06),
        # axis 6 from behind the wrist centre (x = -0.085) to the flange (x = 0)
        "link_6": _cylinder("x", -0.10, 0.0, 0.045),
    }


def _shift(x: float, y: float, z: float) -> np.ndarray:
    return make_transform(p=[x, y, z])


def _link_xml(name: str, has_mesh: bool) -> str:
    if not has_mesh:
        return f'  <link name="{name}"/>\n'
    uri = f"package://{PACKAGE}/meshes"
    return (
        f'  <link name="{name}">\n'
        f'    <visual><origin xyz="0 0 0" rpy="0 0 0"/>'
        f'<geometry><mesh filename="{uri}/visual/{name}.stl"/></geometry></visual>\n'
        f'    <collision><origin xyz="0 0 0" rpy="0 0 0"/>'
        f'<geometry><mesh filename="{uri}/collision/{name}.stl"/></geometry></collision>\n'
        "  </link>\n"
    )


def _joint_xml(
    name: str,
    parent: str,
    child: str,
    xyz: str,
    rpy: str = "0 0 0",
    axis: str | None = None,
    limit_deg: tuple[int, int] | None = None,
) -> str:
    kind = "fixed" if axis is None else "revolute"
    out = (
        f'  <joint name="{name}" type="{kind}">\n'
        f'    <parent link="{parent}"/><child link="{child}"/>\n'
        f'    <origin xyz="{xyz}" rpy="{rpy}"/>\n'
    )
    if axis is not None and limit_deg is not None:
        lo, hi = np.radians(limit_deg)
        out += f'    <axis xyz="{axis}"/>\n'
        out += f'    <limit lower="{lo:.4f}" upper="{hi:.4f}" effort="0" velocity="2.618"/>\n'
    return out + "  </joint>\n"


def write_vendor_urdf(root: Path) -> Path:
    """Write the IRB 2400-like support package under ``root``; return the URDF path."""
    pkg = root / PACKAGE
    for kind in ("collision", "visual"):
        (pkg / "meshes" / kind).mkdir(parents=True)
    for name, mesh in _link_meshes().items():
        mesh.export(pkg / "meshes" / "collision" / f"{name}.stl")
        # visual meshes: the same shapes, a little larger and finer, as vendor visuals are
        vis = mesh.copy()
        vis.apply_scale(1.02)
        vis.export(pkg / "meshes" / "visual" / f"{name}.stl")
    meshes = _link_meshes()
    links = ["base_link", *(f"link_{i}" for i in range(1, 7)), "base", "flange", "tool0"]
    lim = LIMITS_DEG
    joints = [
        _joint_xml("joint_1", "base_link", "link_1", "0 0 0", axis="0 0 1", limit_deg=lim[0]),
        # link_2's frame turned +90 deg about x, so axis 2 (world +y) is its -z
        _joint_xml(
            "joint_2", "link_1", "link_2", "0.1 0 0.615", f"{HALF_PI} 0 0", "0 0 -1", lim[1]
        ),
        _joint_xml("joint_3", "link_2", "link_3", "0 0.705 0", f"-{HALF_PI} 0 0", "0 1 0", lim[2]),
        _joint_xml("joint_4", "link_3", "link_4", "0 0 0.135", axis="1 0 0", limit_deg=lim[3]),
        # link_5's frame turned 180 deg about x, so axis 5 (world +y) is its -y
        _joint_xml("joint_5", "link_4", "link_5", "0.755 0 0", f"{PI} 0 0", "0 -1 0", lim[4]),
        _joint_xml("joint_6", "link_5", "link_6", "0.085 0 0", f"-{PI} 0 0", "1 0 0", lim[5]),
        _joint_xml("base_link-base", "base_link", "base", "0 0 0"),
        _joint_xml("joint_6-flange", "link_6", "flange", "0 0 0"),
        _joint_xml("flange-tool0", "flange", "tool0", "0 0 0", f"0 {HALF_PI} 0"),
    ]
    text = (
        '<?xml version="1.0"?>\n'
        "<!-- IRB 2400/10-like test arm, written by tests/planner/robot/test_vendor_urdf.py -->\n"
        '<robot name="abb_irb2400_like">\n'
        + "".join(_link_xml(n, n in meshes) for n in links)
        + "".join(joints)
        + "</robot>\n"
    )
    path = pkg / "urdf" / "irb2400.urdf"
    path.parent.mkdir()
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def vendor_urdf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_vendor_urdf(tmp_path_factory.mktemp("vendor"))


@pytest.fixture(scope="module")
def cell(vendor_urdf: Path) -> Iterator[Cell]:
    with Cell(robot=vendor_urdf, use_acl_cache=False) as c:
        c.set_work_object(
            trimesh.creation.box([0.4, 0.4, 0.4]),
            "m",
            make_transform(p=[1.0, 0.0, 0.3]),
            name="box",
        )
        yield c


def test_the_file_is_vendor_style_with_meshes(vendor_urdf: Path) -> None:
    model = load_urdf(vendor_urdf)  # raises when a package:// mesh cannot be resolved
    text = vendor_urdf.read_text()
    assert text.count("package://") == 14 and 'rpy="0 0 0"' in text
    with_meshes = [link for link in model.links if link.collisions]
    assert {link.name for link in with_meshes} == set(_link_meshes())
    for link in with_meshes:
        for shape in (*link.collisions, *link.visuals):
            assert shape.geometry.kind == "mesh" and shape.geometry.mesh_path is not None


def test_make_ik_solver_picks_opw_with_the_published_parameters(vendor_urdf: Path) -> None:
    chain = KinematicChain.from_urdf(vendor_urdf)
    assert (chain.base_link, chain.tip_link) == ("base_link", "tool0")
    solver = make_ik_solver(chain)
    assert solver.kind == "opw" and solver.why_not_opw is None and solver.opw_exact
    assert solver.opw is not None
    p = solver.opw.params
    np.testing.assert_allclose((p.a1, p.a2, p.b, p.c1, p.c2, p.c3, p.c4), IRB2400_OPW, atol=1e-12)
    np.testing.assert_allclose(p.offsets, IRB2400_OFFSETS, atol=1e-12)
    assert p.sign_corrections == IRB2400_SIGNS
    np.testing.assert_allclose(solver.opw.T_base_opw, np.eye(4), atol=1e-12)


def test_fk_agrees_with_pybullet_and_ik_round_trips(
    vendor_urdf: Path, rng: np.random.Generator
) -> None:
    chain = KinematicChain.from_urdf(vendor_urdf)
    q = rng.uniform(chain.lower, chain.upper, (40, 6))
    T = chain.fk(q)
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(str(vendor_urdf), useFixedBase=True, physicsClientId=cid)
        n = pb.getNumJoints(body, physicsClientId=cid)
        info = [pb.getJointInfo(body, i, physicsClientId=cid) for i in range(n)]
        joint = {i[1].decode(): i[0] for i in info}
        tip = next(i[0] for i in info if i[12].decode() == "tool0")
        # PyBullet found every mesh (a missing one would leave the link without a shape)
        for i in info:
            if i[12].decode() in _link_meshes():
                shapes = pb.getCollisionShapeData(body, i[0], physicsClientId=cid)
                assert shapes and shapes[0][2] == pb.GEOM_MESH
        for k in range(len(q)):
            for name, v in zip(chain.joint_names, q[k], strict=True):
                pb.resetJointState(body, joint[name], float(v), physicsClientId=cid)
            st = pb.getLinkState(body, tip, computeForwardKinematics=True, physicsClientId=cid)
            np.testing.assert_allclose(st[4], T[k, :3, 3], atol=1e-6)
            R = np.array(pb.getMatrixFromQuaternion(st[5])).reshape(3, 3)
            np.testing.assert_allclose(R, T[k, :3, :3], atol=1e-6)
    finally:
        pb.disconnect(cid)
    sol = make_ik_solver(chain).solve(T)
    assert sol.found.all()
    K = sol.q.shape[1]
    err = (
        chain.fk(sol.q[sol.valid])[:, :3, 3] - np.repeat(T, K, axis=0)[sol.valid.ravel()][:, :3, 3]
    )
    assert np.abs(err).max() <= 1e-9


@pytest.mark.slow
def test_the_acl_allows_the_permanent_wrist_overlap(cell: Cell) -> None:
    acl = cell.checker.acl
    for a, b in (("link_4", "link_6"), ("link_4", "link_5"), ("link_5", "link_6")):
        assert (a, b) in acl.allowed, (a, b)
    # not adjacent, yet in contact in (almost) every sampled pose
    assert acl.near_fraction[("link_4", "link_6")] >= 0.95
    # the upper arm and the wrist are not allowed wholesale
    assert ("link_2", "link_6") not in acl.allowed


def test_a_reachable_point_on_the_box_is_feasible(cell: Cell) -> None:
    assert cell.solver.kind == "opw"
    (res,) = cell.check_probes([[0.0, 0.0, 0.2]], [[0.0, 0.0, 1.0]])  # top face centre
    assert res.feasible and res.status in ("feasible", "marginal"), res.reason
    assert 0 <= res.branch < 8 and res.q is not None
    T_base_sensor = cell.chain.fk(res.q)[0] @ cell.T_flange_tcp("sensor")
    np.testing.assert_allclose(T_base_sensor[:3, 3], [1.0, 0.0, 0.5], atol=1e-6)
    np.testing.assert_allclose(T_base_sensor[:3, 2], [0.0, 0.0, -1.0], atol=1e-6)


def test_an_unreachable_point_is_infeasible_with_a_reason(cell: Cell) -> None:
    (res,) = cell.check_probes([[4.0, 0.0, 0.0]], [[1.0, 0.0, 0.0]])
    assert not res.feasible and res.status == "infeasible"
    assert re.fullmatch(
        r"out of reach \(\d+\.\d\d m from the shoulder, reach \d\.\d\d m\)", res.reason
    )
