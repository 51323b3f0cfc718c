"""Reading a STEP or IGES file with OpenCASCADE: file checks, declared length unit, bodies.

:func:`read_cad_file` checks the file before OpenCASCADE sees it (a STEP file starts with
``ISO-10303-21;`` and ends with ``END-ISO-10303-21;``; an IGES file's last record is its
terminate record, ``T`` in column 73), then reads it into an XCAF document (names on) and
lists its *bodies*: every solid of the assembly tree, placed by the tree's locations and named
by its product (a second instance of a name gets ``#2``, a part of several solids ``.1``,
``.2``, ...). :func:`choose_bodies` takes one explicitly, by name or index, or ``"all"`` (the
bodies together as one rigid part, e.g. a weldment); a file of several bodies without a choice
is refused, naming them.

The length unit is the one the file declares (STEP: the ``LENGTH_UNIT`` of its representation
contexts, read with ``STEPControl_Reader.FileUnits``; IGES: the global section's unit), never
guessed. OpenCASCADE converts the geometry to millimetres as it transfers it
(:data:`MODEL_UNIT_M`); a STEP file that declares no length unit is transferred with its numbers
as they are (as millimetres), so the caller must refuse it or scale it by a unit the user gave.

OpenCASCADE's messages (parse errors, statistics) are kept off the terminal while a file is
read; what went wrong is told by the exceptions here, each naming the file.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from planner.errors import MeshError

#: File suffixes read as B-rep CAD, and their format.
CAD_SUFFIXES: dict[str, str] = {".step": "step", ".stp": "step", ".iges": "iges", ".igs": "iges"}
#: The length unit OpenCASCADE transfers geometry in, metres (its default, millimetres).
MODEL_UNIT_M = 1e-3
#: The ``body`` that takes every body of a file together as one rigid part.
ALL_BODIES = "all"
#: At most this many bodies are named in a message.
_MAX_LISTED = 20
#: Unit names as STEP (``FileUnits``) and IGES (global section) spell them -> canonical name
#: of :data:`calib.units.METRES_PER_UNIT`; others (``FOOT``, ``micrometre``) stay as spelled.
_UNIT_NAMES = {
    "millimetre": "mm",
    "millimeter": "mm",
    "mm": "mm",
    "metre": "m",
    "meter": "m",
    "m": "m",
    "centimetre": "cm",
    "centimeter": "cm",
    "cm": "cm",
    "inch": "in",
    "in": "in",
}
#: OpenCASCADE's reader and its global message printers are shared by the process.
_OCCT_LOCK = threading.Lock()


def is_cad_path(path: str | Path) -> bool:
    """Whether ``path`` names a STEP or IGES file (by its suffix, any case)."""
    return Path(str(path)).suffix.lower() in CAD_SUFFIXES


@dataclass(frozen=True)
class CadBody:
    """One solid of a CAD file.

    Attributes:
        name: its product name (``#k`` for the k-th instance of a name, ``.k`` for the k-th
            solid of a part of several).
        shape: the ``TopoDS_Solid``, placed in the file's frame, millimetres.
    """

    name: str
    shape: Any = field(repr=False)


@dataclass(frozen=True)
class CadFile:
    """A CAD file as read.

    Attributes:
        source: the file path, for messages.
        fmt: ``"step"`` or ``"iges"``.
        unit_names: the length units the file declares, as it spells them (``"INCH"``,
            ``"millimetre"``); ``""`` for a representation that declares none.
        bodies: its solids, in the order of the file's assembly tree.
    """

    source: str
    fmt: str
    unit_names: tuple[str, ...]
    bodies: tuple[CadBody, ...]

    @property
    def unit(self) -> str | None:
        """The declared length unit: a canonical name (``"in"``, ``"mm"``, ...), the file's own
        spelling for another unit, ``None`` when the file declares none (or none for some of
        its shapes).

        Raises:
            MeshError: the file declares different units (then the plan cannot name one).
        """
        names = {_UNIT_NAMES.get(n.strip().lower(), n.strip()) for n in self.unit_names}
        if not names or "" in names:
            return None
        if len(names) > 1:
            raise MeshError(
                f"{self.source}: its shapes declare different length units "
                f"({', '.join(sorted(names))}); wobjcal reads a part in one unit"
            )
        return names.pop()

    def body_list(self) -> str:
        """The bodies as ``0 'box_base', 1 'side_long', ...`` (at most 20 named)."""
        shown = [f"{i} {b.name!r}" for i, b in enumerate(self.bodies[:_MAX_LISTED])]
        more = len(self.bodies) - _MAX_LISTED
        return ", ".join(shown) + (f", ... and {more} more" if more > 0 else "")


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Keep OpenCASCADE's default message printers (stdout) off while reading."""
    from OCP.Message import Message

    messenger = Message.DefaultMessenger_s()
    printers = list(messenger.Printers())
    for p in printers:
        messenger.RemovePrinter(p)
    try:
        yield
    finally:
        for p in printers:
            messenger.AddPrinter(p)


