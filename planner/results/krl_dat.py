"""The KUKA KRL results: the program's data list (``.dat``) as the controller saves it.

The KRL program keeps what it measured in its data list: ``xMeas[i]`` the point of slot ``i``
in the robot base (``$WORLD``, taken to be the robot base as the export does; mm) and
``nFail[i]`` how its search ended (0 measured, 1 no detection on the path, 2 the input already
at the searched level at the start, 3 not run). The controller writes the values of a data
list's variables back into its ``.dat`` file as the program runs: an array's elements as lines
``xMeas[1]={X 1510.2,Y -402.7,Z 731.9,A 0.0,B 0.0,C 0.0}`` and ``nFail[1]=0`` after its
``DECL``, a scalar as the value of its ``DECL`` (``DECL INT nResult=1``). The ``.dat``, copied
from the controller after the run (e.g. from ``KRC:\\R1\\Program``), is the results file.

The slots are the program's (:func:`planner.results.layout.krl_slots`): the points in plan
order, then the A-H retakes. KRL names are not case-sensitive; numbers are read in any form
KRL writes (``-402.7``, ``4.027E+02``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from planner.results.errors import ResultsError
from planner.results.layout import Slot

#: How a search ended, by ``nFail`` code.
CODES = {
    1: "no detection on the search path",
    2: "the input was already at the searched level at the start",
    3: "not run (the program stopped before it)",
}
#: How an adaptive program ended, by ``nResult``.
RESULTS = {
    0: "it was still running or was stopped by the operator",
    1: "it ended with the measured frame (not screened yet) in BASE_DATA[10]",
    2: "a search failed and stopped it",
    3: "the points measured define no frame",
    4: "an x-offset search found nothing (the frame was calibrated)",
}

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_DECL_ARRAY = re.compile(r"^\s*DECL\s+(FRAME|INT)\s+(XMEAS|NFAIL)\s*\[\s*(\d+)\s*\]\s*$", re.I)
_ELEMENT = re.compile(r"^\s*(XMEAS|NFAIL)\s*\[\s*(\d+)\s*\]\s*=\s*(.*?)\s*$", re.I)
_SCALAR = re.compile(r"^\s*DECL\s+INT\s+(NRESULT|NSTOPAT)\s*=\s*([-+]?\d+)\s*$", re.I)
_FIELD = re.compile(rf"\s*([A-Z]+)\s+({_NUM})\s*", re.I)
_DIGEST = re.compile(r"plan digest ([0-9a-f]{16})")


@dataclass
class KrlResults:
    """What a KRL ``.dat`` holds.

    Attributes:
        points_mm: ``{slot: (x, y, z)}`` robot base, mm, of each slot with a value.
        codes: ``{slot: nFail}`` of each slot with a value.
        size: the number of slots the ``.dat`` declares.
        result: ``nResult`` (adaptive programs), or ``None``.
        stop_at: ``nStopAt`` (adaptive programs), or ``None``.
        digest: the plan digest of the program's header, or ``None``.
    """

    points_mm: dict[int, tuple[float, float, float]] = field(default_factory=dict)
    codes: dict[int, int] = field(default_factory=dict)
    size: int | None = None
    result: int | None = None
    stop_at: int | None = None
    digest: str | None = None


def _frame_xyz(text: str, where: str) -> tuple[float, float, float]:
    body = text.strip()
    if not (body.startswith("{") and body.endswith("}")):
        raise ResultsError(f"{where}: expected a FRAME value {{X ..,Y ..,Z ..}}, got {text!r}")
    parts: dict[str, float] = {}
    for item in body[1:-1].split(","):
        m = _FIELD.fullmatch(item)
        if m is None:
            raise ResultsError(f"{where}: cannot read {item.strip()!r} as a FRAME component")
        parts[m.group(1).upper()] = float(m.group(2))
    missing = [k for k in "XYZ" if k not in parts]
    if missing:
        raise ResultsError(f"{where}: the FRAME value has no {', '.join(missing)}")
    return parts["X"], parts["Y"], parts["Z"]


def parse_krl_dat(text: str, source: str) -> KrlResults:
    """The results in the ``.dat`` text ``text`` (``source`` names it in errors).

    Raises:
        ResultsError: no ``DEFDAT``, no ``xMeas``/``nFail`` declaration, an element outside
            the declared slots or twice, or a value that cannot be read; each named by line.
    """
    if not re.search(r"^\s*DEFDAT\s", text, re.I | re.M):
        raise ResultsError(f"{source}: not a KRL data list (no DEFDAT line)")
    out = KrlResults()
    sizes: dict[str, int] = {}
    m = _DIGEST.search(text)
    out.digest = m.group(1) if m else None
    for no, raw in enumerate(text.splitlines(), start=1):
        line = raw.split(";", 1)[0]
        where = f"{source}:{no}"
        if d := _DECL_ARRAY.match(line):
            sizes[d.group(2).upper()] = int(d.group(3))
        elif s := _SCALAR.match(line):
            number = int(s.group(2))
            if s.group(1).upper() == "NRESULT":
                out.result = number
            else:
                out.stop_at = number
        elif e := _ELEMENT.match(line):
            name, i, value = e.group(1).upper(), int(e.group(2)), e.group(3)
            label = f"{where}: {'xMeas' if name == 'XMEAS' else 'nFail'}[{i}]"
            if name not in sizes:
                raise ResultsError(f"{label}: before the array's DECL line")
            if not 1 <= i <= sizes[name]:
                raise ResultsError(f"{label}: outside the declared 1..{sizes[name]}")
            if name == "XMEAS":
                if i in out.points_mm:
                    raise ResultsError(f"{label}: given twice")
                out.points_mm[i] = _frame_xyz(value, label)
            else:
                if i in out.codes:
                    raise ResultsError(f"{label}: given twice")
                if not re.fullmatch(r"[-+]?\d+", value):
                    raise ResultsError(f"{label}: expected an INT, got {value!r}")
                out.codes[i] = int(value)
    for name, label in (("XMEAS", "xMeas"), ("NFAIL", "nFail")):
        if name not in sizes:
            raise ResultsError(
                f"{source}: no 'DECL ... {label}[n]' line: not the data list of a wobjcal KRL "
                "program"
            )
    if sizes["XMEAS"] != sizes["NFAIL"]:
        raise ResultsError(
            f"{source}: xMeas has {sizes['XMEAS']} slots and nFail {sizes['NFAIL']}: not a "
            "data list wobjcal wrote"
        )
    out.size = sizes["XMEAS"]
    return out


@dataclass
class SlotReadings:
    """The readings of a program's slots, by point.

    Attributes:
        points: ``{id: (x, y, z)}`` the first measurement of each point (file units).
        retakes: ``{id: [(x, y, z), ...]}`` its later measurements, in order.
        failed: ``{id: reason}`` points not measured.
        notes: what the file says about the run, for the user.
    """

    points: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    retakes: dict[str, list[tuple[float, float, float]]] = field(default_factory=dict)
    failed: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def krl_readings(res: KrlResults, slots: list[Slot], source: str) -> SlotReadings:
    """The points of ``res`` by the program's ``slots``.

    Raises:
        ResultsError: the ``.dat`` has another number of slots than the plan's program, a
            slot has no ``nFail`` (the program never reset it: not a complete run's data
            list), a measured slot has no ``xMeas``, or a code is unknown.
    """
    if res.size != len(slots):
        raise ResultsError(
            f"{source}: xMeas has {res.size} slots, the plan's KRL program {len(slots)}: "
            "results of another plan's program"
        )
    out = SlotReadings()
    for i, (pid, retake) in enumerate(slots, start=1):
        what = f"{source}: slot {i} (point {pid}{', retake' if retake else ''})"
        code = res.codes.get(i)
        if code is None:
            raise ResultsError(
                f"{what}: nFail[{i}] has no value: the program never ran to it or the .dat "
                "was copied before the run"
            )
        if code == 0:
            if i not in res.points_mm:
                raise ResultsError(f"{what}: nFail[{i}] = 0 (measured) but xMeas[{i}] is empty")
            xyz = res.points_mm[i]
            if retake:
                if pid not in out.points:
                    raise ResultsError(f"{what}: a retake of a point not measured first")
                out.retakes.setdefault(pid, []).append(xyz)
            else:
                out.points[pid] = xyz
        elif code in CODES:
            if not retake:
                out.failed[pid] = f"nFail[{i}] = {code}: {CODES[code]}"
            else:
                out.notes.append(f"the retake of {pid} (slot {i}): {CODES[code]}")
        else:
            raise ResultsError(f"{what}: nFail[{i}] = {code} is no code the program writes")
    if res.result is not None and res.result != 1:
        how = RESULTS.get(res.result, f"nResult {res.result} is no value the program writes")
        stop = ""
        if res.stop_at and 1 <= res.stop_at <= len(slots):
            stop = f" at slot {res.stop_at} (point {slots[res.stop_at - 1][0]})"
        out.notes.append(f"the program ended with nResult = {res.result}{stop}: {how}")
    return out
