"""A plan with its files: one ZIP archive that works wherever it is unpacked, and the plan's file
references (which fields hold them, and the plan with them moved to another folder).

A plan refers to files by paths relative to its folder (or absolute, or ``builtin:NAME``, which
need no file): the work object's mesh, the robot's URDF or xacro (whose meshes and includes lie
beside it, or in ROS packages found through ``cell.robot.package_path``), the tool (a tool
description or URDF, with its URDF and meshes beside it) and the fixtures' meshes.
:func:`plan_bundle` copies every one of them into an archive laid out as::

    <stem>/<stem>.json                    the plan, its references made relative to <stem>/
    <stem>/files/work_object/<file>       the work object's mesh
    <stem>/files/fixtures/<file>          each fixture's mesh (same names made unique: a-2.stl)
    <stem>/files/robot/<folder>/...       the robot's folder (see below), whole
    <stem>/files/tool/<folder>/...        the tool's folder, whole, when the tool is a file
    <stem>/files/packages/<i>/<folder>/...  each folder of the package path that exists

The robot's (and the tool's) folder is the one its URDF may read meshes from, the rule of
:func:`planner.robot.urdf_meshes.package_root`: the nearest folder at or above the file holding
a ``package.xml``, else the parent of a folder named ``urdf``, else the file's own folder. A
folder inside another one copied (a robot package inside a package-path folder) is not copied
twice: the references point into the first copy. Bytes are copied unchanged, so the plan's
``sha256`` digests stay valid. Inside a copied folder, symbolic links are followed only to
files and folders inside that folder; archives (``.zip``, ``.tar``, ...: an earlier bundle of
the same plan) and ``.git``, ``.hg``, ``.svn`` and ``__pycache__`` are left out.

The archive is deterministic (sorted entries, every time stamp 1980-01-01 00:00, fixed
permissions), so the same plan and files give the same bytes. Pure: standard library and
msgspec, no simulator.
"""

from __future__ import annotations

import io
import logging
import os
import re
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Final

import msgspec

from calib.atomic_io import write_bytes_atomic
from calib.errors import PlanError
from calib.limits import MiB
from calib.plan.base import BUILTIN_PREFIX, resolve_ref
from calib.plan.file import Plan, check_plan_files, plan_to_json

log = logging.getLogger(__name__)

#: Most bytes of files (before compression) one bundle may hold: a vendor arm's meshes are
#: 5-40 MB and at most :data:`calib.limits.MAX_URDF_MESH_BYTES` (128 MiB), a CAD part at most
#: :data:`calib.limits.MAX_CAD_FILE_BYTES` (64 MiB), a work-object mesh of the largest triangle
#: count the planner loads ~25 MB; the archive is built in memory.
MAX_BUNDLE_BYTES: Final = 256 * MiB
#: Most files one bundle may hold (a vendor robot package has tens to a few hundred).
MAX_BUNDLE_FILES: Final = 10_000
#: Folders never copied from a robot, tool or package folder.
SKIPPED_FOLDERS: Final = frozenset({".git", ".hg", ".svn", "__pycache__"})
#: Files never copied out of a folder: archives (an earlier bundle of the same plan would
#: otherwise go into the next one; no URDF, mesh or tool reads one).
SKIPPED_SUFFIXES: Final = frozenset({".zip", ".tar", ".gz", ".tgz", ".xz", ".bz2", ".7z"})
#: The time stamp of every archive entry (the earliest a ZIP file can hold).
ZIP_DATE_TIME: Final = (1980, 1, 1, 0, 0, 0)
#: Where the copied files go inside the bundle folder.
FILES_FOLDER: Final = "files"
#: What a bundle's stem may be: it names the archive's folder and the plan file in it.
_STEM_RE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+()-]{0,99}")
_CHUNK = 1 << 20

__all__ = [
    "MAX_BUNDLE_BYTES",
    "MAX_BUNDLE_FILES",
    "file_refs",
    "plan_bundle",
    "rebased_plan",
    "save_plan_bundle",
    "with_refs",
]


# ---- the plan's references -----------------------------------------------------------------