def check_cad_text(path: Path, fmt: str) -> None:
    """Refuse a file that is not a whole STEP or IGES file, before OpenCASCADE parses it.

    Raises:
        MeshError: the file is empty, does not start as its format does, or ends before its
            end marker (truncated); the message names the file and what is missing.
    """
    with path.open("rb") as handle:
        head = handle.read(256)
        handle.seek(0, 2)
        size = handle.tell()
        handle.seek(max(0, size - 4096))
        tail = handle.read()
    if size == 0:
        raise MeshError(f"{path}: empty file (0 bytes): not a {fmt.upper()} file")
    if fmt == "step":
        if not head.lstrip().upper().startswith(b"ISO-10303-21"):
            raise MeshError(
                f"{path}: not a STEP file (a STEP file starts with 'ISO-10303-21;', this one "
                f"with {head.lstrip()[:20]!r})"
            )
        if b"END-ISO-10303-21" not in tail.upper():
            raise MeshError(
                f"{path}: truncated STEP file: it has no 'END-ISO-10303-21;' line at its end "
                f"({size:,} bytes; was the upload or copy cut short?)"
            )
        return
    lines = [ln for ln in tail.splitlines() if ln.strip()]
    if len(head) < 73 or head[72:73] not in (b"S", b"G", b"F"):
        raise MeshError(f"{path}: not an IGES file (no start record, 'S' in column 73)")
    if not lines or lines[-1][72:73] != b"T":
        raise MeshError(
            f"{path}: truncated IGES file: its last record is not the terminate record ('T' "
            f"in column 73; {size:,} bytes; was the upload or copy cut short?)"
        )


def _label_name(label: Any) -> str:
    from OCP.TDataStd import TDataStd_Name

    attr = TDataStd_Name()
    if label.FindAttribute(TDataStd_Name.GetID_s(), attr):
        return str(attr.Get().ToExtString()).strip()
    return ""


def _leaves(shape_tool: Any, label: Any, loc: Any, out: list[tuple[str, Any]]) -> None:
    """Append ``(name, placed shape)`` for every simple shape under ``label``."""
    from OCP.collections import Sequence_TDF_Label
    from OCP.TDF import TDF_Label

    if shape_tool.IsAssembly_s(label):
        comps = Sequence_TDF_Label()
        shape_tool.GetComponents_s(label, comps)
        for i in range(1, comps.Length() + 1):
            comp = comps.Value(i)
            ref = TDF_Label()
            shape_tool.GetReferredShape_s(comp, ref)
            _leaves(shape_tool, ref, loc.Multiplied(shape_tool.GetLocation_s(comp)), out)
        return
    out.append((_label_name(label), shape_tool.GetShape_s(label).Moved(loc)))


def _solids(leaves: list[tuple[str, Any]], stem: str) -> tuple[tuple[CadBody, ...], int]:
    """The solids of the leaves, named; and the number of faces outside any solid."""
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    bodies: list[CadBody] = []
    seen: dict[str, int] = {}
    loose = 0
    for name, shape in leaves:
        solids = []
        ex = TopExp_Explorer(shape, TopAbs_SOLID)
        while ex.More():
            solids.append(ex.Current())
            ex.Next()
        if not solids:
            ex = TopExp_Explorer(shape, TopAbs_FACE)
            while ex.More():
                loose += 1
                ex.Next()
            continue
        base = name or stem
        for k, solid in enumerate(solids):
            one = base if len(solids) == 1 else f"{base}.{k + 1}"
            seen[one] = seen.get(one, 0) + 1
            label = one if seen[one] == 1 else f"{one}#{seen[one]}"
            bodies.append(CadBody(label, solid))
    return tuple(bodies), loose


def _step_units(reader: Any) -> tuple[str, ...]:
    from OCP.collections import Sequence_TCollection_AsciiString

    length = Sequence_TCollection_AsciiString()
    angle = Sequence_TCollection_AsciiString()
    solid = Sequence_TCollection_AsciiString()
    reader.ChangeReader().FileUnits(length, angle, solid)
    return tuple(str(length.Value(i).ToCString()) for i in range(1, length.Length() + 1))


def _load_failures(session: Any) -> str:
    """What OpenCASCADE could not read of the file's entities, in words (``""``: nothing)."""
    checks = session.ModelCheckList(False)
    if checks.IsEmpty(True):
        return ""
    n, first = 0, ""
    checks.Start()
    while checks.More():
        check = checks.Value()
        if check.NbFails():
            n += 1
            first = first or str(check.Fail(1).ToCString())
        checks.Next()
    return f"{n:,} entities could not be read (the first: {first})"


