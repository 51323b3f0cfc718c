"""Expand a xacro robot description in-process, with the ``xacro`` package from PyPI.

:func:`expand_xacro` runs xacro's own Python API (``xacro.process_file``; no ROS install, no
subprocess) with three things of wobjcal's:

* ``$(find pkg)`` is the folder of package ``pkg`` on the package path
  (:class:`planner.robot.ros_packages.PackagePath`), not ROS's package index;
* every file xacro opens (the robot file, its includes, ``xacro.load_yaml`` files) must lie in
  the robot file's own package (:func:`planner.robot.urdf_meshes.package_root`) or in a package
  of the path, symbolic links resolved: ``$(find pkg)/../../etc/passwd`` is refused, naming
  the path; each file holds at most :data:`calib.reading.MAX_URDF_BYTES`, and at most
  :data:`MAX_FILES` are read;
* the arguments (``<xacro:arg>``) take the values given; a value given for an argument that no
  file read declares is an error naming it and the declared ones.

Errors are :class:`planner.errors.URDFError`, one line naming the file: a missing package (and
the path searched), a missing include file (and the file that includes it), an unknown macro,
an undefined argument or property, malformed XML, an include or a macro that recurses.

xacro keeps its state in module globals (the file stack, the argument values, the list of
includes), so expansions run one at a time (a lock) and put every global they change back.
Measured on the ROS-Industrial IRB 2400 package (3 files): 19 ms, 50 ms the first time (the
import of xacro); building the cell takes seconds, so expansions are not cached (the prepared
file is written by content, :mod:`planner.robot.prepared`).
"""

from __future__ import annotations

import contextlib
import logging
import re
import threading
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any
from xml.parsers.expat import ExpatError

from calib.reading import MAX_URDF_BYTES
from planner.errors import URDFError
from planner.robot.ros_packages import PLAN_FIELD, PackagePath
from planner.robot.urdf_meshes import package_root

log = logging.getLogger(__name__)

#: At most this many files are read by one expansion (a vendor package reads 3 to 10).
MAX_FILES = 500
_ARG_USE = re.compile(r"\$\(arg\s+([A-Za-z_]\w*)\s*\)")
_LOCK = threading.Lock()


class _Refused(URDFError):
    """A file xacro was about to read is refused (outside the packages, too large, too many)."""


def expand_xacro(
    path: Path, packages: PackagePath | None, args: Mapping[str, str] | None = None
) -> str:
    """The URDF text of the xacro file ``path``.

    Args:
        path: the robot's ``.xacro`` file.
        packages: where ``$(find pkg)`` looks (``None``: no package path is set).
        args: values of the file's ``<xacro:arg>`` arguments (strings, as on the command line).

    Raises:
        URDFError: see the module docstring; the message names the file.
    """
    import xacro  # the xacro package: imported when a xacro file is expanded
    import xacro.substitution_args

    source = path.resolve()
    if not source.is_file():
        raise URDFError(f"robot xacro file not found: {path}")
    given = dict(args or {})
    own = package_root(source.parent).resolve()
    roots = tuple(dict.fromkeys((own, *(packages.roots() if packages else ()))))
    guard = _Guard(xacro, source, roots, packages)
    with _LOCK, guard.installed():
        try:
            doc = xacro.process_file(str(source), mappings=dict(given), verbosity=0)
            text: str = doc.toprettyxml(indent="  ")
        except URDFError:
            raise
        except xacro.XacroException as exc:
            raise URDFError(_xacro_message(exc, xacro, source, given)) from None
        except ExpatError as exc:
            where = xacro.filestack[-1] if xacro.filestack else source
            raise URDFError(f"{where}: malformed XML: {exc}") from None
        except RecursionError:
            raise URDFError(
                f"{source}: xacro expansion nests too deep (an include or a macro that "
                "includes or calls itself?)"
            ) from None
    unknown = sorted(set(given) - guard.declared)
    if unknown:
        declared = ", ".join(sorted(guard.declared)) or "none"
        raise URDFError(
            f"{source}: cell.robot.xacro_args gives {', '.join(unknown)}, which no "
            f"<xacro:arg> of the files read declares (declared or used: {declared})"
        )
    return text


