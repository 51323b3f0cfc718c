"""Where a URDF's mesh URIs point: plain relative paths, ``file://`` and ``package://`` URIs.

Relative paths are taken from the URDF's folder; ``package://pkg/rest`` is searched in that folder
and upwards (see :func:`resolve_mesh`). Used by :func:`planner.robot.urdf.parse_urdf`.

A URDF reads nothing outside its own folder or package (:func:`outside_problem`): a mesh
reference that resolves elsewhere (``/etc/passwd``, ``file:///etc/passwd``,
``package://pkg/../../etc/passwd``, ``package://etc/passwd``, ``../../../etc/passwd``, or a
symbolic link out) is refused, before PyBullet or trimesh opens it. The URDF's own package
(:func:`package_root`) is the nearest folder at or above it that holds a ``package.xml`` (a ROS
package), else the parent of its folder when that is named ``urdf`` (the ROS layout without a
manifest), else its folder; a ``package://pkg/...`` reference may also read in a sibling
package named ``pkg`` (a folder beside the URDF's own package, as in a ROS workspace).
"""

from __future__ import annotations

from pathlib import Path, PurePosixPath


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


def package_root(base_dir: Path) -> Path:
    """The folder a URDF in ``base_dir`` may read meshes from (see the module docstring)."""
    for folder in (base_dir, *base_dir.parents):
        if (folder / "package.xml").is_file():
            return folder
    return base_dir.parent if base_dir.name == "urdf" else base_dir


def outside_problem(uri: str, base_dir: Path, extra_roots: tuple[Path, ...] = ()) -> str:
    """Why the mesh ``uri`` of a URDF in ``base_dir`` reads outside the URDF's own folder or
    package (see the module docstring), or ``""`` when it does not (a ``package://`` file
    that is not found reads nothing; other paths are judged whether the file exists or not).

    ``extra_roots``: further folders the URDF may read (the ROS packages a prepared robot
    description's meshes were found in, :mod:`planner.robot.prepared`).
    """
    own = package_root(base_dir).resolve()
    if extra_roots:
        p = Path(uri[len("file://") :] if uri.startswith("file://") else uri)
        real = (p if p.is_absolute() else base_dir / p).resolve()
        if any(real == r or r in real.parents for r in (r.resolve() for r in extra_roots)):
            return ""
    roots = [own]
    if uri.startswith("package://"):
        pkg, _, sub = uri[len("package://") :].partition("/")
        if pkg in ("", ".", "..") or ".." in PurePosixPath(sub).parts:
            return "climbs out of its package with '..'"
        if own.parent != own.parent.parent:  # a sibling package, not a top-level folder
            roots.append((own.parent / pkg).resolve())
        found = resolve_mesh(uri, base_dir)
        if found is None:
            return ""
        path = found
    else:
        p = Path(uri[len("file://") :] if uri.startswith("file://") else uri)
        path = p if p.is_absolute() else base_dir / p
    real = path.resolve()
    if any(real == r or r in real.parents for r in roots):
        return ""
    where = str(own) if len(roots) == 1 else f"{own} and the package {roots[1]} beside it"
    return f"resolves to {real}, outside {where}"
