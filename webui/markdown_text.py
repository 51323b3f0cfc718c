"""Text from the plan, the check or a file shown in a viser Markdown widget as it is: one line,
every Markdown character escaped (a reason naming ``link_1`` or ``*.stl`` stays that text)."""

from __future__ import annotations

#: Characters Markdown would read as markup.
MARKUP = "\\`*_[]<>#|"


def plain(text: str) -> str:
    """``text`` as literal Markdown on one line (whitespace runs made single spaces)."""
    out = " ".join(text.split())
    for c in MARKUP:
        out = out.replace(c, "\\" + c)
    return out
