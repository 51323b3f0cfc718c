"""Where a URDF's mesh URIs point: plain relative paths, ``file://`` and ``package://`` URIs.

Relative paths are taken from the URDF's folder; ``package://pkg/rest`` is searched in that folder
and upwards (see :func:`resolve_mesh`). Used by :func:`planner.robot.urdf.parse_urdf`.
"""

from __future__ import annotations

from pathlib import Path


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
