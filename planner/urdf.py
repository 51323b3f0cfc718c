"""Parse and validate URDF robot descriptions into frozen dataclasses.

Only the standard library's ``xml.etree`` is used. Everything wobjcal needs is checked here, once,
with errors (:class:`planner.errors.URDFError`) that name the file and the element: a missing
file, malformed XML, no ``<robot>`` element, joints that refer to unknown links, revolute or
prismatic joints without ``<limit>``, links with two parents, cycles and several roots.

Mesh file names are resolved relative to the URDF file: plain relative paths, ``file://`` URIs and
``package://pkg/rest`` URIs (a folder named ``pkg`` is searched in the URDF's folder and upwards).
:func:`load_urdf` raises when a referenced mesh is missing unless ``check_meshes=False``.

Angles follow URDF: ``rpy`` is roll, pitch, yaw about fixed x, y, z, ``R = Rz(yaw) Ry(pitch)
Rx(roll)``; lengths are metres.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from planner.errors import URDFError

FloatArray = NDArray[np.float64]

#: Joint types of the URDF specification.
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


class URDFWarning(UserWarning):
    """Something in a URDF was ignored (e.g. ``<mimic>``); the message names the element."""


def matrix_from_rpy(rpy: tuple[float, float, float]) -> FloatArray:
    """Rotation ``Rz(yaw) @ Ry(pitch) @ Rx(roll)`` (3, 3) of a URDF ``rpy`` triple (rad)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def transform_from_xyz_rpy(
    xyz: tuple[float, float, float], rpy: tuple[float, float, float]
) -> FloatArray:
    """Homogeneous transform (4, 4) of a URDF ``<origin xyz rpy>`` (m, rad)."""
    T = np.eye(4)
    T[:3, :3] = matrix_from_rpy(rpy)
    T[:3, 3] = xyz
    return T


@dataclass(frozen=True)
class Geometry:
    """One geometry element of a visual or collision shape.

    Attributes:
        kind: ``"box"``, ``"cylinder"``, ``"sphere"`` or ``"mesh"``.
        size: box edge lengths (3,), metres; zeros for other kinds.
        radius: cylinder or sphere radius, metres.
        length: cylinder length along its local z, metres.
        filename: the mesh URI as written in the URDF (``""`` for primitives).
        mesh_path: the resolved mesh file, or ``None`` when not a mesh or not found.
        scale: mesh scale factors (3,).
    """

    kind: str
    size: tuple[float, float, float] = (0.0, 0.0, 0.0)
    radius: float = 0.0
    length: float = 0.0
    filename: str = ""
    mesh_path: Path | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class Shape:
    """A visual or collision shape of a link.

    Attributes:
        xyz: origin of the shape in the link frame, metres.
        rpy: orientation of the shape in the link frame (URDF roll, pitch, yaw), radians.
        geometry: what the shape is.
        rgba: colour (visuals with a ``<material><color>``), else ``None``.
    """

    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    geometry: Geometry
    rgba: tuple[float, float, float, float] | None = None


@dataclass(frozen=True)
class Link:
    """A URDF link: a name and its shapes (link frame)."""

    name: str
    visuals: tuple[Shape, ...] = ()
    collisions: tuple[Shape, ...] = ()


@dataclass(frozen=True)
class JointLimit:
    """Joint limits: position in rad (revolute) or m (prismatic), effort, velocity."""

    lower: float
    upper: float
    effort: float = 0.0
    velocity: float = 0.0


@dataclass(frozen=True)
class Joint:
    """A URDF joint.

    Attributes:
        name: joint name.
        type: one of :data:`JOINT_TYPES`.
        parent: parent link name.
        child: child link name.
        xyz: origin of the joint frame in the parent link frame, metres.
        rpy: orientation of the joint frame in the parent link frame, radians.
        axis: unit joint axis (3,) in the joint frame (default x, as in the URDF spec).
        limit: position limits; ``None`` for continuous, fixed, floating and planar joints.
    """

    name: str
    type: str
    parent: str
    child: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    limit: JointLimit | None = None

    @property
    def T_parent_joint(self) -> FloatArray:
        """The joint frame at zero joint value in the parent link frame, (4, 4)."""
        return transform_from_xyz_rpy(self.xyz, self.rpy)

    @property
    def is_moving(self) -> bool:
        """True for revolute, continuous and prismatic joints."""
        return self.type in ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class URDFModel:
    """A parsed, validated URDF: one tree of links and joints.

    Attributes:
        name: the robot name.
        path: the URDF file (``None`` when parsed from a string).
        links: the links in file order.
        joints: the joints in file order.
        root: the one link that is no joint's child.
    """

    name: str
    path: Path | None
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    root: str
    _by_child: dict[str, Joint] = field(default_factory=dict, repr=False, compare=False)

    @property
    def link_names(self) -> tuple[str, ...]:
        """All link names in file order."""
        return tuple(link.name for link in self.links)

    def link(self, name: str) -> Link:
        """The link called ``name`` (raises :class:`URDFError` listing valid names)."""
        for link in self.links:
            if link.name == name:
                return link
        raise URDFError(f"{self._where()}: no link {name!r}; links are {list(self.link_names)}")

    def parent_joint(self, link: str) -> Joint | None:
        """The joint whose child is ``link`` (``None`` for the root)."""
        return self._by_child.get(link)

    def children(self, link: str) -> tuple[Joint, ...]:
        """Joints whose parent is ``link``, in file order."""
        return tuple(j for j in self.joints if j.parent == link)

    def joints_between(self, base: str, tip: str) -> tuple[Joint, ...]:
        """Joints from ``base`` down to ``tip`` (empty when equal).

        Raises:
            URDFError: ``tip`` is not below ``base`` in the tree.
        """
        chain: list[Joint] = []
        link = tip
        while link != base:
            joint = self._by_child.get(link)
            if joint is None:
                raise URDFError(f"{self._where()}: link {tip!r} is not below link {base!r}")
            chain.append(joint)
            link = joint.parent
        return tuple(reversed(chain))

    def missing_meshes(self) -> list[tuple[str, str]]:
        """``(link name, mesh URI)`` of every referenced mesh file that was not found."""
        out = []
        for link in self.links:
            for shape in (*link.visuals, *link.collisions):
                g = shape.geometry
                if g.kind == "mesh" and g.mesh_path is None:
                    out.append((link.name, g.filename))
        return out

    def _where(self) -> str:
        return str(self.path) if self.path is not None else f"URDF {self.name!r}"


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


def resolve_mesh(uri: str, base_dir: Path) -> Path | None:
    """Find the file a mesh URI refers to, or ``None`` when it does not exist.

    ``file:///abs/path`` is taken as is; ``package://pkg/rest`` looks for ``rest`` in ``base_dir``,
    then for ``pkg/rest`` in ``base_dir`` and each folder above it (or ``rest`` in a folder named
    ``pkg`` on the way up);
    anything else is a path relative to ``base_dir`` (the URDF's folder).
    """
    if uri.startswith("file://"):
        p = Path(uri[len("file://") :])
        return p if p.is_file() else None
    if uri.startswith("package://"):
        rest = uri[len("package://") :]
        pkg, _, sub = rest.partition("/")
        if (base_dir / sub).is_file():
            return base_dir / sub
        for folder in (base_dir, *base_dir.parents):
            if (folder / pkg / sub).is_file():
                return folder / pkg / sub
            if folder.name == pkg and (folder / sub).is_file():
                return folder / sub
        return None
    p = Path(uri)
    p = p if p.is_absolute() else base_dir / p
    return p if p.is_file() else None
