"""Parse and validate URDF files into frozen dataclasses: wobjcal's one URDF parser.

Robot and tool URDFs are both read here, into the product's own typed view
(:mod:`planner.robot.urdf_model`: links with shapes and inertials, joints, the validated tree);
callers never see yourdfpy or lxml objects. Errors are :class:`planner.errors.URDFError` naming
the file and the element: a missing file, malformed XML or not XML at all, no ``<robot>``
element, bad numbers, joints that refer to unknown links, revolute or prismatic joints without
``<limit>``, links with two parents, cycles and several roots. A URDF of one link and no joints
is valid (a tool or a fixed body); a robot chain needs moving joints, which
:class:`planner.robot.kinematics.chain.KinematicChain` checks.

How the work is split with yourdfpy:

* yourdfpy converts each ``<link>``, ``<joint>`` and ``<material>`` element into its dataclasses
  (``URDF._parse_link`` / ``_parse_joint`` / ``_parse_material``, the functions that
  ``URDF.load`` itself calls): origins become 4x4 matrices (URDF's fixed-axis rpy), geometry,
  limits, mimic, materials, inertials with their inertia tensor. We convert those to our model
  (a visual's ``<material name>`` takes the colour of the top-level material of that name).
  yourdfpy fills a missing ``ixx``/``iyy``/``izz`` with 1 (its default), not 0.
* The XML is read here, with lxml (yourdfpy's own XML library) and a strict parser, because
  ``URDF.load`` on malformed XML logs the error and re-parses in lxml's recover mode: a truncated
  file loads silently as a smaller robot, and text that is not XML at all raises a bare
  ``TypeError``. Comments are stripped as ``URDF.load`` does (yourdfpy reads ``<geometry>``'s
  first child).
* Checks on top, done here, because yourdfpy does not do them or fails without context: names,
  ``<parent>``/``<child>`` and ``<geometry>`` present (yourdfpy raises a bare ``KeyError`` or
  ``TypeError``); numeric attributes (yourdfpy silently drops a fourth ``xyz``/``rpy`` number,
  turns ``nan`` into an all-NaN origin, and raises a bare ``ValueError`` on ``"x"``); joint type,
  limits and non-zero axis; and the tree (yourdfpy accepts joints to unknown links, cycles, two
  parents and several roots; its ``URDF.validate`` reports none of these, and its messages do not
  say which element is wrong). ``yourdfpy.URDF`` itself is not built: without a scene graph it
  only adds name maps.
* Mesh URIs are resolved by :mod:`planner.robot.urdf_meshes`, not by yourdfpy's filename
  handlers: those strip the package name from ``package://pkg/rest`` and then search ``rest``
  upwards (so a mesh of a sibling package is not found, and a same-named file of another package
  is taken instead), and they try paths relative to the process's working directory. A mesh
  outside the URDF's own folder or package (``/etc/passwd``, ``../../x``, ``package://p/../..``)
  is refused here, naming the file, the link and the path, before PyBullet or trimesh reads it.

:func:`load_urdf` raises when a referenced mesh is missing unless ``check_meshes=False``. The
data model's names are importable from here too. Angles follow URDF: ``rpy`` is roll, pitch, yaw
about fixed x, y, z, ``R = Rz(yaw) Ry(pitch) Rx(roll)``; lengths are metres. An origin's ``rpy``
is recovered from yourdfpy's matrix, so it is an equivalent triple (pitch in [-pi/2, pi/2]), not
necessarily the one written in the file.
"""

from __future__ import annotations

