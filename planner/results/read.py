"""Read a controller's results for a plan: which controller wrote them, and its readings as
:class:`calib.plan.measurements.Measurements` (robot base frame)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Final

import numpy as np
from numpy.typing import NDArray

from calib.plan.file import Plan, plan_digest
from calib.plan.measurements import Measurements, measurements_from_json
from calib.reading import MiB, read_bytes_capped
from planner.plan_cell import nominal_T_base_wobj
from planner.results.errors import ResultsError
from planner.results.fanuc_va import fanuc_readings, parse_numreg, parse_posreg
from planner.results.krl_dat import SlotReadings, krl_readings, parse_krl_dat
from planner.results.layout import krl_slots, plan_order
from planner.results.urscript_log import MARK, parse_urscript_log

FloatArray = NDArray[np.float64]

#: The controllers whose results can be read (``--from``).
KINDS: Final = ("rapid", "krl", "urscript", "fanuc")
#: What each kind's results file is, for messages and ``--help``.
WHAT: Final = {
    "rapid": "the wobjcal.measurements/1 JSON the RAPID program writes",
    "krl": "the program's .dat as the controller saved it after the run",
    "urscript": "the controller's log (or a capture of it) with the program's wobjcal/1 lines",
    "fanuc": "POSREG.VA and NUMREG.VA backed up from MD: (two files, or their folder)",
}
#: Largest results file read (a PolyScope log can be long).
MAX_RESULTS_BYTES: Final = 64 * MiB
_FANUC_FILES: Final = ("POSREG.VA", "NUMREG.VA")


@dataclass
class ControllerResults:
    """A controller's results, read for a plan.

    Attributes:
        kind: the controller (one of :data:`KINDS`).
        measurements: the points, robot base frame.
        notes: what the files say about the run (the program stopped, earlier runs in a log,
            no plan digest to compare), for the user.
        sources: the files read.
    """

    kind: str
    measurements: Measurements
    notes: list[str] = field(default_factory=list)
    sources: tuple[str, ...] = ()


def _text(path: Path) -> str:
    data = read_bytes_capped(path, MAX_RESULTS_BYTES, "results file", ResultsError)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:  # KRL and FANUC files may be ANSI (Windows-1252)
        return data.decode("cp1252", errors="replace")


def _expand(paths: list[Path]) -> list[Path]:
    """The files of ``paths``: a folder stands for the FANUC register files in it."""
    out: list[Path] = []
    for p in paths:
        if not p.is_dir():
            out.append(p)
            continue
        names = {c.name.upper(): c for c in p.iterdir() if c.is_file()}
        found = [names[n] for n in _FANUC_FILES if n in names]
        if not found:
            raise ResultsError(
                f"{p}: a folder, and it holds no {' or '.join(_FANUC_FILES)}: give the results "
                "file itself"
            )
        out += found
    return out


def _kind_of_text(text: str) -> str | None:
    head = text.lstrip()
    if head.startswith("{"):
        return "rapid"
    if "[*POSREG*]$POSREG" in text or "[*NUMREG*]$NUMREG" in text:
        return "fanuc"
    if any(line.lstrip().upper().startswith("DEFDAT") for line in text.splitlines()[:50]):
        return "krl"
    if MARK in text:
        return "urscript"
    return None


def detect_kind(texts: dict[str, str]) -> str:
    """The controller that wrote the files ``{name: text}``.

    Raises:
        ResultsError: a file of no known kind, or files of different kinds (each named).
    """
    kinds: dict[str, str] = {}
    for name, text in texts.items():
        kind = _kind_of_text(text)
        if kind is None:
            raise ResultsError(
                f"{name}: cannot tell which controller wrote it (no JSON, DEFDAT, {MARK} lines "
                "or FANUC register header); give --from " + "|".join(KINDS)
            )
        kinds[name] = kind
    if len(set(kinds.values())) > 1:
        listed = ", ".join(f"{n} ({k})" for n, k in kinds.items())
        raise ResultsError(f"results of different controllers: {listed}")
    return next(iter(kinds.values()))


def _measurements(readings: SlotReadings, units: str, comment: str) -> Measurements:
    return Measurements(
        frame="base",
        units="mm" if units == "mm" else "m",
        points=readings.points,
        retakes=readings.retakes,
        failed=readings.failed,
        comment=comment,
    )


def _digest_note(found: str | None, plan: Plan, source: str) -> list[str]:
    want = plan_digest(plan)
    if found is None or found == "":
        return [f"{source} names no plan digest: not checked that it belongs to this plan"]
    if found != want:
        raise ResultsError(
            f"{source}: measured by the program of plan digest {found}, not of this plan "
            f"(digest {want}): calibrate with the plan the program was exported from"
        )
    return []


def read_results(
    plan: Plan,
    paths: list[str | Path],
    kind: str | None = None,
    T_controller_wobj: FloatArray | None = None,
) -> ControllerResults:
    """Read the results of ``plan``'s program on a controller.

    The points come in the controller's base frame (``frame: base``), as the controller
    measured them; :func:`planner.calibrate.job.calibrate_plan` takes them to the robot base.

    Args:
        plan: the plan the program was exported from.
        paths: the results file(s): one, or for FANUC ``POSREG.VA`` and ``NUMREG.VA`` (or
            the folder holding them).
        kind: the controller (:data:`KINDS`), or ``None`` to detect it from the contents.
        T_controller_wobj: ``(4, 4)`` the nominal work object in the controller's base frame
            as the program declares it (``inv(T_base_controller) @ T_base_wobj``, the base
            from :func:`planner.plan_cell.plan_controller_base`; FANUC's ``PR[1]`` is checked
            against it and the user-frame points taken to the base with it); ``None``: the
            plan's nominal work object in the robot base.

    Raises:
        ResultsError: a file of the wrong kind, malformed or partial, or another plan's
            results (the message names the file and the point or register).
        OSError: a file cannot be read.
    """
    if kind is not None and kind not in KINDS:
        raise ResultsError(f"--from {kind!r}: expected one of {', '.join(KINDS)}")
    files = _expand([Path(p) for p in paths])
    if not files:
        raise ResultsError("no results file given")
    texts = {str(f): _text(f) for f in files}
    found = detect_kind(texts)
    if kind is not None and kind != found:
        raise ResultsError(
            f"{', '.join(texts)}: --from {kind} expects {WHAT[kind]}, but this looks like "
            f"{WHAT[found]}"
        )
    kind = found
    sources = tuple(texts)
    if kind != "fanuc" and len(texts) > 1:
        raise ResultsError(f"{kind} results are one file ({WHAT[kind]}), got {len(texts)}")
    if kind == "rapid":
        ((name, text),) = texts.items()
        m = measurements_from_json(text, source=name)
        notes = _digest_note(m.plan_digest or None, plan, name)
        return ControllerResults(kind, m, notes, sources)
    if kind == "krl":
        ((name, text),) = texts.items()
        dat = parse_krl_dat(text, name)
        notes = _digest_note(dat.digest, plan, name)
        readings = krl_readings(dat, krl_slots(plan), name)
        m = _measurements(readings, "mm", f"KRL data list {Path(name).name}")
        return ControllerResults(kind, m, notes + readings.notes, sources)
    if kind == "urscript":
        ((name, text),) = texts.items()
        said: list[str] = []
        run = parse_urscript_log(
            text,
            name,
            plan_order(plan),
            lambda digest, where: said.extend(_digest_note(digest, plan, where)),
        )
        m = _measurements(run.readings, "m", f"URScript log {Path(name).name}")
        return ControllerResults(kind, m, said + run.readings.notes, sources)
    T_uframe = nominal_T_base_wobj(plan) if T_controller_wobj is None else T_controller_wobj
    return _read_fanuc(plan, texts, T_uframe)


def _read_fanuc(plan: Plan, texts: dict[str, str], T_uframe: FloatArray) -> ControllerResults:
    pos = [n for n, t in texts.items() if "[*POSREG*]$POSREG" in t]
    num = [n for n, t in texts.items() if "[*NUMREG*]$NUMREG" in t]
    if len(pos) != 1 or len(num) != 1 or len(texts) != 2:
        raise ResultsError(
            "FANUC results are two files, POSREG.VA (the points, PR[]) and NUMREG.VA (which of "
            f"them this run measured, R[]); got {', '.join(texts) or 'none'}"
        )
    regs = parse_posreg(texts[pos[0]], pos[0])
    codes = parse_numreg(texts[num[0]], num[0])
    readings = fanuc_readings(regs, codes, plan_order(plan), T_uframe, (pos[0], num[0]))
    notes = [
        "FANUC register backups carry no plan digest: checked instead that PR[1] holds the "
        "plan's nominal work object"
    ]
    m = _measurements(readings, "mm", f"FANUC {Path(pos[0]).name} + {Path(num[0]).name}")
    return ControllerResults("fanuc", m, notes, (pos[0], num[0]))