def _ref_fields(plan: Plan) -> list[tuple[str, str]]:
    """Every field of ``plan`` that holds one file reference or built-in, with its value."""
    c = plan.cell
    refs = [("cell.robot.urdf", c.robot.urdf), ("cell.tool.name", c.tool.name)]
    refs += [
        (f"cell.fixtures[{i}].mesh", f.mesh) for i, f in enumerate(c.fixtures) if f.mesh is not None
    ]
    refs.append(("work_object.mesh", plan.work_object.mesh))
    return refs


def file_refs(plan: Plan) -> list[tuple[str, str]]:
    """Every reference of ``plan`` to one file, as ``(field, ref)`` in a fixed order:
    ``cell.robot.urdf``, ``cell.tool.name``, ``cell.fixtures[i].mesh``, ``work_object.mesh``.

    ``builtin:`` references and fixtures without a mesh (boxes) are left out. The robot's
    ``package_path`` names folders, not a file, and is not among them.
    """
    return [(where, ref) for where, ref in _ref_fields(plan) if not ref.startswith(BUILTIN_PREFIX)]


def with_refs(
    plan: Plan,
    refs: Mapping[str, str],
    package_path: str | msgspec.UnsetType | None = None,
) -> Plan:
    """``plan`` with the file references named in ``refs`` replaced.

    Args:
        plan: the plan.
        refs: new reference (a path or ``builtin:NAME``) by field, the fields as
            :func:`file_refs` names them (a built-in's field too); a field left out keeps its
            reference.
        package_path: the new ``cell.robot.package_path`` (``msgspec.UNSET``: left out of the
            file); ``None`` keeps the plan's.

    Raises:
        PlanError: a field of ``refs`` holds no file reference in ``plan`` (the message lists
            those that do).
    """
    fields = [where for where, _ in _ref_fields(plan)]
    unknown = sorted(set(refs) - set(fields))
    if unknown:
        raise PlanError(f"no file reference {unknown} in the plan (fields: {fields})")
    rep = msgspec.structs.replace
    c = plan.cell
    robot = rep(c.robot, urdf=refs.get("cell.robot.urdf", c.robot.urdf))
    if package_path is not None:
        robot = rep(robot, package_path=package_path)
    fixtures = [
        rep(f, mesh=refs.get(f"cell.fixtures[{i}].mesh", f.mesh)) for i, f in enumerate(c.fixtures)
    ]
    cell = rep(
        c,
        robot=robot,
        tool=rep(c.tool, name=refs.get("cell.tool.name", c.tool.name)),
        fixtures=fixtures,
    )
    wobj = rep(plan.work_object, mesh=refs.get("work_object.mesh", plan.work_object.mesh))
    return rep(plan, cell=cell, work_object=wobj)


def _package_entries(path: str) -> list[str]:
    """The folders of a ``:``-separated package path as written, stripped, empty ones dropped
    (as :func:`planner.robot.ros_packages.split_path` reads them)."""
    return [p for p in (e.strip() for e in path.split(":")) if p]


def rebased_plan(plan: Plan, from_dir: Path, to_dir: Path) -> Plan:
    """``plan`` with its file references (robot, its ROS package path, tool, work object,
    fixture meshes) made relative to ``to_dir`` instead of ``from_dir``, so a plan written into
    another folder still finds its files.

    ``builtin:`` references, absolute paths and package-path folders from the home folder
    (``~/ws/src``) are unchanged; no file is read or copied.
    """
    src, dst = Path(from_dir), Path(to_dir).resolve()

    def rebase(ref: str) -> str:
        if not ref or Path(ref).is_absolute():
            return ref
        return os.path.relpath((src / ref).resolve(), dst)

    path = plan.cell.robot.package_path
    packages = path
    if isinstance(path, str):
        entries = _package_entries(path)
        packages = ":".join(p if p.startswith("~") else rebase(p) for p in entries)
    return with_refs(plan, {where: rebase(ref) for where, ref in file_refs(plan)}, packages)


# ---- the bundle ------------------------------------------------------------------------------


def _package_root(folder: Path) -> Path:
    """The folder a URDF in ``folder`` may read meshes from: the nearest folder at or above it
    holding a ``package.xml``, else the parent of a folder named ``urdf``, else ``folder``
    (:func:`planner.robot.urdf_meshes.package_root`; a test keeps them equal)."""
    for f in (folder, *folder.parents):
        if (f / "package.xml").is_file():
            return f
    return folder.parent if folder.name == "urdf" else folder


