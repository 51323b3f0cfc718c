"""Check a KUKA KRL ``.src`` or ``.dat`` with a grammar not written here: ``kuka/krl.g4`` of
ANTLR's grammars-v4 (Jan Schlößin, LGPL-3; reverse-engineered from KRL programs), compiled
to Python by ``antlr-ng`` and vendored in :mod:`tests.grammars.krl` (provenance and how to
regenerate it: ``tests/grammars/README.md``). Needs ``antlr4-python3-runtime`` 4.13.2.

:func:`krl_errors` parses a whole file from the grammar's start rule ``module``: a routine
module (``DEF`` ... ``END``, then more ``DEF``/``DEFFCT``) or a data list (``DEFDAT`` ...
``ENDDAT``); ``&`` header lines and ``;`` comments are skipped. It checks the layout (one
statement a line; in a routine its declarations before its first statement; in a data list
only declarations and array element lines ``name[i]=value``), the block statements and their
ends, motions, interrupts, expressions, aggregates and literals, and that no name is one of
the ~80 keywords the grammar knows.

It does not check what a grammar cannot, nor what this one leaves out: names are any length
and never resolved (no symbol table), so KRL's limit of 24 characters and its case-insensitive
uniqueness of names are not seen (``tests/planner/export/test_krl_program_runs.py`` checks those,
and
:mod:`tests.krl_interp` at run time); nor are types, parameters (``:IN``/``:OUT``), where
``RESUME`` may stand, or keywords it does not know (``RESUME``, ``STEP`` parse as names). Any
expression is a statement (``nResult==0`` on its own passes).

A gap that rejects valid KRL, not bridged because nothing we write runs into it: blank and
comment lines (a comment leaves an empty line) are taken neither before the first ``DEF`` or
``DEFDAT`` nor, in a routine's declaration part, one at a time (``mismatched input 'DECL'
expecting END`` after a single comment line between ``DEF`` and a ``DECL``).
"""

from __future__ import annotations

from typing import Any

from antlr4 import CommonTokenStream, InputStream
from antlr4.error.ErrorListener import ErrorListener

from tests.grammars.krl.krlLexer import krlLexer
from tests.grammars.krl.krlParser import krlParser


class _Collect(ErrorListener):
    """Keeps every syntax error of the lexer and the parser as ``"line:col message"``."""

    def __init__(self) -> None:
        super().__init__()
        self.errors: list[str] = []

    def syntaxError(  # the runtime's name
        self, recognizer: Any, offendingSymbol: Any, line: int, column: int, msg: str, e: Any
    ) -> None:
        self.errors.append(f"{line}:{column} {msg}")


def krl_errors(text: str) -> list[str]:
    """The syntax errors the grammar finds in the ``.src`` or ``.dat`` ``text``, lexer's and
    parser's, as ``"line:col message"`` (``[]``: it parses)."""
    found = _Collect()
    lexer = krlLexer(InputStream(text))
    lexer.removeErrorListeners()
    lexer.addErrorListener(found)
    parser = krlParser(CommonTokenStream(lexer))
    parser.removeErrorListeners()
    parser.addErrorListener(found)
    parser.module()
    return found.errors
