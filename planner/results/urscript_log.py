"""The URScript results: the lines the program writes to the controller's log.

The URScript program writes one line per search result with ``textmsg`` (PolyScope's log, the
``log_history.txt`` a support file or the log tab's export holds; or any capture of those
lines, e.g. from the primary interface), each line starting ``wobjcal/1``:

- ``wobjcal/1 start <plan digest>``: the program started (``<plan digest>``:
  :func:`calib.plan.file.plan_digest` of the plan it was exported from);
- ``wobjcal/1 point <id> <code> <x> <y> <z>``: a search of point ``<id>`` ended; ``<code>`` 0
  measured, 1 no detection on the path, 2 the input already at the searched level at the
  start; ``x y z`` the sensor TCP at the switching event, robot base frame, in integer
  **nanometres** (``floor(x * 1e9 + 0.5)``: an integer prints exactly whatever the
  controller's float formatting; +-2.147 m, beyond any UR arm's reach from its base);
  a point's second line is its retake (the A-H procedure measures C and D twice);
- ``wobjcal/1 stop <why>``: an adaptive program stopped (a search failed);
- ``wobjcal/1 end``: the program ended.

Whatever stands before ``wobjcal/1`` on a line (a time stamp, the log's source) is ignored. A
log that holds several runs is read from its last ``start`` line; the earlier runs are named
in a note.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

from planner.results.errors import ResultsError
from planner.results.krl_dat import SlotReadings

MARK = "wobjcal/1"
#: Reasons, by the code of a ``point`` line.
CODES = {
    1: "no detection on the search path",
    2: "the input was already at the searched level at the start",
}
_LINE = re.compile(rf"{re.escape(MARK)}\s+(start|point|stop|end)\b\s*(.*?)\s*$")
_POINT = re.compile(r"(\S+)\s+([-+]?\d+)\s+([-+]?\d+)\s+([-+]?\d+)\s+([-+]?\d+)")
NM_PER_M = 1e9


@dataclass
class LogRun:
    """One run of the program in the log.

    Attributes:
        start_line: the line number of its ``start`` line.
        digest: the plan digest its ``start`` line names.
        readings: what it measured (points in metres).
        ended: ``end``, ``stop`` or ``None`` (the log stops before the program's end).
    """

    start_line: int
    digest: str
    readings: SlotReadings
    ended: str | None = None


def parse_urscript_log(
    text: str,
    source: str,
    ids: list[str],
    check_digest: Callable[[str, str], object] | None = None,
) -> LogRun:
    """The last run of the program in the log ``text``, its points by the plan's ``ids``;
    ``check_digest(digest, where)`` is called with the run's plan digest before its lines are
    read (it raises for another plan's run).

    Raises:
        ResultsError: no ``wobjcal/1`` line, result lines before any ``start``, a line that
            cannot be read, a point the plan does not have, a third search of a point, or a
            run with no ``end`` or ``stop`` line (the program was stopped or the log is cut:
            named with the last point the log holds).
    """
    runs: list[tuple[int, list[tuple[int, str, str]]]] = []
    loose: list[int] = []
    for no, raw in enumerate(text.splitlines(), start=1):
        if MARK not in raw:
            continue
        m = _LINE.search(raw)
        if m is None:
            raise ResultsError(f"{source}:{no}: cannot read the {MARK} line {raw.strip()!r}")
        kind, rest = m.group(1), m.group(2)
        if kind == "start":
            runs.append((no, []))
        elif not runs:
            loose.append(no)
        else:
            runs[-1][1].append((no, kind, rest))
    if not runs:
        where = f" (result lines from line {loose[0]} on)" if loose else ""
        raise ResultsError(
            f"{source}: no '{MARK} start' line{where}: not the log of a wobjcal URScript "
            "program's run, or cut before its start"
        )
    start_no, lines = runs[-1]
    start_text = text.splitlines()[start_no - 1]
    m = _LINE.search(start_text)
    digest = m.group(2).split()[0] if m and m.group(2) else ""
    if check_digest is not None:
        check_digest(digest, f"{source}:{start_no}")
    run = LogRun(start_line=start_no, digest=digest, readings=SlotReadings())
    if len(runs) > 1:
        run.readings.notes.append(
            f"the log holds {len(runs)} runs; read the last one, from line {start_no}"
        )
    known = set(ids)
    takes: dict[str, int] = {}
    last = "none"
    r = run.readings
    for no, kind, rest in lines:
        where = f"{source}:{no}"
        if kind in ("end", "stop"):
            run.ended = kind
            if kind == "stop":
                r.notes.append(f"the program stopped: {rest}")
            break
        p = _POINT.fullmatch(rest)
        if p is None:
            raise ResultsError(
                f"{where}: a point line must be '<id> <code> <x> <y> <z>' (integers, nm), got "
                f"{rest!r}"
            )
        pid = p.group(1)
        if pid not in known:
            raise ResultsError(f"{where}: point {pid!r} is not in the plan")
        code = int(p.group(2))
        takes[pid] = takes.get(pid, 0) + 1
        if takes[pid] > 2:
            raise ResultsError(f"{where}: point {pid} searched a third time in one run")
        last = pid
        xyz = tuple(int(p.group(k)) / NM_PER_M for k in (3, 4, 5))
        if code == 0:
            if takes[pid] == 1:
                r.points[pid] = (xyz[0], xyz[1], xyz[2])
            elif pid in r.points:
                r.retakes.setdefault(pid, []).append((xyz[0], xyz[1], xyz[2]))
            else:
                raise ResultsError(f"{where}: a retake of point {pid}, whose first search failed")
        elif code in CODES:
            if takes[pid] == 1:
                r.failed[pid] = CODES[code]
            else:
                r.notes.append(f"the retake of {pid}: {CODES[code]}")
        else:
            raise ResultsError(f"{where}: code {code} of point {pid} is no code the program writes")
    if run.ended is None:
        raise ResultsError(
            f"{source}: the run that starts at line {start_no} has no '{MARK} end' or "
            f"'{MARK} stop' line (last point: {last}): the program was stopped by hand or the "
            "log is cut; nothing is read from a run that may be incomplete"
        )
    missing = [pid for pid in ids if pid not in r.points and pid not in r.failed]
    if missing and run.ended == "end":
        raise ResultsError(
            f"{source}: the run that starts at line {start_no} ended but has no line for "
            f"point(s) {', '.join(missing)}: the log is incomplete"
        )
    for pid in missing:
        r.failed[pid] = "not run (the program stopped before it)"
    return run
