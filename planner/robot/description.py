"""A robot description as its vendor ships it, made into a URDF file PyBullet can open.

Vendors ship robots as ROS packages: a xacro file (``.xacro``, ``.urdf.xacro``) of macros that
include other packages' files through ``$(find pkg)``, and meshes named
``package://pkg/path``. :func:`robot_description` turns such a file into a plain URDF:

1. a xacro file is expanded (:func:`planner.robot.xacro_expand.expand_xacro`, with the
   arguments given); a ``.urdf`` is read as it is;
2. every ``<mesh filename>`` becomes the absolute path of its file: ``package://pkg/rest`` is
   ``rest`` in package ``pkg`` of the ROS package path
   (:class:`planner.robot.ros_packages.PackagePath`), or, when the path has no such package,
   in the robot's own package or a package beside it (as before, see
   :mod:`planner.robot.urdf_meshes`); relative paths are from the robot file's folder. A
   reference that climbs out of its package (``package://pkg/../../etc/passwd``, a symbolic
   link out) or points outside the robot's package (``/etc/passwd``) is refused, naming the
   file, the link and the reference; missing mesh files are listed in one error;
3. the result is parsed and checked as any URDF (:func:`planner.robot.urdf.parse_urdf`, errors
   naming the robot's own file, not the prepared one) and written as a prepared file
   (:mod:`planner.robot.prepared`) with the package folders its meshes are in.

A ``.urdf`` is left as it is (no prepared file) when no package path is set: it then reads its
meshes as any URDF does.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from pathlib import Path, PurePosixPath

from calib.reading import MAX_URDF_BYTES, read_bytes_capped
from planner.errors import URDFError
from planner.robot.prepared import write_prepared
from planner.robot.ros_packages import PackagePath
from planner.robot.urdf import URDFWarning, mesh_bytes_problem, parse_urdf
from planner.robot.urdf_meshes import outside_problem, package_root, resolve_mesh
from planner.robot.xacro_expand import expand_xacro

_RULE = (
    "a robot description reads only files in its own package and the ROS packages on the "
    "package path"
)


def is_xacro(path: Path) -> bool:
    """Whether ``path`` is a xacro file (``.xacro``, ``.urdf.xacro``)."""
    return path.suffix.lower() == ".xacro"


def robot_description(
    source: Path, packages: PackagePath | None, args: Mapping[str, str] | None = None
) -> Path:
    """The URDF file PyBullet and the parser read for the robot file ``source``.

    Args:
        source: the robot's ``.urdf`` or ``.xacro`` file.
        packages: the ROS package path (``None``: none set).
        args: values of the xacro file's arguments (only for a ``.xacro``).

    Returns:
        ``source`` itself for a ``.urdf`` without a package path, else the prepared file.

    Raises:
        URDFError: the file cannot be expanded or read, a mesh is missing or outside the
            packages, or the result is not a valid URDF (the message names ``source``).
    """
    if not is_xacro(source):
        if args:
            raise URDFError(f"{source}: xacro arguments given, but it is not a .xacro file")
        if packages is None:
            return source
    urdf, roots = prepared_urdf(source, packages, args)
    return write_prepared(urdf, roots)


def prepared_urdf(
    source: Path, packages: PackagePath | None, args: Mapping[str, str] | None = None
) -> tuple[bytes, tuple[Path, ...]]:
    """The prepared URDF text of ``source`` (steps 1-3 of the module docstring, without
    writing it) and the folders its meshes lie in (the robot's own package first).

    Raises:
        URDFError: as :func:`robot_description`.
    """
    from lxml import etree

    source = source.resolve()
    if is_xacro(source):
        data = expand_xacro(source, packages, args).encode("utf-8")
    else:
        if not source.is_file():
            raise URDFError(f"URDF file not found: {source}")
        data = read_bytes_capped(source, MAX_URDF_BYTES, "URDF file", URDFError)
    if len(data) > MAX_URDF_BYTES:
        raise URDFError(
            f"{source}: expands to {len(data) / (1 << 20):.0f} MiB of URDF, at most "
            f"{MAX_URDF_BYTES >> 20} MiB"
        )
    try:
        root = etree.fromstring(data, etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError as exc:
        raise URDFError(f"{source}: malformed XML: {exc}") from None
    own = package_root(source.parent).resolve()
    roots: dict[Path, None] = {own: None}
    missing: list[str] = []
    for link in root.iter("link"):
        for mesh in link.iter("mesh"):
            uri = mesh.get("filename") or ""
            if not uri:
                continue  # parse_urdf names a mesh without a filename
            where = f"{source}: <link name={link.get('name')!r}>: mesh {uri!r}"
            found, folder = _mesh_file(uri, source.parent, own, packages, where)
            if found is None or isinstance(folder, str):
                missing.append(f"link {link.get('name')!r}: {uri!r} ({folder})")
                continue
            roots[folder] = None
            mesh.set("filename", str(found))
    if missing:
        raise URDFError(f"{source}: mesh file(s) not found: {'; '.join(missing)}")
    urdf = etree.tostring(root, xml_declaration=True, encoding="utf-8")
    folders = tuple(roots)
    with warnings.catch_warnings():  # the cell's load of the prepared file warns once
        warnings.simplefilter("ignore", URDFWarning)
        model = parse_urdf(urdf, source=source, allowed_roots=folders)
    too_big = mesh_bytes_problem(model)
    if too_big:
        raise URDFError(f"{source}: {too_big}")
    return urdf, folders


def _mesh_file(
    uri: str, base_dir: Path, own: Path, packages: PackagePath | None, where: str
) -> tuple[Path | None, Path | str]:
    """The file of mesh ``uri`` (``None`` when missing) and the folder it lies in (when
    missing: where it was looked for, in words).

    Raises:
        URDFError: the reference reads outside its package (``where`` names it).
    """
    pkg = ""
    if uri.startswith("package://"):
        pkg, _, sub = uri[len("package://") :].partition("/")
        if pkg in ("", ".", "..") or ".." in PurePosixPath(sub).parts or sub.startswith("/"):
            raise URDFError(f"{where} climbs out of its package with '..': {_RULE}")
        folder = None if packages is None else packages.packages.get(pkg)
        if folder is not None:
            real = (folder / sub).resolve()
            if not (real == folder or folder in real.parents):
                raise URDFError(f"{where} resolves to {real}, outside package {folder}: {_RULE}")
            return (real, folder) if real.is_file() else (None, f"not in {folder}")
    problem = outside_problem(uri, base_dir)
    if problem:
        raise URDFError(f"{where} {problem}: {_RULE}")
    found = resolve_mesh(uri, base_dir)
    if found is None:
        if uri.startswith("package://"):
            searched = "no package path set" if packages is None else packages.describe()
            return None, f"package {pkg!r} not on the package path: {searched}"
        return None, f"not found from {base_dir}"
    real = found.resolve()
    sibling = (own.parent / pkg).resolve() if pkg else own
    return real, sibling if sibling in real.parents else own  # outside_problem allowed it


__all__ = ["is_xacro", "prepared_urdf", "robot_description"]