def _within(path: Path, root: Path) -> bool:
    return path == root or root in path.parents


@dataclass
class _Contents:
    """What goes into the archive, names relative to the bundle folder (POSIX).

    Attributes:
        files: archive name -> the file whose bytes it holds.
        roots: each folder copied whole (resolved) -> its archive name, in the order copied.
        singles: each single file copied (resolved) -> its archive name.
        total_bytes: the files' sizes together, bytes.
    """

    files: dict[str, Path] = field(default_factory=dict)
    roots: dict[Path, str] = field(default_factory=dict)
    singles: dict[Path, str] = field(default_factory=dict)
    total_bytes: int = 0

    def unique(self, folder: str, name: str) -> str:
        """``folder/name``, or ``folder/<stem>-2<suffix>`` ... when taken (case ignored, for
        file systems that ignore it)."""
        taken = {n.lower() for n in (*self.files, *self.roots.values())}
        stem, suffix = (name, "") if name.startswith(".") else (Path(name).stem, Path(name).suffix)
        candidate, k = f"{folder}/{name}", 2
        while candidate.lower() in taken or any(
            t.startswith(candidate.lower() + "/") for t in taken
        ):
            candidate, k = f"{folder}/{stem}-{k}{suffix}", k + 1
        return candidate

    def add(self, name: str, source: Path, size: int, where: str) -> None:
        """Take ``source`` (``size`` bytes) as ``name``; refuse past the limits, naming
        ``where`` and the file."""
        if name in self.files:
            return
        if len(self.files) >= MAX_BUNDLE_FILES:
            raise PlanError(
                f"plan bundle: {where}: more than {MAX_BUNDLE_FILES:,} files to bundle (at "
                f"{source}); keep the robot, tool and packages in folders that hold only them"
            )
        self.total_bytes += size
        if self.total_bytes > MAX_BUNDLE_BYTES:
            raise PlanError(
                f"plan bundle: {where}: the files to bundle exceed the limit of "
                f"{_size(MAX_BUNDLE_BYTES)} (MAX_BUNDLE_BYTES) at {source} ({_size(size)}; "
                f"{_size(self.total_bytes)} with the files before it); keep the robot, tool "
                "and packages in folders that hold only them"
            )
        self.files[name] = source

    def inside(self, real: Path) -> str | None:
        """The archive name of ``real`` (resolved) when it lies in a folder copied whole."""
        for root, name in self.roots.items():
            if _within(real, root):
                rel = real.relative_to(root).as_posix()
                return name if rel == "." else f"{name}/{rel}"
        return None


def _size(n: int) -> str:
    return f"{n / MiB:.1f} MiB" if n >= MiB else f"{n:,} bytes"


def _copy_folder(contents: _Contents, root: Path, name: str, where: str) -> None:
    """Take every file under ``root`` (resolved) as ``name/...``: symbolic links only to files
    and folders inside ``root``, no :data:`SKIPPED_FOLDERS`, no loops, no names that are not
    printable text or hold ``\\`` (they would not unpack alike everywhere)."""
    contents.roots[root] = name
    stack: list[tuple[Path, PurePosixPath, tuple[Path, ...]]] = [(root, PurePosixPath(), (root,))]
    while stack:
        folder, rel, seen = stack.pop()
        try:
            entries = sorted(os.scandir(folder), key=lambda e: e.name)
        except OSError as exc:
            raise PlanError(f"plan bundle: {where}: cannot list {folder}: {exc.strerror}") from None
        below = []
        for entry in entries:
            path = Path(entry.path)
            if not entry.name.isprintable() or "\\" in entry.name:
                log.warning("plan bundle: left out %r: its name is not portable", entry.path)
                continue
            try:
                if entry.is_symlink():
                    real = path.resolve(strict=True)
                    if not _within(real, root):
                        log.warning("plan bundle: left out %s: it links outside %s", path, root)
                        continue
                else:
                    real = path
                if real.is_dir():
                    if entry.name not in SKIPPED_FOLDERS and real.resolve() not in seen:
                        below.append((real, rel / entry.name, (*seen, real.resolve())))
                elif real.is_file():
                    if real.suffix.lower() in SKIPPED_SUFFIXES:  # e.g. an earlier bundle
                        log.info("plan bundle: left out %s: an archive", path)
                        continue
                    contents.add(f"{name}/{rel / entry.name}", real, real.stat().st_size, where)
            except (OSError, RuntimeError) as exc:  # a dangling link, a link loop, a vanished file
                log.info("plan bundle: skipping %s: %s", path, exc)
        stack.extend(reversed(below))


