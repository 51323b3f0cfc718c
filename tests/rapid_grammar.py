"""Check a RAPID module with ``rapidchecker`` (PyPI: a pyparsing grammar of ABB RAPID, not
written here), allowing for the two RAPID constructs that tool does not know.

- A doubled quote inside a string (``"{""schema"": ...``) is RAPID's escape for a quote; the
  tool ends the string there. Each ``""`` inside a string is replaced by ``'`` first.
- An array index is any integer expression in RAPID (``nH{(r+1)*(c-1)+c}``); the tool takes
  only a literal or a name. Each index that is not is replaced by a name, innermost first,
  and every expression taken out is checked by the tool as the right-hand side of an
  assignment (``xIdx:=<expression>;``: all of them in one routine, each on its own when that
  fails, to name it), so nothing escapes the grammar.

Everything else, from the module's layout (data declarations before routines) to every
statement, is the tool's verdict. Indentation is checked at the module's 4 spaces.
"""

from __future__ import annotations

import functools
import re

_STRING = re.compile(r'"(?:[^"\n]|"")*"')
#: An index in braces after a name, with no brace inside (innermost first).
_INDEX = re.compile(r"(?<=[A-Za-z0-9_])\{([^{}\n]*)\}")
_SIMPLE = re.compile(r"\s*([A-Za-z_][A-Za-z0-9_]*|\d+)\s*")


def _checker():  # type: ignore[no-untyped-def]
    from rapidchecker import config

    config.CONFIG.indentation_size = 4
    config.CONFIG.max_empty_lines = 2
    from rapidchecker.check import check_format

    return check_format


def _normalised(text: str) -> tuple[str, list[str]]:
    """``text`` with the tool's two gaps bridged, and the index expressions taken out."""
    text = _STRING.sub(lambda m: '"' + m.group(0)[1:-1].replace('""', "'") + '"', text)
    taken: list[str] = []

    def index(m: re.Match[str]) -> str:
        if _SIMPLE.fullmatch(m.group(1)) or "," in m.group(1):
            return m.group(0) if "," not in m.group(1) else "{" + _multi(m.group(1)) + "}"
        taken.append(m.group(1))
        return "{xIdx}"

    def _multi(inner: str) -> str:  # several indices: each its own
        parts = inner.split(",")
        out = []
        for part in parts:
            if _SIMPLE.fullmatch(part):
                out.append(part.strip())
            else:
                taken.append(part)
                out.append("xIdx")
        return ",".join(out)

    lines = []
    for line in text.split("\n"):
        code, comment = _split_comment(line)
        while True:  # innermost first
            new = _INDEX.sub(index, code)
            if new == code:
                break
            code = new
        lines.append(code + comment)
    return "\n".join(lines), taken


def _split_comment(line: str) -> tuple[str, str]:
    """``(code, comment)`` of a line: the comment from the first ``!`` outside a string."""
    quoted = False
    for k, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif ch == "!" and not quoted:
            return line[:k], line[k:]
    return line, ""


def rapid_errors(text: str) -> list[str]:
    """What ``rapidchecker`` finds in the module ``text`` (``[]``: it passes), with the index
    expressions checked one by one. A text checked before in this process is not parsed again
    (two plan variants give the same RAPID module; the parse takes about 0.1 ms a character)."""
    return list(_errors_of(text))


@functools.lru_cache(maxsize=32)
def _errors_of(text: str) -> tuple[str, ...]:
    check_format = _checker()
    module, taken = _normalised(text)
    out = [f"module {e}" for e in check_format(module)]
    exprs = sorted(set(taken))
    # all index expressions in one routine first (one parse, not one per expression: a
    # routine's statements parse each on its own, so it passes exactly when each does); only
    # when it fails is each checked alone, to name the ones that fail (and where)
    if exprs and check_format(_index_probe(exprs)):
        for expr in exprs:
            out += [f"index {expr!r}: {e}" for e in check_format(_index_probe([expr]))]
    return tuple(out)


def _index_probe(exprs: list[str]) -> str:
    """A module whose routine assigns each of ``exprs`` to an index variable."""
    body = "".join(f"        xIdx:={expr};\n" for expr in exprs)
    return f"MODULE WobjcalIndex\n    VAR num xIdx;\n\n    PROC p()\n{body}    ENDPROC\nENDMODULE\n"