import math
import warnings
from collections import Counter
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from calib.limits import MAX_URDF_LINKS, MAX_URDF_MESH_BYTES, MiB
from calib.reading import MAX_URDF_BYTES, read_bytes_capped
from planner.errors import URDFError
from planner.robot.prepared import prepared_roots
from planner.robot.urdf_meshes import outside_problem, resolve_mesh
from planner.robot.urdf_model import (
    JOINT_TYPES,
    FloatArray,
    Geometry,
    Inertial,
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
    "Inertial",
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

Vec3 = tuple[float, float, float]

#: Numeric attributes checked before yourdfpy converts them: child path -> {attribute: count}.
_ORIGIN = {"origin": {"xyz": 3, "rpy": 3}}
_JOINT_NUMBERS = {
    **_ORIGIN,
    "axis": {"xyz": 3},
    "limit": {"lower": 1, "upper": 1, "effort": 1, "velocity": 1},
}
_SHAPE_NUMBERS = {
    **_ORIGIN,
    "geometry/box": {"size": 3},
    "geometry/cylinder": {"radius": 1, "length": 1},
    "geometry/sphere": {"radius": 1},
    "geometry/mesh": {"scale": 3},
    "material/color": {"rgba": 4},
}
_INERTIAL_NUMBERS = {
    **_ORIGIN,
    "mass": {"value": 1},
    "inertia": {k: 1 for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")},
}
#: Geometry elements and the attributes each needs (yourdfpy raises a bare KeyError without).
_GEOMETRY_NEEDS = {
    "box": ("size",),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "mesh": ("filename",),
}


class URDFWarning(UserWarning):
    """Something in a URDF was ignored (e.g. ``<mimic>``); the message names the element."""


def load_urdf(path: str | Path, check_meshes: bool = True) -> URDFModel:
    """Read and validate a URDF file.

    A robot description wobjcal prepared (:mod:`planner.robot.prepared`: an expanded xacro
    file, or a URDF with its ``package://`` meshes found on a ROS package path) may read its
    meshes in the ROS packages listed beside it too.

    Args:
        path: the ``.urdf`` file.
        check_meshes: raise when a referenced mesh file cannot be found.

    Raises:
        URDFError: missing file, malformed XML, or invalid content; the message names the file and
            the element (and lists every missing mesh).
    """
    p = Path(path)
    if not p.exists():
        raise URDFError(f"URDF file not found: {p}")
    try:
        data = read_bytes_capped(p, MAX_URDF_BYTES, "URDF file", URDFError)
    except OSError as exc:
        raise URDFError(f"cannot read URDF file {p}: {exc}") from None
    model = parse_urdf(data, source=p, allowed_roots=prepared_roots(p))
    missing = model.missing_meshes()
    if check_meshes and missing:
        listed = "; ".join(f"link {link!r}: {uri!r}" for link, uri in missing)
        raise URDFError(f"{p}: mesh file(s) not found: {listed}")
    too_big = mesh_bytes_problem(model)
    if too_big:
        raise URDFError(f"{p}: {too_big}")
    return model


def parse_urdf(
    text: str | bytes, source: Path | None = None, allowed_roots: tuple[Path, ...] = ()
) -> URDFModel:
    """Parse URDF text; ``source`` (the file) names errors and anchors relative mesh paths.

    ``bytes`` are decoded as their XML declaration says (default UTF-8); ``str`` is taken as is.
    ``allowed_roots``: folders (ROS packages) whose meshes the text may name besides the
    source's own folder or package.
    """
    from yourdfpy import URDF  # pulls in trimesh: imported when a URDF is read

    where = str(source) if source is not None else "URDF text"
    root = _xml_root(text, where)
    name = root.get("name", "")
    base_dir = source.parent if source is not None else Path.cwd()
    colors: dict[str, tuple[float, float, float, float]] = {}
    for e in root.findall("material"):
        what = f"{where}: <material name={e.get('name')!r}>"
        _check_numbers(e, {"color": {"rgba": 4}}, what)
        material = _parsed(URDF._parse_material, e, what)
        if material.name and material.color is not None:
            colors[material.name] = _tuple(material.color.rgba)
    _check_sizes(root, where)
    links = tuple(
        _link(e, URDF._parse_link, where, (base_dir, allowed_roots), colors)
        for e in root.findall("link")
    )
    joints = tuple(_joint(e, URDF._parse_joint, where) for e in root.findall("joint"))
    return _validated(name, source, links, joints, where)


def _check_sizes(root: Any, where: str) -> None:
    """Refuse more than :data:`calib.limits.MAX_URDF_LINKS` links or joints before either is
    parsed (the tree checks and the cell's collision pairs grow with the square)."""
    for tag in ("link", "joint"):
        n = len(root.findall(tag))
        if n > MAX_URDF_LINKS:
            raise URDFError(
                f"{where}: {n:,} <{tag}> elements, at most {MAX_URDF_LINKS:,} (an arm has 7 to "
                "10 links, with a track, a positioner and a tool changer a few dozen; PyBullet "
                "poses at most 128 in one body)"
            )


def mesh_bytes_problem(model: URDFModel) -> str:
    """Why the mesh files ``model`` refers to are too large to load, or ``""``: more than
    :data:`calib.limits.MAX_URDF_MESH_BYTES` together (PyBullet and the drawings read them
    all)."""
    files = {g.mesh_path for link in model.links for g in _geometries(link) if g.mesh_path}
    total = 0
    for f in files:
        try:
            total += f.stat().st_size
        except OSError:
            continue
    if total <= MAX_URDF_MESH_BYTES:
        return ""
    return (
        f"its {len(files)} mesh files hold {total / MiB:.1f} MiB, at most "
        f"{MAX_URDF_MESH_BYTES / MiB:.0f} MiB (PyBullet and the drawings load every one; a "
        "vendor arm's meshes are 5-40 MB): simplify them (e.g. MeshLab's quadric edge collapse)"
    )


def _geometries(link: Link) -> list[Any]:
    return [shape.geometry for shape in (*link.visuals, *link.collisions)]


def _xml_root(text: str | bytes, where: str) -> Any:
    """The ``<robot>`` element, parsed strictly (no recovery), comments stripped."""
    from lxml import etree

    as_text = isinstance(text, str)
    data = text.encode("utf-8") if isinstance(text, str) else text
    parser = etree.XMLParser(remove_blank_text=True, encoding="utf-8" if as_text else None)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        raise URDFError(f"{where}: malformed XML: {exc}") from None
    etree.strip_tags(root, etree.Comment, etree.ProcessingInstruction)
    if root.tag != "robot":
        raise URDFError(f"{where}: the top element must be <robot>, got <{root.tag}>")
    return root


def _validated(
    name: str, source: Path | None, links: tuple[Link, ...], joints: tuple[Joint, ...], where: str
) -> URDFModel:
    if not links:
        raise URDFError(f"{where}: <robot name={name!r}> has no <link> elements")
    names = [link.name for link in links]
    dup = sorted(n for n, k in Counter(names).items() if k > 1)  # linear: links are many
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
    children: dict[str, list[str]] = {}
    for j in joints:
        children.setdefault(j.parent, []).append(j.child)
    reached = {roots[0]}
    frontier = [roots[0]]
    while frontier:
        for child in children.get(frontier.pop(), ()):
            if child not in reached:
                reached.add(child)
                frontier.append(child)
    if len(reached) != len(names):
        cyc = sorted(known - reached)
        raise URDFError(f"{where}: links {cyc} form a cycle, unreachable from root {roots[0]!r}")
    return URDFModel(name, source, links, joints, roots[0], by_child)


def _check_numbers(e: Any, spec: Mapping[str, Mapping[str, int]], what: str) -> None:
    """Every attribute of ``spec`` below ``e`` that is present holds that many finite numbers."""
    for path, attrs in spec.items():
        sub = e.find(path)
        if sub is None:
            continue
        for attr, n in attrs.items():
            text = sub.get(attr)
            if text is None:
                continue
            label = f"{what} <{sub.tag} {attr}>"
            try:
                vals = [float(v) for v in text.split()]
            except ValueError:
                raise URDFError(f"{label} must be {n} numbers, got {text!r}") from None
            if len(vals) != n or not all(math.isfinite(v) for v in vals):
                raise URDFError(f"{label} must be {n} finite numbers, got {text!r}")


def _parsed(parse: Callable[[Any], Any], e: Any, what: str) -> Any:
    """yourdfpy's dataclass of element ``e``; its bare exceptions become URDFErrors naming ``e``."""
    try:
        return parse(e)
    except (KeyError, ValueError, TypeError, IndexError, AttributeError) as exc:
        raise URDFError(f"{what} cannot be read: {type(exc).__name__}: {exc}") from None


def _tuple(values: Any) -> Any:
    return tuple(float(v) for v in np.ravel(values))


def _xyz_rpy(T: FloatArray | None) -> tuple[Vec3, Vec3]:
    """``xyz`` and an equivalent ``rpy`` of yourdfpy's origin matrix (``None``: identity)."""
    from trimesh.transformations import euler_from_matrix

    if T is None:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    return _tuple(T[:3, 3]), _tuple(euler_from_matrix(T, "sxyz"))


def _joint(e: Any, parse: Callable[[Any], Any], where: str) -> Joint:
    name = e.get("name")
    if not name:
        raise URDFError(f"{where}: a <joint> element has no name")
    what = f"{where}: <joint name={name!r}>"
    parent, child = e.find("parent"), e.find("child")
    if parent is None or child is None or not parent.get("link") or not child.get("link"):
        raise URDFError(f"{what} needs <parent link=...> and <child link=...>")
    _check_numbers(e, _JOINT_NUMBERS, what)
    yj = _parsed(parse, e, what)
    jtype = yj.type or ""
    if jtype not in JOINT_TYPES:
        raise URDFError(f"{what} has type {jtype!r}; expected one of {list(JOINT_TYPES)}")
    ax, ay, az = _tuple(yj.axis)
    norm = float(np.sqrt(ax * ax + ay * ay + az * az))
    if jtype not in ("fixed", "floating") and norm < 1e-12:
        raise URDFError(f"{what} has a zero <axis xyz>")
    axis = (ax / norm, ay / norm, az / norm) if norm > 0 else (1.0, 0.0, 0.0)
    limit = None
    if jtype in ("revolute", "prismatic"):
        lim = yj.limit
        if lim is None or lim.lower is None or lim.upper is None:
            raise URDFError(f"{what} is {jtype} but has no <limit lower=... upper=...>")
        if lim.lower > lim.upper:
            raise URDFError(f"{what} <limit> has lower {lim.lower} > upper {lim.upper}")
        limit = JointLimit(lim.lower, lim.upper, lim.effort or 0.0, lim.velocity or 0.0)
    if yj.mimic is not None:
        msg = f"{what}: <mimic> is ignored; the joint moves freely"
        warnings.warn(msg, URDFWarning, stacklevel=4)
    xyz, rpy = _xyz_rpy(yj.origin)
    return Joint(name, jtype, yj.parent, yj.child, xyz, rpy, axis, limit)


def _link(
    e: Any,
    parse: Callable[[Any], Any],
    where: str,
    base: tuple[Path, tuple[Path, ...]],
    colors: Mapping[str, tuple[float, float, float, float]],
) -> Link:
    name = e.get("name")
    if not name:
        raise URDFError(f"{where}: a <link> element has no name")
    what = f"{where}: <link name={name!r}>"
    for kind in ("visual", "collision"):
        for s in e.findall(kind):
            _check_shape(s, f"{what} <{kind}>")
    inertial_e = e.find("inertial")
    if inertial_e is not None:
        _check_numbers(inertial_e, _INERTIAL_NUMBERS, f"{what} <inertial>")
    yl = _parsed(parse, e, what)
    visuals = tuple(_shape(v, f"{what} <visual>", base, colors) for v in yl.visuals)
    collisions = tuple(_shape(c, f"{what} <collision>", base, {}) for c in yl.collisions)
    return Link(name, visuals, collisions, _inertial(yl.inertial, f"{what} <inertial>"))


def _check_shape(e: Any, what: str) -> None:
    geom = e.find("geometry")
    if geom is None or len(geom) == 0:
        raise URDFError(f"{what} has no <geometry>")
    g = geom[0]
    if g.tag not in _GEOMETRY_NEEDS:
        raise URDFError(f"{what} has unknown geometry <{g.tag}>")
    for attr in _GEOMETRY_NEEDS[g.tag]:
        if not g.get(attr):
            raise URDFError(f"{what} <{g.tag}> has no {attr}")
    _check_numbers(e, _SHAPE_NUMBERS, what)


def _shape(
    ys: Any,
    what: str,
    base: tuple[Path, tuple[Path, ...]],
    colors: Mapping[str, tuple[float, float, float, float]],
) -> Shape:
    """Our :class:`Shape` of a yourdfpy ``Visual`` or ``Collision`` (checked by _check_shape);
    ``base``: the URDF's folder and the further folders its meshes may be read from."""
    base_dir, allowed_roots = base
    g = ys.geometry
    if g.box is not None:
        geom = Geometry("box", size=_tuple(g.box.size))
    elif g.cylinder is not None:
        c = g.cylinder
        geom = Geometry("cylinder", radius=float(c.radius), length=float(c.length))
    elif g.sphere is not None:
        geom = Geometry("sphere", radius=float(g.sphere.radius))
    else:
        uri = g.mesh.filename
        outside = outside_problem(uri, base_dir, allowed_roots)
        if outside:
            raise URDFError(
                f"{what}: mesh {uri!r} {outside}: a URDF reads only files in its own folder or "
                "package; copy the mesh there and refer to it by a relative path"
            )
        scale = (1.0, 1.0, 1.0) if g.mesh.scale is None else _tuple(g.mesh.scale)
        geom = Geometry("mesh", filename=uri, mesh_path=resolve_mesh(uri, base_dir), scale=scale)
    rgba = None
    material = getattr(ys, "material", None)
    if material is not None:
        if material.color is not None:
            rgba = _tuple(material.color.rgba)
        elif material.name:
            rgba = colors.get(material.name)
    xyz, rpy = _xyz_rpy(ys.origin)
    return Shape(xyz, rpy, geom, rgba)


def _inertial(yi: Any, what: str) -> Inertial | None:
    if yi is None:
        return None
    if yi.mass is None:
        warnings.warn(f"{what} has no <mass>; taken as 0 kg", URDFWarning, stacklevel=5)
    mass = float(yi.mass or 0.0)
    if mass < 0.0:
        raise URDFError(f"{what} <mass value> must be >= 0 kg, got {mass}")
    xyz, rpy = _xyz_rpy(yi.origin)
    I = np.zeros((3, 3)) if yi.inertia is None else yi.inertia
    inertia = (I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2])
    return Inertial(mass, xyz, rpy, _tuple(inertia))