def _file_of(ref: str, plan_dir: Path, where: str) -> Path:
    """The resolved file a reference names; refused, naming it, when it is missing."""
    path = Path(resolve_ref(ref, plan_dir))
    if path.is_dir():
        raise PlanError(f"plan bundle: {where}: {path} is a directory, not a file")
    if not path.is_file():
        raise PlanError(f"plan bundle: {where}: file not found: {path}")
    return path.resolve()


def _check_stem(stem: str) -> None:
    if not isinstance(stem, str) or not _STEM_RE.fullmatch(stem) or stem.endswith("."):
        raise PlanError(
            f"plan bundle: stem {stem!r} must be 1 to 100 letters, digits and _ . + ( ) -, "
            "starting with a letter, digit or _ and not ending with ."
        )


def _folders(plan: Plan, plan_dir: Path, contents: _Contents) -> tuple[dict[str, Path], list[Path]]:
    """Copy the folders whole: the package path's that exist, the robot's and the tool's (outer
    ones first, a folder inside one copied not again). Returns the robot's and the tool's files
    by field (resolved) and the package folders in path order (resolved)."""
    refs = dict(file_refs(plan))
    files: dict[str, Path] = {
        where: _file_of(refs[where], plan_dir, where)
        for where in ("cell.robot.urdf", "cell.tool.name")
        if where in refs
    }
    folders: list[tuple[Path, str, str]] = []  # (folder, archive folder it goes in, field)
    packages: list[Path] = []
    path = plan.cell.robot.packages
    for entry in _package_entries(path or ""):
        p = Path(entry).expanduser()
        p = (p if p.is_absolute() else plan_dir / p).resolve()
        if not p.is_dir():
            log.info("plan bundle: package path folder %s does not exist: left out", p)
            continue
        if p == Path(p.anchor):
            raise PlanError(
                f"plan bundle: cell.robot.package_path: the entry {p} is the file system's "
                "root; name the folders that hold the ROS packages"
            )
        if p not in packages:
            folders.append((p, f"{FILES_FOLDER}/packages/{len(packages)}", "package_path"))
            packages.append(p)
    for where, real in files.items():
        kind = "robot" if where == "cell.robot.urdf" else "tool"
        folders.append((_package_root(real.parent), f"{FILES_FOLDER}/{kind}", where))
    for folder, parent, where in sorted(folders, key=lambda f: len(f[0].parts)):
        if contents.inside(folder) is None:
            _copy_folder(contents, folder, contents.unique(parent, folder.name or "root"), where)
    return files, packages


def _bundle_contents(plan: Plan, plan_dir: Path) -> tuple[_Contents, Plan]:
    """What the archive holds, and ``plan`` with its references into it."""
    check_plan_files(plan, plan_dir, source="plan bundle")  # meshes there, digests right
    contents = _Contents()
    robot_tool, packages = _folders(plan, plan_dir, contents)
    new: dict[str, str] = {}
    for where, ref in file_refs(plan):
        real = robot_tool.get(where) or _file_of(ref, plan_dir, where)
        name = contents.inside(real)
        if where not in robot_tool and (name is None or name not in contents.files):
            name = contents.singles.get(real)  # a mesh: a single file, once
            if name is None:
                kind = "work_object" if where == "work_object.mesh" else "fixtures"
                name = contents.singles[real] = contents.unique(f"{FILES_FOLDER}/{kind}", real.name)
        if name is None:  # cannot happen: the robot's and the tool's folders are copied
            raise PlanError(f"plan bundle: {where}: {real} is in no folder copied")
        contents.add(name, real, real.stat().st_size, where)  # even from a skipped folder
        new[where] = name
    package_path = plan.cell.robot.package_path
    if isinstance(package_path, str):
        package_path = ":".join(contents.inside(p) or "" for p in packages)
    elif "cell.robot.urdf" in robot_tool and _names_packages(robot_tool["cell.robot.urdf"]):
        log.warning(
            "plan bundle: the robot %s names ROS packages and the plan sets no "
            "cell.robot.package_path: where the bundle is used, packages outside the robot's "
            "folder are looked for on ROS_PACKAGE_PATH; set the package path to bundle them",
            robot_tool["cell.robot.urdf"],
        )
    return contents, with_refs(plan, new, package_path)