def read_cad_file(path: Path) -> CadFile:
    """Read a STEP or IGES file: its declared length unit and its bodies (millimetres).

    Args:
        path: a ``.step``/``.stp``/``.iges``/``.igs`` file.

    Raises:
        MeshError: not a STEP/IGES file, truncated, unparsable, nothing transferable, or no
            solid in it; each message names the file.
    """
    fmt = CAD_SUFFIXES[path.suffix.lower()]
    check_cad_text(path, fmt)
    try:
        from OCP.IFSelect import IFSelect_RetDone
        from OCP.TCollection import TCollection_ExtendedString
        from OCP.TDocStd import TDocStd_Document
        from OCP.TopLoc import TopLoc_Location
        from OCP.XCAFDoc import XCAFDoc_DocumentTool
    except ImportError as exc:  # a broken install: say what to install
        raise MeshError(
            f"{path}: reading STEP/IGES parts needs the OpenCASCADE bindings "
            f"(pip install cadquery-ocp-novtk): {exc}"
        ) from None
    from OCP.collections import Sequence_TDF_Label

    with _OCCT_LOCK, _quiet():
        doc = TDocStd_Document(TCollection_ExtendedString("wobjcal"))
        if fmt == "step":
            from OCP.STEPCAFControl import STEPCAFControl_Reader

            reader: Any = STEPCAFControl_Reader()
        else:
            from OCP.IGESCAFControl import IGESCAFControl_Reader

            reader = IGESCAFControl_Reader()
        reader.SetNameMode(True)
        reader.SetColorMode(False)
        reader.SetLayerMode(False)
        status = reader.ReadFile(str(path))
        if status != IFSelect_RetDone:
            raise MeshError(
                f"{path}: OpenCASCADE cannot parse this {fmt.upper()} file ({status.name}): "
                "corrupt, or written by a tool that breaks the format"
            )
        xs = reader.ChangeReader() if fmt == "step" else reader
        failed = _load_failures(xs.WS())
        if failed:
            raise MeshError(
                f"{path}: corrupt {fmt.upper()} file: {failed} (a damaged file, or one "
                "written by a tool that breaks the format; export it again)"
            )
        if fmt == "step":
            units = _step_units(reader)
        else:
            units = (str(reader.IGESModel().GlobalSection().UnitName().ToCString()),)
        if not reader.Transfer(doc):
            raise MeshError(f"{path}: OpenCASCADE read the file but could not transfer a shape")
        tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
        free = Sequence_TDF_Label()
        tool.GetFreeShapes(free)
        leaves: list[tuple[str, Any]] = []
        for i in range(1, free.Length() + 1):
            _leaves(tool, free.Value(i), TopLoc_Location(), leaves)
        bodies, loose = _solids(leaves, path.stem)
    if not bodies:
        faces = f"{loose:,} face{'' if loose == 1 else 's'}"
        what = f"{faces} in surfaces or open shells" if loose else "no geometry at all"
        raise MeshError(
            f"{path}: holds no solid body ({what}): a work object must be a solid; export the "
            "part from CAD as a solid (STEP AP203/AP214/AP242 'solid' or 'B-rep')"
        )
    return CadFile(str(path), fmt, units, bodies)


def choose_bodies(cad: CadFile, body: str | int | None) -> tuple[tuple[CadBody, ...], str]:
    """The bodies ``body`` names, and a short name for the part.

    Args:
        cad: the file as read.
        body: ``None`` (the file must hold one body), a body name, its index (0-based, in
            :meth:`CadFile.body_list` order) or :data:`ALL_BODIES`.

    Raises:
        MeshError: several bodies and no choice, or a name/index the file does not hold; the
            message lists the bodies.
    """
    bodies = cad.bodies
    if body is None:
        if len(bodies) == 1:
            return bodies, bodies[0].name
        raise MeshError(
            f"{cad.source}: holds {len(bodies)} bodies ({cad.body_list()}); choose one with "
            f"work_object.body (a name or an index), or {ALL_BODIES!r} to take them together "
            "as one rigid part"
        )
    if isinstance(body, bool) or not isinstance(body, (int, str)):
        raise MeshError(f"work_object.body must be a name or an index, got {body!r}")
    if body == ALL_BODIES:
        return bodies, Path(cad.source).stem
    if isinstance(body, int):
        if 0 <= body < len(bodies):
            return (bodies[body],), bodies[body].name
        raise MeshError(
            f"work_object.body: {cad.source} has no body {body} (it holds {len(bodies)}: "
            f"{cad.body_list()})"
        )
    for b in bodies:
        if b.name == body:
            return (b,), b.name
    raise MeshError(
        f"work_object.body: {cad.source} has no body named {body!r} (it holds "
        f"{len(bodies)}: {cad.body_list()})"
    )
