"""Text that goes into robot programs: identifiers, numbers, and names made safe.

Every writer (:mod:`planner.export`) formats numbers with :func:`fmt`, makes identifiers with
:func:`identifier` and passes plan names and point ids through :func:`comment_text` (comments)
or :func:`literal_text` (string literals): plans already restrict ids and names
(:data:`calib.plan.base.POINT_ID_PATTERN`), but a job built in code may hold anything, and no
text of a job may end a comment or a string and become a statement.
"""

from __future__ import annotations

import re


def identifier(text: str, prefix: str = "p") -> str:
    """A robot-language identifier made of ``text``: ASCII letters, digits and ``_`` only."""
    ident = re.sub(r"[^A-Za-z0-9_]", "_", text)
    if not ident or not ident[0].isalpha():
        ident = prefix + ident
    return ident


def comment_text(text: object) -> str:
    """``text`` safe inside a one-line program comment: control characters (line breaks,
    tabs) become spaces, so nothing after them can become a statement. Every writer passes
    names and ids through it (plans restrict ids already; jobs built in code may not)."""
    return re.sub(r"[\x00-\x1f\x7f\u2028\u2029\x85]", " ", str(text))


def literal_text(text: object) -> str:
    """``text`` safe inside a string literal of any robot language: letters, digits and
    ``_ . -`` kept, anything else (quotes, backslashes, line breaks) replaced by ``_``."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", str(text))


def file_stem(name: str, fallback: str = "wobjcal_plan") -> str:
    """A file name (without suffix) made of ``name``: letters, digits and ``_ - .`` kept, every
    run of anything else (spaces, ``/``, ``:`` ...) one ``_``; no leading ``.`` or ``-`` (a
    hidden file, an option), no trailing ``.``; ``fallback`` when nothing is left."""
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", name).lstrip(".-").rstrip(".")
    return stem or fallback


def module_name(plan_name: str) -> str:
    """``"stator_section_ah"`` -> ``"WobjcalStatorSectionAh"`` (max 32 characters)."""
    words = re.split(r"[^A-Za-z0-9]+", plan_name)
    return ("Wobjcal" + "".join(w[:1].upper() + w[1:] for w in words if w))[:32]


def fmt(x: float, decimals: int = 4) -> str:
    """A number for program text: fixed decimals, no ``-0``, trailing zeros trimmed."""
    s = f"{x:.{decimals}f}"
    if "." in s:  # trailing zeros of the decimals only: 10 stays 10
        s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s
