"""ROS packages without ROS: the folders ``$(find pkg)`` and ``package://pkg/...`` name.

A package path is a list of folders, written as ``ROS_PACKAGE_PATH`` is (separated by ``:``).
Each folder is searched as a ROS workspace is crawled: a folder holding a ``package.xml`` is a
package (named by the manifest's ``<name>``, and also by its folder name when no other package
takes that name) and is not searched further; other folders are searched down to
:data:`MAX_DEPTH` levels, skipping hidden folders and those marked ``CATKIN_IGNORE``,
``COLCON_IGNORE`` or ``AMENT_IGNORE``. The first folder of the path that holds a package wins,
as in ROS. At most :data:`MAX_FOLDERS` folders are looked at (a path entry of ``/`` is refused,
naming the entry, rather than crawled for minutes).

Where the path comes from (:func:`package_path`): the plan's ``cell.robot.package_path`` when it
sets one (relative folders from the plan's folder), else the environment's
``ROS_PACKAGE_PATH`` (relative folders from the working directory), else none.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from planner.errors import URDFError

log = logging.getLogger(__name__)

#: The environment variable ROS reads its package path from.
PATH_ENV = "ROS_PACKAGE_PATH"
#: The plan field that sets the package path instead.
PLAN_FIELD = "cell.robot.package_path"
#: How deep below a path folder packages are looked for (a workspace's ``src/repo/pkg`` is 2).
MAX_DEPTH = 4
#: At most this many folders are looked at over the whole path.
MAX_FOLDERS = 20_000
#: A ``package.xml`` larger than this is not read for its name (a manifest is 1-5 kB).
MAX_MANIFEST_BYTES = 1 << 20
_IGNORE_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE")


@dataclass(frozen=True)
class PackagePath:
    """The ROS packages found on a package path.

    Attributes:
        folders: the path's folders, in order, absolute (some may not exist).
        source: where the path was given, for messages (``"ROS_PACKAGE_PATH"``,
            ``"cell.robot.package_path"``, ``"the robot zip"``).
        packages: package name -> its folder (absolute, symbolic links resolved).
        hint: what to do when a package is missing, for messages.
    """

    folders: tuple[Path, ...]
    source: str
    packages: Mapping[str, Path] = field(default_factory=dict)
    hint: str = f"add the folder that holds it to {PLAN_FIELD} or {PATH_ENV}"

    def describe(self) -> str:
        """The path in words: ``ROS_PACKAGE_PATH (/a, /b (missing))``."""
        if not self.folders:
            return f"{self.source} (empty)"
        shown = [f"{f}" if f.is_dir() else f"{f} (missing)" for f in self.folders]
        return f"{self.source} ({', '.join(shown)})"

    def find(self, name: str) -> Path:
        """The folder of package ``name``.

        Raises:
            URDFError: no package of that name on the path (the message names the package,
                the path searched and how to set it).
        """
        folder = self.packages.get(name)
        if folder is None:
            raise URDFError(f"ROS package {name!r} not found in {self.describe()}: {self.hint}")
        return folder

    def roots(self) -> tuple[Path, ...]:
        """Every package folder (the folders a robot description may read)."""
        return tuple(dict.fromkeys(self.packages.values()))


def split_path(text: str, base_dir: Path) -> tuple[Path, ...]:
    """The folders of a ``:``-separated path, relative ones from ``base_dir``, in order,
    empty entries dropped (as ROS does)."""
    out = []
    for entry in text.split(":"):
        entry = entry.strip()
        if not entry:
            continue
        p = Path(entry).expanduser()
        out.append((p if p.is_absolute() else base_dir / p).resolve())
    return tuple(dict.fromkeys(out))


def find_packages(folders: tuple[Path, ...], source: str, hint: str = "") -> PackagePath:
    """Crawl ``folders`` for ROS packages (see the module docstring); ``source`` and ``hint``
    (default: set the package path) word the error of a missing package.

    Raises:
        URDFError: an entry is the file system's root (``/``), or the folders hold more than
            :data:`MAX_FOLDERS` folders (the entry that overflowed is named).
    """
    named: dict[str, Path] = {}
    by_folder: list[tuple[str, Path]] = []
    seen = 0
    for top in folders:
        if top == Path(top.anchor):  # crawling it would take any copy of a package anywhere
            raise URDFError(
                f"{source}: the entry {top} is the file system's root; name the folders that "
                "hold the ROS packages (e.g. a workspace's src/), not a folder above them"
            )
        if not top.is_dir():
            continue
        stack = [(top, 0)]
        while stack:
            folder, depth = stack.pop()
            seen += 1
            if seen > MAX_FOLDERS:
                raise URDFError(
                    f"{source}: the folder {top} holds more than {MAX_FOLDERS:,} folders to "
                    "search for ROS packages; name the workspace's package folders (e.g. its "
                    "src/), not a folder above them"
                )
            if (folder / "package.xml").is_file():
                name = _manifest_name(folder / "package.xml") or folder.name
                named.setdefault(name, folder.resolve())
                by_folder.append((folder.name, folder.resolve()))
                continue
            if depth >= MAX_DEPTH or any((folder / m).exists() for m in _IGNORE_MARKERS):
                continue
            try:
                children = sorted(
                    (c for c in folder.iterdir() if c.is_dir() and not c.name.startswith(".")),
                    reverse=True,
                )
            except OSError as exc:
                log.debug("not searching %s for ROS packages: %s", folder, exc)
                continue
            stack.extend((c, depth + 1) for c in children)
    for name, folder in by_folder:  # a folder name is a package name no manifest took
        named.setdefault(name, folder)
    if hint:
        return PackagePath(folders, source, named, hint)
    return PackagePath(folders, source, named)


def _manifest_name(path: Path) -> str:
    """The ``<name>`` of a ``package.xml``, or ``""`` when it cannot be read."""
    from lxml import etree

    try:
        if path.stat().st_size > MAX_MANIFEST_BYTES:
            return ""
        parser = etree.XMLParser(resolve_entities=False, no_network=True)
        root = etree.parse(str(path), parser).getroot()
    except (OSError, etree.XMLSyntaxError) as exc:
        log.debug("cannot read the package name in %s: %s", path, exc)
        return ""
    name = root.findtext("name") if root.tag == "package" else None
    return (name or "").strip()


def package_path(plan_value: str | None, plan_dir: Path) -> PackagePath | None:
    """The package path in effect: the plan's (``plan_value``, relative folders from
    ``plan_dir``) when given, else ``ROS_PACKAGE_PATH`` when set (relative folders from the
    working directory), else ``None``."""
    if plan_value is not None:
        return find_packages(split_path(plan_value, plan_dir), PLAN_FIELD)
    env = os.environ.get(PATH_ENV, "")
    if env.strip():
        return find_packages(split_path(env, Path.cwd()), PATH_ENV)
    return None


__all__ = [
    "MAX_DEPTH",
    "MAX_FOLDERS",
    "PATH_ENV",
    "PLAN_FIELD",
    "PackagePath",
    "find_packages",
    "package_path",
    "split_path",
]
