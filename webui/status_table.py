"""The points' status table and the details of one point, as Markdown.

One row per point: an icon and the status (✓ feasible, ⚠ marginal, ✗ infeasible, … being
checked; the icon follows the check, so a point its procedure cannot use, flagged **role** in
purple beside it, still shows ✗ when it cannot be probed), the point's id and role, and the
first cause, short: the check's first reason (or the role flag's when the check passes)
without the part's size note (``work object NAME: 0.2 x 0.3 x 0.0127 m (file units 'm',
given)``, which the check adds to every reason about the part), cut at :data:`SHORT_CHARS`; a
collision cut short names its pair (:func:`short_cause`). :func:`details_markdown` gives every
cause of one point, one per line, with the part's note once, its clearance, position and
search: the Points tab shows it for the tab's selected point. The causes are the check's
:class:`planner.reasons.Reason` s (:attr:`planner.check.results.PointCheck.causes`): their
text, note and pair, never words searched for.
"""

from __future__ import annotations

from collections.abc import Mapping

from planner.check.job import PointCheck
from planner.reasons import Reason
from webui.markdown_text import plain
from webui.plan_doc import NO_ROLE, UiPlan, UiPoint
from webui.scene import STATUS_RGB

#: The icon of each status (``checking``: no check yet).
ICON: dict[str, str] = {"feasible": "✓", "marginal": "⚠", "infeasible": "✗", "checking": "…"}
#: The first cause is cut at about this many characters (at a word), with "…".
SHORT_CHARS = 64
#: The header of the table.
HEADER = ("| status | point | role | first cause |", "|---|---|---|---|")
#: Below the table: where the rest is.
HINT = "*Select a point (its marker, or **Selected** below) for all its causes.*"


def _colour(rgb: tuple[int, int, int], text: str) -> str:
    r, g, b = rgb
    return f"<span style='color:rgb({r},{g},{b})'>{text}</span>"


def causes(check: PointCheck | None) -> list[Reason]:
    """The check's causes in order (``[]`` without a check)."""
    return [] if check is None else list(check.causes)


def part_note(check: PointCheck | None) -> str:
    """The part's size note the check added to its reasons about the part (``work object
    NAME: ... (file units 'm', given)``), or ``""``."""
    return next((r.note for r in causes(check) if r.note), "")


def shorten(text: str, limit: int = SHORT_CHARS) -> str:
    """``text`` cut at the last word before ``limit`` characters, with "…" (whole if short)."""
    if len(text) <= limit:
        return text
    cut = text[:limit].rsplit(" ", 1)[0].rstrip(",;:(")
    return cut + " …"


def short_cause(cause: Reason, limit: int = SHORT_CHARS) -> str:
    """A cause for the table, without the part's note: its text when short; else one with a
    pair (a collision, a move's collision) named by its kind and pair, e.g. ``"collision:
    sensor_body – table"``, and any other cut at a word (:func:`shorten`)."""
    if len(cause.text) <= limit or cause.pair is None:
        return shorten(cause.text, limit)
    return shorten(f"{cause.kind}: {cause.pair[0]} – {cause.pair[1]}", limit)


def status_cell(check: PointCheck | None, flag: str) -> str:
    """The icon and status word (coloured as the markers are), with a **role** mark when the
    procedure cannot use the point."""
    status = "checking" if check is None else check.status
    rgb = STATUS_RGB.get("pending" if check is None else status, STATUS_RGB["unknown"])
    word = "checking..." if check is None else status
    cell = f"{_colour(rgb, ICON.get(status, '?'))} {word}"
    if flag:
        cell += " " + _colour(STATUS_RGB["role"], "**role**")
    return f"<span style='white-space:nowrap'>{cell}</span>"


def first_cause(check: PointCheck | None, flag: str) -> str:
    """The short reason of a row: the check's first cause, or the role flag's when the check
    passes (``""``: nothing to say)."""
    found = causes(check)
    if check is not None and check.status == "infeasible" and found:
        # what makes it infeasible first: a pose that is only marginal (a joint near its
        # limit) comes after the search path, face, moves or landing that fail
        if check.pose_status != "infeasible" and check.pose_cause is not None and len(found) > 1:
            found = [r for r in found if r is not check.pose_cause] or found
        return short_cause(found[0])
    if flag:
        return shorten(flag)
    return short_cause(found[0]) if found else ""


def table_rows(
    doc: UiPlan, checks: Mapping[str, PointCheck], flags: Mapping[str, str], none_role: str
) -> list[str]:
    """The table's Markdown lines: header and one row per point (``none_role``: what a point
    without a role shows)."""
    rows = list(HEADER)
    for p in doc.points:
        c, flag = checks.get(p.id), flags.get(p.id, "")
        role = p.role if p.role != NO_ROLE else none_role
        why = plain(first_cause(c, flag))
        rows.append(f"| {status_cell(c, flag)} | {p.id} | {role} | {why} |")
    if not doc.points:
        rows.append("| - | - | - | no points yet: click the work object |")
    return rows


def details_markdown(point: UiPoint, check: PointCheck | None, flag: str) -> str:
    """Everything known about one point, one cause per line (Markdown): its status, every
    cause of its check, the role flag, the part's note once, the clearance of the probe pose,
    its position (mm) and normal (wobj frame) and its search (mm)."""
    lines = [f"**{plain(point.id)}**: {status_cell(check, flag)}"]
    reasons = causes(check)
    lines += [f"- {plain(c.text)}" for c in reasons]
    if flag:
        lines.append(f"- role: {plain(flag)}")
    if check is not None and not reasons and check.status == "feasible":
        lines.append("- reachable, search path clear")
    note = part_note(check)
    if note:
        lines.append(f"- part: {plain(note)}")
    if check is not None and check.clearance_m == check.clearance_m:  # not NaN
        pair = f" ({plain(' – '.join(check.clearance_pair))})" if check.clearance_pair else ""
        more = "≥ " if check.clearance_is_lower_bound else ""
        lines.append(f"- clearance {more}{check.clearance_m * 1e3:.1f} mm{pair}")
    pr = point.probe
    xyz = ", ".join(f"{v * 1e3:.1f}" for v in pr.position_m)
    nrm = ", ".join(f"{v:.3f}" for v in pr.normal)
    s = pr.search
    lines.append(f"- at ({xyz}) mm, normal ({nrm}), wobj frame")
    lines.append(
        f"- {s.kind} search: start {s.start_offset_m * 1e3:.1f} mm, overtravel "
        f"{s.overtravel_m * 1e3:.1f} mm"
    )
    return "\n".join(lines)
