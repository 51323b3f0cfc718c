"""Robot programs from a plan: the export job and one writer per robot language.

Owns:
    - :mod:`planner.export.job`: :class:`~planner.export.job.ExportJob` (what every writer
      formats: the nominal work object, the sensor tool, one :class:`TargetPair` per point,
      the safe starts and the adaptive A-H spec) and :func:`~planner.export.job.build_job`;
    - :mod:`planner.program.safety`: safe search starts under the plan's misplacement;
    - :mod:`planner.export.text`: identifiers, numbers, and names made safe for comments and
      string literals, shared by writers;
    - one module per language, with its helpers: ``rapid`` (+ ``rapid_probe``,
      ``rapid_adaptive``, ``rapid_steer``, ``rapid_write``), ``krl`` (+ ``krl_probe``,
      ``krl_adaptive``, ``krl_steer``, ``krl_xoffset``, ``krl_text``), ``urscript`` (+
      ``urscript_layout``, ``urscript_probe``, ``urscript_adaptive``, ``urscript_steer``,
      ``urscript_xoffset``), ``fanuc`` (FANUC TP ``.ls``, nominal); the adaptive ones write the
      frame updates of :mod:`planner.program`;
    - :mod:`planner.export.paste`: :class:`~planner.export.paste.PasteLines`, a calibrated
      frame in a controller's syntax (what ``wobjcal calibrate`` prints to paste);
    - the registry :data:`FORMATS` and :func:`export_files`.

A writer is a function ``(ExportJob) -> {file suffix: text}`` (KRL writes a ``.src`` and a
``.dat``); beside it, a function ``(T_base_wobj) -> PasteLines`` writes a calibrated frame in
the same language. Adding a robot language is one module with both plus one entry in
:data:`FORMATS`; the command line (``wobjcal export --format NAME``, the lines ``wobjcal
calibrate`` prints), the web UI's download buttons and the tests all look formats up here::

    CONTROLLERS["mylang"] = Controller("mylang", "MyLang", "Maker")  # planner.program
    FORMATS["mylang"] = ExportFormat(
        "mylang", "planner.export.mylang:export_mylang", (".prg",),
        "planner.export.mylang:paste_lines",
    )

Writers are imported when first used (:func:`calib.registry.load`), so listing the formats
imports no writer. Files are
named after the plan (:func:`export_file_stem`; the command line's ``-o DIR`` and the UI's
downloads), or after the program where the controller wants that (``program_name``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from calib.registry import load, lookup
from planner.export.job import ExportJob, TargetPair, ToolData, build_job
from planner.export.paste import PasteLines
from planner.export.text import file_stem, module_name
from planner.program.controllers import CONTROLLERS

#: A writer: the program files of a job, ``{suffix: text}``.
Writer = Callable[[ExportJob], dict[str, str]]
#: The lines to paste for a calibrated ``(4, 4)`` ``T_base_wobj`` (robot base, metres).
PasteWriter = Callable[[NDArray[np.float64]], PasteLines]


@dataclass(frozen=True)
class ExportFormat:
    """One robot-program format: the writer of one controller's programs.

    Attributes:
        name: the format's name on the command line, e.g. ``"rapid"``: a controller of
            :data:`planner.program.controllers.CONTROLLERS` (its language's name, its vendor and
            what its programs compute are recorded there, once).
        writer: ``"module:function"`` of the writer ``(ExportJob) -> {suffix: text}``.
        suffixes: the suffixes of the files the writer returns, first one first (the first
            file is written to the output path, the others beside it with their suffix).
        paste: ``"module:function"`` of ``(T_base_wobj) -> PasteLines``: a calibrated work
            object in this language (:meth:`paste_lines`).
        program_name: ``"module:function"`` naming the program from the job's name, for a
            controller whose file must be named as the program in it (KRL's ``DEF``, FANUC's
            ``/PROG``); ``""``: the files are named after the plan (:meth:`file_stem`).
    """

    name: str
    writer: str
    suffixes: tuple[str, ...]
    paste: str
    program_name: str = ""

    @property
    def label(self) -> str:
        """The language's name, as the UI's download button shows it, e.g. ``"RAPID"``."""
        return CONTROLLERS[self.name].label

    @property
    def vendor(self) -> str:
        """The robot maker, e.g. ``"ABB"``."""
        return CONTROLLERS[self.name].vendor

    def load(self) -> Writer:
        """The writer function (imports its module)."""
        writer: Writer = load(self.writer)
        return writer

    def paste_lines(self, T_base_wobj: NDArray[np.float64]) -> PasteLines:
        """The lines that give this controller the calibrated work object ``T_base_wobj``
        (``(4, 4)``, robot base, metres), in its language (imports the writer's module)."""
        paste: PasteWriter = load(self.paste)
        return paste(np.asarray(T_base_wobj, dtype=np.float64))

    def file_stem(self, plan_name: str) -> str:
        """The name (without suffix) of the files of the plan named ``plan_name``, as the
        command line and the UI's downloads name them: the program's name where the controller
        wants the file named so (:attr:`program_name`), else the plan's name made safe for file
        systems (:func:`planner.export.text.file_stem`)."""
        if not self.program_name:
            return file_stem(plan_name)
        name: Callable[[str], str] = load(self.program_name)
        return file_stem(name(module_name(plan_name or "plan")))


#: The robot-program formats by name.
FORMATS: dict[str, ExportFormat] = {
    f.name: f
    for f in (
        ExportFormat(
            "rapid",
            "planner.export.rapid:rapid_files",
            (".mod",),
            "planner.export.rapid:paste_lines",
        ),
        ExportFormat(
            "krl",
            "planner.export.krl:export_krl",
            (".src", ".dat"),
            "planner.export.krl:paste_lines",
            "planner.export.krl:program_name",
        ),
        ExportFormat(
            "urscript",
            "planner.export.urscript:urscript_files",
            (".script",),
            "planner.export.urscript:paste_lines",
        ),
        ExportFormat(
            "fanuc",
            "planner.export.fanuc:export_fanuc",
            (".ls",),
            "planner.export.fanuc:paste_lines",
            "planner.export.fanuc_text:program_name",
        ),
    )
}
#: What ``wobjcal export --format`` accepts: the robot formats and the plan's own JSON.
FORMAT_CHOICES = (*FORMATS, "json")

__all__ = [
    "FORMATS",
    "FORMAT_CHOICES",
    "ExportFormat",
    "ExportJob",
    "PasteLines",
    "PasteWriter",
    "TargetPair",
    "ToolData",
    "Writer",
    "build_job",
    "export_file_stem",
    "export_files",
]


def export_file_stem(plan_name: str, fmt: str) -> str:
    """The name (without suffix) of the files of the plan named ``plan_name`` in ``fmt`` (a
    key of :data:`FORMATS`, or ``"json"``: the plan's name made safe for file systems)."""
    if fmt in FORMATS:
        return FORMATS[fmt].file_stem(plan_name)
    return file_stem(plan_name)


def export_files(job: ExportJob, fmt: str) -> dict[str, str]:
    """The program files of ``job`` in the robot format ``fmt`` (a key of :data:`FORMATS`).

    Returns:
        ``{suffix: text}``, e.g. ``{".mod": ...}`` or ``{".src": ..., ".dat": ...}``.

    Raises:
        InputError: unknown format (the message lists the known ones).
    """
    files = lookup(FORMATS, fmt, "export format (--format)").load()(job)
    if tuple(files) != FORMATS[fmt].suffixes:
        raise RuntimeError(f"writer of {fmt!r} returned {list(files)}, not {FORMATS[fmt].suffixes}")
    return files