def _xacro_message(exc: Any, xacro: Any, source: Path, given: Mapping[str, str]) -> str:
    """One line for a ``XacroException``, naming the file it arose in."""
    stack = [f for f in (xacro.filestack or []) if f]
    where = stack[-1] if stack else str(source)
    inner = exc.exc
    if isinstance(inner, URDFError):
        return str(inner)
    if isinstance(inner, OSError):
        missing = inner.filename or str(exc)
        return f"{where}: xacro include file not found: {missing}"
    from xacro.substitution_args import ArgException

    if isinstance(inner, ArgException):
        name = str(inner)
        return (
            f"{where}: xacro argument {name!r} is used ($(arg {name})) but neither declared "
            "with <xacro:arg name=... default=...> nor given in cell.robot.xacro_args"
        )
    text = " ".join(str(exc).split())
    if text.startswith("unknown macro name: "):
        macro = text.removeprefix("unknown macro name: ")
        return f"{where}: undefined xacro macro <{macro}> (no <xacro:macro> of that name read)"
    return f"{where}: xacro: {text}"


class _Guard:
    """xacro's module globals, replaced for one expansion (see the module docstring)."""

    def __init__(
        self, xacro: Any, source: Path, roots: tuple[Path, ...], packages: PackagePath | None
    ) -> None:
        self.xacro = xacro
        self.source = source
        self.roots = roots
        self.packages = packages
        self.declared: set[str] = set()
        self.files = 0

    def find(self, name: str) -> str:
        if self.packages is None:
            raise URDFError(
                f"{self._current()}: $(find {name}) needs a ROS package path: set "
                f"{PLAN_FIELD} in the plan, or ROS_PACKAGE_PATH, to the folder holding {name}"
            )
        try:
            return str(self.packages.find(name))
        except URDFError as exc:
            raise URDFError(f"{self._current()}: $(find {name}): {exc}") from None

    def _current(self) -> str:
        stack = [f for f in (self.xacro.filestack or []) if f]
        return stack[-1] if stack else str(self.source)

    def check(self, filename: str, opening: bool = False) -> None:
        """Refuse reading ``filename``: outside the packages, too large, or (``opening``: the
        file is being opened now) one file too many."""
        real = Path(filename).resolve()
        if not any(real == r or r in real.parents for r in self.roots):
            shown = ", ".join(str(r) for r in self.roots)
            readers = [f for f in (self.xacro.filestack or []) if f and f != filename]
            where = readers[-1] if readers else str(self.source)
            raise _Refused(
                f"{where}: xacro would read {filename}, which resolves to {real}, "
                f"outside the robot's package and the ROS packages given ({shown})"
            )
        self.files += int(opening)
        if self.files > MAX_FILES:
            raise _Refused(f"{self.source}: xacro reads more than {MAX_FILES} files")
        with contextlib.suppress(OSError):
            if real.stat().st_size > MAX_URDF_BYTES:
                raise _Refused(
                    f"{filename}: {real.stat().st_size / (1 << 20):.0f} MiB, at most "
                    f"{MAX_URDF_BYTES >> 20} MiB for a robot description file"
                )

    def abs_filename_spec(self, original: Callable[[str], str]) -> Callable[[str], str]:
        def guarded(spec: str) -> str:
            full = original(spec)
            if not any(c in full for c in "*[?"):  # a glob: its matches are checked on parse
                self.check(full)
            return full

        return guarded

    def parse(self, original: Callable[..., Any]) -> Callable[..., Any]:
        def guarded(inp: Any, filename: str | None = None) -> Any:
            if inp is None and filename is not None:
                self.check(filename, opening=True)
            doc = original(inp, filename)
            for e in doc.getElementsByTagName("xacro:arg"):
                self.declared.add(e.getAttribute("name"))
            self.declared.update(_ARG_USE.findall(doc.toxml()))  # $(arg x) given, not declared
            return doc

        return guarded

    @contextlib.contextmanager
    def installed(self) -> Iterator[None]:
        """Replace xacro's globals for the expansion; put them all back after."""
        x = self.xacro
        sa = x.substitution_args
        saved = {
            "parse": x.parse,
            "abs_filename_spec": x.abs_filename_spec,
            "warning": x.warning,
            "message": x.message,
            "print_location": x.print_location,
        }
        saved_find, saved_eval_find = sa._eval_find, sa._eval_dict.get("find")
        saved_includes = list(x.all_includes)
        x.parse = self.parse(saved["parse"])
        x.abs_filename_spec = self.abs_filename_spec(saved["abs_filename_spec"])
        x.warning = lambda *a, **k: log.info("xacro: %s", " ".join(map(str, a)))
        x.message = lambda *a, **k: log.debug("xacro: %s", " ".join(map(str, a)))
        x.print_location = lambda *a, **k: None
        sa._eval_find = self.find
        sa._eval_dict["find"] = self.find
        try:
            yield
        finally:
            for name, value in saved.items():
                setattr(x, name, value)
            sa._eval_find = saved_find
            sa._eval_dict["find"] = saved_eval_find
            x.all_includes[:] = saved_includes
            x.substitution_args_context["arg"] = {}


__all__ = ["MAX_FILES", "expand_xacro"]