def _names_packages(urdf: Path) -> bool:
    """Whether a robot file names ROS packages (``$(find pkg)``, ``="package://...``): its first
    16 MiB read."""
    try:
        with urdf.open("rb") as handle:
            head = handle.read(16 * MiB)
    except OSError:
        return False
    return re.search(rb"\$\(find\s|=\s*[\"']package://", head) is not None


def _entry(name: str) -> zipfile.ZipInfo:
    info = zipfile.ZipInfo(name, date_time=ZIP_DATE_TIME)
    info.compress_type = zipfile.ZIP_DEFLATED
    info.create_system = 3  # Unix, whatever writes it
    info.external_attr = 0o100644 << 16  # a regular file, rw-r--r--
    return info


def plan_bundle(plan: Plan, plan_dir: Path, stem: str) -> bytes:
    """The plan with every file it refers to, as one deterministic ZIP archive (see the module
    docstring for its layout).

    Unpacked anywhere, ``<stem>/<stem>.json`` loads with :func:`calib.plan.file.load_plan` and
    its references (all relative to ``<stem>/``, ``builtin:`` ones unchanged) resolve to the
    copied files, with the same bytes and digests.

    Args:
        plan: the plan.
        plan_dir: the folder the plan's relative references resolve against (the plan file's).
        stem: the name of the archive's folder and of the plan file in it (``plan`` gives
            ``plan/plan.json``): letters, digits and ``_ . + ( ) -``, at most 100.

    Returns:
        The archive's bytes (files stored deflated, entries sorted, every time stamp
        1980-01-01 00:00): the same plan and files give the same bytes.

    Raises:
        PlanError: a bad ``stem``; a referenced file missing, a directory, or changed since the
            plan was made (its ``sha256``); a folder that cannot be listed or a file that
            cannot be read; more than :data:`MAX_BUNDLE_BYTES` bytes or
            :data:`MAX_BUNDLE_FILES` files to bundle. The message names the field and the file
            (and the limit).
    """
    _check_stem(stem)
    contents, bundled = _bundle_contents(plan, Path(plan_dir))
    buffer = io.BytesIO()
    written = 0
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        entries = {
            f"{stem}/{stem}.json": None,
            **{f"{stem}/{n}": p for n, p in contents.files.items()},
        }
        for name in sorted(entries):
            source = entries[name]
            if source is None:
                archive.writestr(_entry(name), plan_to_json(bundled).encode("utf-8"))
                continue
            try:
                with source.open("rb") as src, archive.open(_entry(name), "w") as dst:
                    while block := src.read(_CHUNK):
                        written += len(block)
                        if written > MAX_BUNDLE_BYTES:  # a file grew since it was listed
                            raise PlanError(
                                f"plan bundle: the files exceed the limit of "
                                f"{_size(MAX_BUNDLE_BYTES)} (MAX_BUNDLE_BYTES) at {source}"
                            )
                        dst.write(block)
            except OSError as exc:
                raise PlanError(f"plan bundle: cannot read {source}: {exc.strerror}") from None
    return buffer.getvalue()


def save_plan_bundle(plan: Plan, plan_dir: Path, path: str | Path) -> Path:
    """Write :func:`plan_bundle` of ``plan`` atomically to ``path`` (a ``.zip``, whose stem
    names the folder inside) and return the path written.

    Raises:
        PlanError: as :func:`plan_bundle`.
        OSError: ``path`` cannot be written (the error names it).
    """
    return write_bytes_atomic(path, plan_bundle(plan, plan_dir, Path(path).stem))
