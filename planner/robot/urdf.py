"""Parse and validate URDF robot descriptions into frozen dataclasses.

Only the standard library's ``xml.etree`` is used. Everything wobjcal needs is checked here, once,
with errors (:class:`planner.errors.URDFError`) that name the file and the element: a missing
file, malformed XML, no ``<robot>`` element, joints that refer to unknown links, revolute or
prismatic joints without ``<limit>``, links with two parents, cycles and several roots.

Mesh file names are resolved relative to the URDF file: plain relative paths, ``file://`` URIs and
``package://pkg/rest`` URIs (a folder named ``pkg`` is searched in the URDF's folder and upwards).
:func:`load_urdf` raises when a referenced mesh is missing unless ``check_meshes=False``.

The data model lives in :mod:`planner.robot.urdf_model` and mesh URIs are resolved by
:mod:`planner.robot.urdf_meshes`; their names are importable from here too.

Angles follow URDF: ``rpy`` is roll, pitch, yaw about fixed x, y, z, ``R = Rz(yaw) Ry(pitch)
Rx(roll)``; lengths are metres.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from planner.errors import URDFError
from planner.robot.urdf_meshes import resolve_mesh
from planner.robot.urdf_model import (
    JOINT_TYPES,
    FloatArray,
    Geometry,
    Joint,
    JointLimit,
    Link,
    Shape,
    URDFModel,
    matrix_from_rpy,
    transform_from_xyz_rpy,
)

__all__ = [
    "JOINT_TYPES",
    "FloatArray",
    "Geometry",
    "Joint",
    "JointLimit",
    "Link",
    "Shape",
    "URDFModel",
    "URDFWarning",
    "Vec3",
    "load_urdf",
    "matrix_from_rpy",
    "parse_urdf",
    "resolve_mesh",
    "transform_from_xyz_rpy",
]


class URDFWarning(UserWarning):
    """Something in a URDF was ignored (e.g. ``<mimic>``); the message names the element."""


def load_urdf(path: str | Path, check_meshes: bool = True) -> URDFModel:
    """Read and validate a URDF file.

    Args:
        path: the ``.urdf`` file.
        check_meshes: raise when a referenced mesh file cannot be found.

    Raises:
        URDFError: missing file, malformed XML, or invalid content; the message names the file and
            the element (and lists every missing mesh).
    """
    p = Path(path)
    if not p.is_file():
        raise URDFError(f"URDF file not found: {p}")
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise URDFError(f"cannot read URDF file {p}: {exc}") from None
    model = parse_urdf(text, source=p)
    missing = model.missing_meshes()
    if check_meshes and missing:
        listed = "; ".join(f"link {link!r}: {uri!r}" for link, uri in missing)
        raise URDFError(f"{p}: mesh file(s) not found: {listed}")
    return model


def parse_urdf(text: str, source: Path | None = None) -> URDFModel:
    """Parse URDF text; ``source`` (the file) names errors and anchors relative mesh paths."""
    where = str(source) if source is not None else "URDF text"
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise URDFError(f"{where}: malformed XML: {exc}") from None
    if root.tag != "robot":
        raise URDFError(f"{where}: the top element must be <robot>, got <{root.tag}>")
    name = root.get("name", "")
    base_dir = source.parent if source is not None else Path.cwd()
    links = tuple(_parse_link(e, where, base_dir) for e in root.findall("link"))
    joints = tuple(_parse_joint(e, where) for e in root.findall("joint"))
    return _validated(name, source, links, joints, where)


def _validated(
    name: str, source: Path | None, links: tuple[Link, ...], joints: tuple[Joint, ...], where: str
) -> URDFModel:
    if not links:
        raise URDFError(f"{where}: <robot name={name!r}> has no <link> elements")
    names = [link.name for link in links]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise URDFError(f"{where}: duplicate link name(s) {dup}")
    known = set(names)
    by_child: dict[str, Joint] = {}
    for j in joints:
        for role, link in (("parent", j.parent), ("child", j.child)):
            if link not in known:
                raise URDFError(f"{where}: <joint name={j.name!r}> {role} link {link!r} is unknown")
        if j.child in by_child:
            raise URDFError(
                f"{where}: link {j.child!r} is the child of two joints, "
                f"{by_child[j.child].name!r} and {j.name!r}"
            )
        by_child[j.child] = j
    roots = [n for n in names if n not in by_child]
    if len(roots) != 1:
        what = "no root link (the joints form a cycle)" if not roots else f"several roots {roots}"
        raise URDFError(f"{where}: the links must form one tree, found {what}")
    reached = {roots[0]}
    frontier = [roots[0]]
    while frontier:
        link = frontier.pop()
        for j in joints:
            if j.parent == link and j.child not in reached:
                reached.add(j.child)
                frontier.append(j.child)
    if len(reached) != len(names):
        cyc = sorted(known - reached)
        raise URDFError(f"{where}: links {cyc} form a cycle, unreachable from root {roots[0]!r}")
    return URDFModel(name, source, links, joints, roots[0], by_child)


Vec3 = tuple[float, float, float]


def _floats(text: str | None, n: int, default: tuple[float, ...], what: str) -> tuple[float, ...]:
    """``n`` finite floats parsed from an attribute, or ``default`` when it is absent."""
    if text is None:
        return default
    try:
        vals = tuple(float(v) for v in text.split())
    except ValueError:
        raise URDFError(f"{what} must be {n} numbers, got {text!r}") from None
    if len(vals) != n or not all(np.isfinite(vals)):
        raise URDFError(f"{what} must be {n} finite numbers, got {text!r}")
    return vals


def _float(text: str | None, default: float, what: str) -> float:
    return _floats(text, 1, (default,), what)[0]


def _vec3(text: str | None, default: Vec3, what: str) -> Vec3:
    x, y, z = _floats(text, 3, default, what)
    return (x, y, z)


def _origin(elem: ET.Element | None, what: str) -> tuple[Vec3, Vec3]:
    if elem is None:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    xyz = _vec3(elem.get("xyz"), (0.0, 0.0, 0.0), f"{what} <origin xyz>")
    rpy = _vec3(elem.get("rpy"), (0.0, 0.0, 0.0), f"{what} <origin rpy>")
    return xyz, rpy


def _parse_joint(e: ET.Element, where: str) -> Joint:
    name = e.get("name")
    if not name:
        raise URDFError(f"{where}: a <joint> element has no name")
    what = f"{where}: <joint name={name!r}>"
    jtype = e.get("type", "")
    if jtype not in JOINT_TYPES:
        raise URDFError(f"{what} has type {jtype!r}; expected one of {list(JOINT_TYPES)}")
    parent, child = e.find("parent"), e.find("child")
    if parent is None or child is None or not parent.get("link") or not child.get("link"):
        raise URDFError(f"{what} needs <parent link=...> and <child link=...>")
    xyz, rpy = _origin(e.find("origin"), what)
    axis_e = e.find("axis")
    axis_text = axis_e.get("xyz") if axis_e is not None else None
    ax, ay, az = _vec3(axis_text, (1.0, 0.0, 0.0), f"{what} <axis>")
    norm = float(np.sqrt(ax * ax + ay * ay + az * az))
    if jtype not in ("fixed", "floating") and norm < 1e-12:
        raise URDFError(f"{what} has a zero <axis xyz>")
    axis = (ax / norm, ay / norm, az / norm) if norm > 0 else (1.0, 0.0, 0.0)
    limit = None
    lim_e = e.find("limit")
    if jtype in ("revolute", "prismatic"):
        if lim_e is None or lim_e.get("lower") is None or lim_e.get("upper") is None:
            raise URDFError(f"{what} is {jtype} but has no <limit lower=... upper=...>")
        lo = _float(lim_e.get("lower"), 0.0, f"{what} <limit lower>")
        hi = _float(lim_e.get("upper"), 0.0, f"{what} <limit upper>")
        if lo > hi:
            raise URDFError(f"{what} <limit> has lower {lo} > upper {hi}")
        eff = _float(lim_e.get("effort"), 0.0, f"{what} <limit effort>")
        vel = _float(lim_e.get("velocity"), 0.0, f"{what} <limit velocity>")
        limit = JointLimit(lo, hi, eff, vel)
    if e.find("mimic") is not None:
        msg = f"{what}: <mimic> is ignored; the joint moves freely"
        warnings.warn(msg, URDFWarning, stacklevel=3)
    p_link, c_link = parent.get("link", ""), child.get("link", "")
    return Joint(name, jtype, p_link, c_link, xyz, rpy, axis, limit)


def _parse_link(e: ET.Element, where: str, base_dir: Path) -> Link:
    name = e.get("name")
    if not name:
        raise URDFError(f"{where}: a <link> element has no name")
    what = f"{where}: <link name={name!r}>"
    visuals = tuple(_parse_shape(v, f"{what} <visual>", base_dir) for v in e.findall("visual"))
    collisions = tuple(
        _parse_shape(c, f"{what} <collision>", base_dir) for c in e.findall("collision")
    )
    return Link(name, visuals, collisions)


def _parse_shape(e: ET.Element, what: str, base_dir: Path) -> Shape:
    xyz, rpy = _origin(e.find("origin"), what)
    geom_e = e.find("geometry")
    if geom_e is None or len(geom_e) == 0:
        raise URDFError(f"{what} has no <geometry>")
    g = geom_e[0]
    if g.tag == "box":
        geom = Geometry("box", size=_vec3(g.get("size"), (0.0, 0.0, 0.0), f"{what} <box size>"))
    elif g.tag == "cylinder":
        r = _float(g.get("radius"), 0.0, f"{what} <cylinder radius>")
        ln = _float(g.get("length"), 0.0, f"{what} <cylinder length>")
        geom = Geometry("cylinder", radius=r, length=ln)
    elif g.tag == "sphere":
        geom = Geometry("sphere", radius=_float(g.get("radius"), 0.0, f"{what} <sphere radius>"))
    elif g.tag == "mesh":
        uri = g.get("filename", "")
        if not uri:
            raise URDFError(f"{what} <mesh> has no filename")
        scale = _vec3(g.get("scale"), (1.0, 1.0, 1.0), f"{what} <mesh scale>")
        path = resolve_mesh(uri, base_dir)
        geom = Geometry("mesh", filename=uri, mesh_path=path, scale=scale)
    else:
        raise URDFError(f"{what} has unknown geometry <{g.tag}>")
    rgba = None
    color = e.find("material/color")
    if color is not None and color.get("rgba"):
        r_, g_, b_, a_ = _floats(color.get("rgba"), 4, (1.0, 1.0, 1.0, 1.0), f"{what} <rgba>")
        rgba = (r_, g_, b_, a_)
    return Shape(xyz, rpy, geom, rgba)
