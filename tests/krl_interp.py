"""An interpreter, for tests, of the KUKA KRL that ``planner.export.krl`` writes (and more).

:class:`KrlMachine` loads a ``.src``/``.dat`` pair (``planner.export.export_files(job, "krl")``)
and runs the module's first ``DEF`` against a simulated robot, so tests can check what a program
*does*, not only what it says (:meth:`KrlMachine.call` then calls one of its routines, as a
statement of the main program would: e.g. a function the program offers but never calls). It
checks what the KRL compiler and controller check, so that wrong KRL fails here too: names of
at most 24 characters, case-insensitive (``xA`` is ``XA``),
declared once; declarations before the first statement; every parameter declared; constant
values in data lists; values invalid until assigned (reading one is an error); write-protected
``$IN``; types of assignments and operands. Anything it does not know is an error naming the
line, never skipped.

Language (KSS 8, one statement a line, ``;`` comments, ``&`` header lines ignored):

- data: ``[GLOBAL] DECL [CONST] type name[dims][=value], ...`` (``DECL`` optional for INT,
  REAL, BOOL, CHAR) of INT, REAL, BOOL, CHAR (CHAR arrays take strings), ``ENUM`` types, FRAME,
  POS, E6POS, AXIS, E6AXIS, LOAD, INERTIA and ``STRUC`` types; arrays of 1-3 dimensions indexed
  from 1 (``name[]``: the whole array, for strings and :OUT array parameters);
  ``SIGNAL name $IN[n]`` / ``$OUT[n]``; data lists (``DEFDAT``) with element lines
  ``name[i]=value``;
- expressions: ``12``, ``1.5E-3``, ``'H1F'``, ``'B101'``, ``"text"``, ``TRUE``, ``#ENUM``,
  aggregates ``{X 1,Y 2}`` (``{E6POS: X 1}``; missing components stay as they were),
  components, indices, ``+ - * /`` (INT / INT truncates), comparisons, ``NOT AND OR EXOR``,
  ``B_NOT B_AND B_OR B_EXOR`` and the geometric operator ``:`` (frame composition; the result
  has the type of the right operand), with KRL's priorities: ``:`` binds strongest, then
  ``NOT``/sign, ``* /``, ``+ -``, ``AND``, ``EXOR``, ``OR``, and the comparisons weakest (write
  ``(a>0) AND (b>0)``); functions ``ABS SQRT SIN COS TAN ACOS ATAN2`` (degrees), ``INV_POS``
  and the module's ``DEFFCT`` functions;
- statements: assignment, ``IF/ELSE/ENDIF``, ``FOR i=a TO b [STEP s]/ENDFOR``,
  ``WHILE/ENDWHILE``, ``REPEAT/UNTIL``, ``LOOP/ENDLOOP``, ``EXIT``,
  ``SWITCH/CASE/DEFAULT/ENDSWITCH``, calls of ``DEF`` subprograms with ``:IN`` (by value) and
  ``:OUT`` (by reference, the default) parameters, ``RETURN [value]``, ``HALT`` (ends the run:
  :attr:`KrlMachine.halted`), ``WAIT SEC`` (no time passes), ``WAIT FOR`` (must already hold),
  ``CONTINUE``, ``BAS(#INITMOV|#TOOL|#BASE|#VEL_PTP|#ACC_PTP|#VEL_CP|#ACC_CP, value)``;
- interrupts: ``[GLOBAL] INTERRUPT DECL prio WHEN cond DO routine(args)`` (the condition reads
  module or system data only), ``INTERRUPT ON|OFF|ENABLE|DISABLE [prio]``; an interrupt fires when
  its condition turns TRUE (an edge; TRUE already at ``ON`` does not fire), is known at the
  level of the routine that declared it and below, and is dropped when that routine ends
  (``GLOBAL``: kept). ``BRAKE [F]`` in an interrupt routine stops the robot (at the event: no
  braking distance); the interrupted motion goes on when the routine ends, unless it runs
  ``RESUME``, which ends the routines down to the declaring level and goes on after the call
  (in the declaring routine) into the level below. KSS refuses a RESUME when the interrupted
  motion runs in the declaring routine itself ("impermissible program structure for RESUME"):
  so does this interpreter.

Motion (mm and degrees; ``$WORLD`` = ``$ROBROOT`` = the robot base): ``PTP`` and ``LIN`` (also
``SPTP``, ``SLIN``; approximation ``C_PTP``/``C_DIS``/... ignored: every motion ends at its
target) to a FRAME/POS/E6POS or aggregate put the TCP at ``$BASE:target`` (components the target
lacks keep their current value). ``PTP`` to AXIS/E6AXIS records the axes: there are no
kinematics here, so the TCP is unknown until the next Cartesian target. ``LIN_REL``/``PTP_REL``
move by a translation in ``#BASE`` (the default) or by a frame in ``#TOOL``. ``$POS_ACT`` is the
TCP in the current ``$BASE``; ``$TOOL`` only relates the TCP to the flange (in the motion log).

The sensor is the input ``$IN[sensor_input]``. A ``LIN`` while an interrupt whose condition reads
that input is on asks ``search(start_m, end_m, sensor_axis, neg_flank)`` -- robot base, metres,
the TCP's z axis, ``neg_flank`` when the input is on and the search waits for it to go off, the
contract of :mod:`tests.rapid_interp` -- for the point where the input changes, ``(3,)``, or a
string: no change on the way, or ``"ERR_SIGSUPSEARCH"``, the input was already at the other
level before the motion (it flips then, and no interrupt sees an edge). Where it changes, the
input flips, the interrupts whose condition turns TRUE fire with ``$POS_INT`` = that pose in
the current ``$BASE``, and the TCP stays there if one of them ends the motion. ``PTP`` with
such an interrupt on is an error (its path is not modelled). After every motion that reaches
its target the input is
``sensor(tcp_m, sensor_axis)`` when that callback is given; without it, FALSE after a motion
that moved the TCP (more than 1e-6 mm), unchanged after one that did not (so it stays on after
a search stopped on the part and a move to where it stopped).

REAL is float64 here unless ``KrlMachine(..., real_float32=True)``: then, as on the controller
(KRL's REAL is an IEEE 754 single), every REAL is rounded to float32 where it is made or stored:
literals, the result of each ``+ - * /`` on REALs (so that arithmetic is exactly single
precision), of each built-in function, of ``:`` and ``INV_POS`` (their components; the maths
inside is float64), ``$POS_ACT``/``$POS_INT``, and every value stored in a REAL or a REAL
component of a structure (FRAME, POS, E6POS...). INT stays exact.
"""

from __future__ import annotations

import copy
import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from calib.frames import (
    invert_transform,
    make_transform,
    matrix_from_rotvec,
    matrix_from_tait_bryan_zyx,
    rotvec_from_matrix,
    tait_bryan_zyx_from_matrix,
)

#: Longest name KRL accepts.
MAX_NAME = 24
#: Number of digital inputs and outputs.
N_IO = 4096
#: A motion shorter than this (mm) leaves the sensor input as it was.
MOVE_TOL_MM = 1e-6
#: A search answer farther than this from the commanded line (mm) is refused.
LINE_TOL_MM = 1e-6
#: Statements one run may execute (an endless loop fails instead of hanging the test).
MAX_STEPS = 1_000_000

SearchFn = Callable[[np.ndarray, np.ndarray, np.ndarray, bool], "np.ndarray | str"]
SensorFn = Callable[[np.ndarray, np.ndarray], bool]

SIMPLE = ("INT", "REAL", "BOOL", "CHAR")
_FRAME = tuple((c, "REAL") for c in "XYZABC")
_EXT = tuple((f"E{k}", "REAL") for k in range(1, 7))
_AXES = tuple((f"A{k}", "REAL") for k in range(1, 7))
_ST = (("S", "INT"), ("T", "INT"))
#: The predefined structure types: ``{type: ((component, type), ...)}``.
STRUCTS: dict[str, tuple[tuple[str, str], ...]] = {
    "FRAME": _FRAME,
    "POS": _FRAME + _ST,
    "E6POS": _FRAME + _EXT + _ST,
    "AXIS": _AXES,
    "E6AXIS": _AXES + _EXT,
    "INERTIA": (("X", "REAL"), ("Y", "REAL"), ("Z", "REAL")),
    "LOAD": (("M", "REAL"), ("CM", "FRAME"), ("J", "INERTIA")),
    "CP": (("CP", "REAL"), ("ORI1", "REAL"), ("ORI2", "REAL")),
    "APO": (("CVEL", "INT"), ("CPTP", "INT"), ("CDIS", "REAL"), ("CORI", "REAL")),
}
#: Types whose values convert into each other (common components copied).
FAMILIES = ({"FRAME", "POS", "E6POS"}, {"AXIS", "E6AXIS"})
MOTIONS = {
    "PTP": "PTP",
    "LIN": "LIN",
    "SPTP": "PTP",
    "SLIN": "LIN",
    "PTP_REL": "PTP_REL",
    "LIN_REL": "LIN_REL",
    "SPTP_REL": "PTP_REL",
    "SLIN_REL": "LIN_REL",
}
APPROXIMATION = ("C_PTP", "C_DIS", "C_VEL", "C_ORI", "C_SPL")
UNSUPPORTED = (
    "CIRC",
    "CIRC_REL",
    "SCIRC",
    "SPLINE",
    "ENDSPLINE",
    "TRIGGER",
    "GOTO",
    "PULSE",
    "ANIN",
    "ANOUT",
    "ON_ERROR_PROCEED",
    "IMPORT",
)
BLOCK_ENDS = (
    "ELSE",
    "ENDIF",
    "ENDFOR",
    "ENDWHILE",
    "UNTIL",
    "ENDLOOP",
    "CASE",
    "DEFAULT",
    "ENDSWITCH",
    "END",
    "ENDFCT",
    "ENDDAT",
    "DEF",
    "DEFFCT",
    "DEFDAT",
)
#: Interrupt priorities KRL lets a program use.
PRIORITIES = {1, 2, *range(4, 40), *range(81, 129)}


# ------------------------------------------------------------------------------ errors
@dataclass(frozen=True)
class Src:
    """One source line.

    Attributes:
        file: the file's suffix or name, e.g. ``".src"``.
        number: 1-based line number.
        text: the line without its comment.
    """

    file: str
    number: int
    text: str

    def __str__(self) -> str:
        return f"{self.file} line {self.number} ({self.text.strip()!r})"


class KrlError(Exception):
    """A compile or run-time error of a KRL program; the message names the line."""

    def __init__(self, message: str, where: Src | None = None) -> None:
        super().__init__(f"{where}: {message}" if where else message)
        self.message = message
        self.where = where

    def at(self, where: Src) -> KrlError:
        """This error, located at ``where`` unless it already names a line."""
        return self if self.where is not None else KrlError(self.message, where)


class _Exit(Exception):
    def __init__(self, where: Src) -> None:
        self.where = where


class _Return(Exception):
    def __init__(self, value: Any, where: Src) -> None:
        self.value, self.where = value, where


class _Halt(Exception):
    def __init__(self, where: Src) -> None:
        self.where = where


class _Resume(Exception):
    def __init__(self, where: Src) -> None:
        self.where = where


class _Unwind(Exception):
    """RESUME going back to the routine at call depth ``depth``."""

    def __init__(self, depth: int, where: Src) -> None:
        self.depth, self.where = depth, where


# ------------------------------------------------------------------------------ tokens
_TOKEN = re.compile(
    r"\s*(?:(?P<real>(?:\d+\.\d*|\.\d+)(?:[Ee][+-]?\d+)?|\d+[Ee][+-]?\d+)"
    r"|(?P<int>\d+)|(?P<bits>'[BbHh][0-9A-Fa-f]+')|(?P<str>\"[^\"]*\")"
    r"|(?P<enum>#[A-Za-z_]\w*)|(?P<name>\$?[A-Za-z_]\w*)"
    r"|(?P<op>==|<>|<=|>=|[-+*/:<>=()\[\]{},.]))"
)


@dataclass(frozen=True)
class Tok:
    """A token: ``kind`` is real, int, bits, str, enum, name or op."""

    kind: str
    text: str

    @property
    def up(self) -> str:
        """The text in upper case (KRL names are case-insensitive)."""
        return self.text.upper()


def strip_comment(line: str) -> str:
    """``line`` without its ``;`` comment (a ``;`` inside a string is kept)."""
    in_str = False
    for k, ch in enumerate(line):
        if ch == '"':
            in_str = not in_str
        elif ch == ";" and not in_str:
            return line[:k]
    return line


def tokenize(where: Src) -> list[Tok]:
    """The tokens of one line.

    Raises:
        KrlError: a character KRL does not have here.
    """
    out: list[Tok] = []
    text, pos = where.text.rstrip(), 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            raise KrlError(f"cannot read {text[pos:].strip()!r}", where)
        pos = m.end()
        kind = m.lastgroup or ""
        out.append(Tok(kind, m.group(kind)))
    return out


# ------------------------------------------------------------------------------ syntax tree
@dataclass(frozen=True)
class EnumVal:
    """An ENUM value ``#NAME`` (upper case)."""

    name: str


@dataclass(frozen=True)
class Lit:
    """A literal: int, float, bool, str or :class:`EnumVal`."""

    value: Any


@dataclass(frozen=True)
class Name:
    """A variable, signal or system variable (upper case)."""

    name: str


@dataclass(frozen=True)
class Index:
    """``base[i, j]``."""

    base: Expr
    indices: tuple[Expr, ...]


@dataclass(frozen=True)
class Member:
    """``base.name``."""

    base: Expr
    name: str


@dataclass(frozen=True)
class Call:
    """``name(args)``: a function in an expression, a subprogram as a statement."""

    name: str
    args: tuple[Expr, ...]


@dataclass(frozen=True)
class Agg:
    """An aggregate ``{[TYPE:] C1 v1, C2 v2}``."""

    type: str | None
    items: tuple[tuple[str, Expr], ...]


@dataclass(frozen=True)
class Unary:
    """``NOT x``, ``B_NOT x``, ``-x``, ``+x``."""

    op: str
    operand: Expr


@dataclass(frozen=True)
class Binary:
    """``left op right``."""

    op: str
    left: Expr
    right: Expr


Expr = Lit | Name | Index | Member | Call | Agg | Unary | Binary


@dataclass(frozen=True)
class Stmt:
    """A statement and where it is."""

    where: Src


@dataclass(frozen=True)
class DeclItem:
    """One name of a declaration: ``dims`` for an array (``None`` in a dimension: ``a[]``)."""

    name: str
    dims: tuple[int | None, ...] | None
    init: Expr | None


@dataclass(frozen=True)
class Decl(Stmt):
    """``DECL [CONST] type items``."""

    type: str
    items: tuple[DeclItem, ...]
    const: bool


@dataclass(frozen=True)
class SignalDecl(Stmt):
    """``SIGNAL name $IN[n]`` or ``$OUT[n]``."""

    name: str
    io: str
    number: int


@dataclass(frozen=True)
class StrucDecl(Stmt):
    """``STRUC name type c1, c2, type c3``."""

    name: str
    comps: tuple[tuple[str, str], ...]


@dataclass(frozen=True)
class EnumDecl(Stmt):
    """``ENUM name v1, v2``."""

    name: str
    values: tuple[str, ...]


@dataclass(frozen=True)
class Assign(Stmt):
    """``target = value``."""

    target: Expr
    value: Expr


@dataclass(frozen=True)
class CallStmt(Stmt):
    """A subprogram call."""

    call: Call


@dataclass(frozen=True)
class If(Stmt):
    """``IF cond THEN then ELSE other ENDIF``."""

    cond: Expr
    then: tuple[Stmt, ...]
    other: tuple[Stmt, ...]


@dataclass(frozen=True)
class For(Stmt):
    """``FOR var = lo TO hi [STEP step] body ENDFOR``."""

    var: str
    lo: Expr
    hi: Expr
    step: Expr | None
    body: tuple[Stmt, ...]


@dataclass(frozen=True)
class While(Stmt):
    """``WHILE cond body ENDWHILE``."""

    cond: Expr
    body: tuple[Stmt, ...]


@dataclass(frozen=True)
class Repeat(Stmt):
    """``REPEAT body UNTIL cond``."""

    body: tuple[Stmt, ...]
    cond: Expr


@dataclass(frozen=True)
class Loop(Stmt):
    """``LOOP body ENDLOOP``."""

    body: tuple[Stmt, ...]


@dataclass(frozen=True)
class Exit(Stmt):
    """``EXIT``: leaves the innermost loop."""


@dataclass(frozen=True)
class Switch(Stmt):
    """``SWITCH value CASE v1, v2 ... DEFAULT ... ENDSWITCH``."""

    value: Expr
    cases: tuple[tuple[tuple[Expr, ...], tuple[Stmt, ...]], ...]
    default: tuple[Stmt, ...] | None


@dataclass(frozen=True)
class Return(Stmt):
    """``RETURN [value]``."""

    value: Expr | None


@dataclass(frozen=True)
class Halt(Stmt):
    """``HALT``."""


@dataclass(frozen=True)
class WaitSec(Stmt):
    """``WAIT SEC seconds``."""

    seconds: Expr


@dataclass(frozen=True)
class WaitFor(Stmt):
    """``WAIT FOR cond``."""

    cond: Expr


@dataclass(frozen=True)
class Move(Stmt):
    """A motion: ``kind`` PTP, LIN, PTP_REL or LIN_REL; ``rel_frame`` BASE or TOOL."""

    kind: str
    target: Expr
    rel_frame: str


@dataclass(frozen=True)
class IntDecl(Stmt):
    """``[GLOBAL] INTERRUPT DECL prio WHEN cond DO call``."""

    prio: Expr
    cond: Expr
    call: Call
    is_global: bool


@dataclass(frozen=True)
class IntCtl(Stmt):
    """``INTERRUPT ON|OFF|ENABLE|DISABLE [prio]``."""

    action: str
    prio: Expr | None


@dataclass(frozen=True)
class Brake(Stmt):
    """``BRAKE [F]``."""

    fast: bool


@dataclass(frozen=True)
class Resume(Stmt):
    """``RESUME``."""


@dataclass(frozen=True)
class Nop(Stmt):
    """``CONTINUE`` (an advance-run hint: nothing to do here)."""


DECLARATIONS = (Decl, SignalDecl, StrucDecl, EnumDecl)


@dataclass(frozen=True)
class Routine:
    """A ``DEF`` (``returns`` None) or ``DEFFCT``.

    Attributes:
        params: ``(NAME, "IN" | "OUT", is_array)`` in order.
    """

    name: str
    params: tuple[tuple[str, str, bool], ...]
    returns: str | None
    decls: tuple[Stmt, ...]
    body: tuple[Stmt, ...]
    where: Src


# ------------------------------------------------------------------------------ parsing
_LEVELS: tuple[tuple[str, ...], ...] = (
    ("==", "<>", "<", ">", "<=", ">="),
    ("OR", "B_OR"),
    ("EXOR", "B_EXOR"),
    ("AND", "B_AND"),
    ("+", "-"),
    ("*", "/"),
)


class _Parser:
    """Expressions and statements of one line's tokens."""

    def __init__(self, where: Src, toks: list[Tok] | None = None) -> None:
        self.where = where
        self.t = tokenize(where) if toks is None else toks
        self.i = 0

    def error(self, message: str) -> KrlError:
        return KrlError(message, self.where)

    def peek(self, k: int = 0) -> Tok | None:
        j = self.i + k
        return self.t[j] if j < len(self.t) else None

    def peek_up(self, k: int = 0) -> str:
        tok = self.peek(k)
        return tok.up if tok is not None and tok.kind in ("name", "op") else ""

    def take(self) -> Tok:
        if self.i >= len(self.t):
            raise self.error("the line ends too early")
        self.i += 1
        return self.t[self.i - 1]

    def expect(self, text: str) -> Tok:
        tok = self.take()
        if tok.up != text:
            raise self.error(f"expected {text!r}, got {tok.text!r}")
        return tok

    def name(self) -> str:
        tok = self.take()
        if tok.kind != "name":
            raise self.error(f"expected a name, got {tok.text!r}")
        return tok.up

    def done(self) -> bool:
        return self.i >= len(self.t)

    def end(self) -> None:
        if not self.done():
            raise self.error(f"unexpected {self.t[self.i].text!r}")

    # -- expressions
    def expr(self) -> Expr:
        return self._binary(0)

    def _binary(self, level: int) -> Expr:
        if level == len(_LEVELS):
            return self._unary()
        left = self._binary(level + 1)
        while self.peek_up() in _LEVELS[level]:
            op = self.take().up
            left = Binary(op, left, self._binary(level + 1))
        return left

    def _unary(self) -> Expr:
        if self.peek_up() in ("NOT", "B_NOT", "-", "+"):
            op = self.take().up
            return Unary(op, self._unary())
        left = self.postfix()
        while self.peek_up() == ":":
            self.take()
            left = Binary(":", left, self.postfix())
        return left

    def postfix(self) -> Expr:
        e = self._primary()
        while self.peek_up() in ("[", "."):
            if self.take().text == "[":
                e = Index(e, tuple(self._list("]")))
            else:
                e = Member(e, self.name())
        return e

    def _list(self, close: str) -> list[Expr]:
        items: list[Expr] = []
        if self.peek_up() == close:
            self.take()
            return items
        while True:
            items.append(self.expr())
            if self.take().text == close:
                return items
            if self.t[self.i - 1].text != ",":
                raise self.error(f"expected ',' or {close!r}")

    def _primary(self) -> Expr:
        tok = self.take()
        if tok.kind == "int":
            return Lit(int(tok.text))
        if tok.kind == "real":
            return Lit(float(tok.text))
        if tok.kind == "bits":
            return Lit(int(tok.text[2:-1], 2 if tok.text[1] in "Bb" else 16))
        if tok.kind == "str":
            return Lit(tok.text[1:-1])
        if tok.kind == "enum":
            return Lit(EnumVal(tok.up[1:]))
        if tok.text == "(":
            e = self.expr()
            self.expect(")")
            return e
        if tok.text == "{":
            return self._aggregate()
        if tok.kind == "name":
            if tok.up in ("TRUE", "FALSE"):
                return Lit(tok.up == "TRUE")
            if self.peek_up() == "(":
                self.take()
                return Call(tok.up, tuple(self._list(")")))
            return Name(tok.up)
        raise self.error(f"unexpected {tok.text!r}")

    def _aggregate(self) -> Agg:
        typ = None
        if self.peek_up(1) == ":":
            typ = self.name()
            self.take()
        items: list[tuple[str, Expr]] = []
        while True:
            comp = self.name()
            items.append((comp, self.expr()))
            sep = self.take().text
            if sep == "}":
                return Agg(typ, tuple(items))
            if sep != ",":
                raise self.error(f"expected ',' or '}}' in an aggregate, got {sep!r}")


def _head(toks: list[Tok]) -> str:
    return toks[0].up if toks and toks[0].kind == "name" else ""


def _is_declaration(toks: list[Tok]) -> bool:
    """Whether a line declares (``DECL``, ``SIGNAL``, ``STRUC``, ``ENUM``, ``INT i``)."""
    k = 1 if toks and toks[0].up == "GLOBAL" else 0
    if len(toks) <= k or toks[k].kind != "name":
        return False
    if toks[k].up in ("DECL", "SIGNAL", "STRUC", "ENUM"):
        return True
    # DECL left out before a simple type: "INT i, j"
    return toks[k].up in SIMPLE and len(toks) > k + 1 and toks[k + 1].kind == "name"


def _check_name(name: str, where: Src) -> str:
    if len(name) > MAX_NAME:
        raise KrlError(f"name {name} has {len(name)} characters, KRL allows {MAX_NAME}", where)
    return name


def parse_declaration(where: Src, toks: list[Tok]) -> Stmt:
    """A ``DECL``/``SIGNAL``/``STRUC``/``ENUM`` line."""
    p = _Parser(where, toks)
    if p.peek_up() == "GLOBAL":
        p.take()
    head = p.name()
    if head == "SIGNAL":
        name = _check_name(p.name(), where)
        io = p.name()
        if io not in ("$IN", "$OUT"):
            raise p.error(f"SIGNAL to {io}: only $IN and $OUT are supported")
        p.expect("[")
        number = p.take()
        p.expect("]")
        if number.kind != "int":
            raise p.error("SIGNAL needs a constant input number")
        if p.peek_up() == "TO":
            raise p.error("group signals (SIGNAL ... TO ...) are not supported")
        p.end()
        return SignalDecl(where, name, io, int(number.text))
    if head == "STRUC":
        return _struc(p)
    if head == "ENUM":
        name = _check_name(p.name(), where)
        values = [p.name()]
        while not p.done():
            p.expect(",")
            values.append(p.name())
        return EnumDecl(where, name, tuple(values))
    if head == "DECL":
        if p.peek_up() == "GLOBAL":
            p.take()
        head = p.name()
    const = head == "CONST"
    typ = p.name() if const else head
    items = [_decl_item(p)]
    while not p.done():
        p.expect(",")
        items.append(_decl_item(p))
    return Decl(where, typ, tuple(items), const)


def _decl_item(p: _Parser) -> DeclItem:
    name = _check_name(p.name(), p.where)
    dims: tuple[int | None, ...] | None = None
    if p.peek_up() == "[":
        p.take()
        sizes: list[int | None] = []
        while True:
            tok = p.take()
            if tok.text in ("]", ","):
                sizes.append(None)
            else:
                if tok.kind != "int":
                    raise p.error(f"array size must be an integer literal, got {tok.text!r}")
                sizes.append(int(tok.text))
                tok = p.take()
            if tok.text == "]":
                break
            if tok.text != ",":
                raise p.error(f"expected ',' or ']', got {tok.text!r}")
        dims = tuple(sizes)
    init = None
    if p.peek_up() == "=":
        p.take()
        init = p.expr()
    return DeclItem(name, dims, init)


def _struc(p: _Parser) -> StrucDecl:
    name = _check_name(p.name(), p.where)
    comps: list[tuple[str, str]] = []
    typ = None
    while not p.done():
        word = p.name()
        if p.peek() is not None and p.peek_up() not in (",", ""):
            typ, word = word, p.name()
        if typ is None:
            raise p.error("STRUC component without a type")
        comps.append((word, typ))
        if not p.done():
            p.expect(",")
    return StrucDecl(p.where, name, tuple(comps))


class _Lines:
    """Statement blocks of a routine's lines."""

    def __init__(self, lines: list[Src]) -> None:
        self.lines, self.i = lines, 0

    def block(self, stops: tuple[str, ...]) -> tuple[tuple[Stmt, ...], str, Src, list[Tok]]:
        """Statements up to (and consuming) a line starting with a word of ``stops``."""
        body: list[Stmt] = []
        while self.i < len(self.lines):
            where = self.lines[self.i]
            toks = tokenize(where)
            self.i += 1
            word = _head(toks)
            if word in stops:
                return tuple(body), word, where, toks
            body.append(self.statement(where, toks, word))
        last = self.lines[-1] if self.lines else Src("?", 0, "")
        raise KrlError(f"missing {' or '.join(stops)}", last)

    def statement(self, where: Src, toks: list[Tok], word: str) -> Stmt:
        """One statement (and, for IF/FOR/..., its blocks)."""
        if _is_declaration(toks):
            raise KrlError("declaration after the first statement (KRL declares first)", where)
        if word in BLOCK_ENDS:
            raise KrlError(f"{word} without the statement it ends", where)
        if word in UNSUPPORTED:
            raise KrlError(f"{word} is not supported by this interpreter", where)
        handler = _STATEMENTS.get(word)
        if handler is not None:
            return handler(self, _Parser(where, toks[1:]), where)
        if word == "GLOBAL" and len(toks) > 1 and toks[1].up == "INTERRUPT":
            return self._interrupt(_Parser(where, toks[2:]), where, is_global=True)
        if word in MOTIONS:
            return _move(_Parser(where, toks[1:]), where, MOTIONS[word])
        return _simple_statement(_Parser(where, toks))

    def _if(self, p: _Parser, where: Src) -> Stmt:
        if not p.t or p.t[-1].up != "THEN":
            raise KrlError("IF without THEN at the end of the line", where)
        p.t = p.t[:-1]
        cond = p.expr()
        p.end()
        then, stop, _, _ = self.block(("ELSE", "ENDIF"))
        other: tuple[Stmt, ...] = ()
        if stop == "ELSE":
            other, _, _, _ = self.block(("ENDIF",))
        return If(where, cond, then, other)

    def _for(self, p: _Parser, where: Src) -> Stmt:
        var = p.name()
        p.expect("=")
        lo = p.expr()
        p.expect("TO")
        hi = p.expr()
        step = None
        if p.peek_up() == "STEP":
            p.take()
            step = p.expr()
        p.end()
        body, _, _, _ = self.block(("ENDFOR",))
        return For(where, var, lo, hi, step, body)

    def _while(self, p: _Parser, where: Src) -> Stmt:
        cond = p.expr()
        p.end()
        body, _, _, _ = self.block(("ENDWHILE",))
        return While(where, cond, body)

    def _repeat(self, p: _Parser, where: Src) -> Stmt:
        p.end()
        body, _, until, toks = self.block(("UNTIL",))
        q = _Parser(until, toks[1:])
        cond = q.expr()
        q.end()
        return Repeat(where, body, cond)

    def _loop(self, p: _Parser, where: Src) -> Stmt:
        p.end()
        body, _, _, _ = self.block(("ENDLOOP",))
        return Loop(where, body)

    def _switch(self, p: _Parser, where: Src) -> Stmt:
        value = p.expr()
        p.end()
        stops = ("CASE", "DEFAULT", "ENDSWITCH")
        pre, stop, at, toks = self.block(stops)
        if pre:
            raise KrlError("statements between SWITCH and its first CASE", where)
        cases: list[tuple[tuple[Expr, ...], tuple[Stmt, ...]]] = []
        default: tuple[Stmt, ...] | None = None
        while stop != "ENDSWITCH":
            head = _Parser(at, toks[1:])
            values = [head.expr()] if stop == "CASE" else []
            while stop == "CASE" and not head.done():
                head.expect(",")
                values.append(head.expr())
            head.end()
            body, next_stop, next_at, next_toks = self.block(stops)
            if stop == "CASE":
                cases.append((tuple(values), body))
            elif default is not None:
                raise KrlError("a second DEFAULT", at)
            else:
                default = body
            stop, at, toks = next_stop, next_at, next_toks
        return Switch(where, value, tuple(cases), default)

    def _interrupt(self, p: _Parser, where: Src, is_global: bool = False) -> Stmt:
        action = p.name()
        if action == "DECL":
            prio = p.expr()
            p.expect("WHEN")
            cond = p.expr()
            p.expect("DO")
            call = p.postfix()
            p.end()
            if not isinstance(call, Call):
                raise KrlError("INTERRUPT DECL ... DO needs a subprogram call", where)
            return IntDecl(where, prio, cond, call, is_global)
        if is_global or action not in ("ON", "OFF", "ENABLE", "DISABLE"):
            raise KrlError(f"INTERRUPT {action}: expected DECL, ON, OFF, ENABLE or DISABLE", where)
        which = None if p.done() else p.expr()
        p.end()
        return IntCtl(where, action, which)


def _no_args(kind: type[Stmt]) -> Callable[[_Lines, _Parser, Src], Stmt]:
    def parse(_lines: _Lines, p: _Parser, where: Src) -> Stmt:
        p.end()
        return kind(where)

    return parse


def _return(_lines: _Lines, p: _Parser, where: Src) -> Stmt:
    value = None if p.done() else p.expr()
    p.end()
    return Return(where, value)


def _wait(_lines: _Lines, p: _Parser, where: Src) -> Stmt:
    how = p.name()
    value = p.expr()
    p.end()
    if how == "SEC":
        return WaitSec(where, value)
    if how == "FOR":
        return WaitFor(where, value)
    raise KrlError(f"WAIT {how}: expected SEC or FOR", where)


def _brake(_lines: _Lines, p: _Parser, where: Src) -> Stmt:
    fast = not p.done() and p.name() == "F"
    p.end()
    return Brake(where, fast)


def _move(p: _Parser, where: Src, kind: str) -> Stmt:
    target = p.expr()
    rel_frame = "BASE"
    if p.peek_up() in APPROXIMATION:
        p.take()
    if not p.done() and kind.endswith("_REL"):
        tok = p.take()
        if tok.kind != "enum" or tok.up not in ("#BASE", "#TOOL"):
            raise KrlError(f"{kind}: expected #BASE or #TOOL, got {tok.text!r}", where)
        rel_frame = tok.up[1:]
    p.end()
    return Move(where, kind, target, rel_frame)


def _simple_statement(p: _Parser) -> Stmt:
    """An assignment or a subprogram call; anything else is an unknown statement."""
    try:
        target = p.postfix()
    except KrlError:
        target = None
    if target is not None and p.peek_up() == "=":
        p.take()
        value = p.expr()
        p.end()
        if not isinstance(target, Name | Index | Member):
            raise p.error("the left side of an assignment must be a variable")
        return Assign(p.where, target, value)
    if isinstance(target, Call) and p.done():
        return CallStmt(p.where, target)
    raise p.error("unknown statement")


_STATEMENTS: dict[str, Callable[[_Lines, _Parser, Src], Stmt]] = {
    "IF": _Lines._if,
    "FOR": _Lines._for,
    "WHILE": _Lines._while,
    "REPEAT": _Lines._repeat,
    "LOOP": _Lines._loop,
    "SWITCH": _Lines._switch,
    "INTERRUPT": _Lines._interrupt,
    "EXIT": _no_args(Exit),
    "HALT": _no_args(Halt),
    "RESUME": _no_args(Resume),
    "CONTINUE": _no_args(Nop),
    "RETURN": _return,
    "WAIT": _wait,
    "BRAKE": _brake,
}


def _source_lines(text: str, file: str) -> list[Src]:
    """The non-empty lines of a file without comments and ``&`` header lines."""
    out = []
    for k, raw in enumerate(text.splitlines(), start=1):
        code = strip_comment(raw)
        if code.strip() and not code.lstrip().startswith("&"):
            out.append(Src(file, k, code))
    return out


def _routine_header(where: Src, toks: list[Tok]) -> tuple[str, str | None, list[Tok]]:
    """``(name, return type or None, parameter tokens)`` of a ``DEF``/``DEFFCT`` line."""
    p = _Parser(where, toks)
    if p.peek_up() == "GLOBAL":
        p.take()
    kind = p.name()
    returns = p.name() if kind == "DEFFCT" else None
    name = _check_name(p.name(), where)
    p.expect("(")
    params = p.t[p.i : -1]
    if not p.t or p.t[-1].text != ")":
        raise KrlError(f"{kind} {name}: the parameter list must end the line with ')'", where)
    return name, returns, params


def _parameters(where: Src, toks: list[Tok]) -> tuple[tuple[str, str, bool], ...]:
    p = _Parser(where, toks)
    out: list[tuple[str, str, bool]] = []
    while not p.done():
        name = _check_name(p.name(), where)
        is_array = False
        if p.peek_up() == "[":
            p.take()
            p.expect("]")
            is_array = True
        mode = "OUT"
        if p.peek_up() == ":":
            p.take()
            mode = p.name()
            if mode not in ("IN", "OUT"):
                raise p.error(f"parameter {name}: expected :IN or :OUT, got :{mode}")
        out.append((name, mode, is_array))
        if not p.done():
            p.expect(",")
    if len({n for n, _, _ in out}) != len(out):
        raise KrlError("a parameter name appears twice", where)
    return tuple(out)


def parse_src(text: str, file: str = ".src") -> dict[str, Routine]:
    """The routines of a ``.src`` file, in order (the first is the main program).

    Raises:
        KrlError: anything but ``DEF``/``DEFFCT`` blocks at the top level, or a bad line.
    """
    lines = _Lines(_source_lines(text, file))
    routines: dict[str, Routine] = {}
    while lines.i < len(lines.lines):
        where = lines.lines[lines.i]
        toks = tokenize(where)
        lines.i += 1
        words = [t.up for t in toks[:2]]
        kind = words[1] if words[0] == "GLOBAL" and len(words) > 1 else words[0]
        if kind not in ("DEF", "DEFFCT"):
            raise KrlError("expected DEF or DEFFCT at the top level of the .src", where)
        name, returns, param_toks = _routine_header(where, toks)
        decls: list[Stmt] = []
        while lines.i < len(lines.lines):
            t = tokenize(lines.lines[lines.i])
            if not _is_declaration(t):
                break
            decls.append(parse_declaration(lines.lines[lines.i], t))
            lines.i += 1
        body, _, _, _ = lines.block(("ENDFCT",) if returns else ("END",))
        if name in routines:
            raise KrlError(f"routine {name} defined twice", where)
        params = _parameters(where, param_toks)
        routines[name] = Routine(name, params, returns, tuple(decls), body, where)
    if not routines:
        raise KrlError(f"{file}: no DEF")
    return routines


def parse_dat(text: str, file: str = ".dat") -> tuple[str, list[Stmt]]:
    """``(DEFDAT name, declarations and element assignments)`` of a ``.dat`` file.

    Raises:
        KrlError: a line that is not a declaration or a constant element assignment, or a
            value that is not constant.
    """
    lines = _source_lines(text, file)
    if not lines:
        raise KrlError(f"{file}: empty data list")
    head = _Parser(lines[0])
    head.expect("DEFDAT")
    name = _check_name(head.name(), lines[0])
    if head.peek_up() == "PUBLIC":
        head.take()
    head.end()
    if _head(tokenize(lines[-1])) != "ENDDAT" or len(tokenize(lines[-1])) != 1:
        raise KrlError("the data list must end with ENDDAT", lines[-1])
    out: list[Stmt] = []
    for where in lines[1:-1]:
        toks = tokenize(where)
        stmt = parse_declaration(where, toks) if _is_declaration(toks) else None
        if stmt is None:
            stmt = _simple_statement(_Parser(where, toks))
            if not (isinstance(stmt, Assign) and isinstance(stmt.target, Index)):
                raise KrlError("a data list holds only declarations", where)
        for value in _initial_values(stmt):
            if not _is_constant(value):
                raise KrlError("a data list value must be a constant", where)
        out.append(stmt)
    return name, out


def _initial_values(stmt: Stmt) -> list[Expr]:
    if isinstance(stmt, Decl):
        return [d.init for d in stmt.items if d.init is not None]
    if isinstance(stmt, Assign):
        return [stmt.value]
    return []


def _is_constant(e: Expr) -> bool:
    if isinstance(e, Lit):
        return True
    if isinstance(e, Unary):
        return e.op in ("-", "+") and isinstance(e.operand, Lit)
    if isinstance(e, Agg):
        return all(_is_constant(v) for _, v in e.items)
    return False


# ------------------------------------------------------------------------------ values
@dataclass
class Struct:
    """A structure value: its type and its components (``None``: invalid)."""

    type: str
    f: dict[str, Any]


@dataclass(frozen=True)
class AggValue:
    """An evaluated aggregate, not yet given a type."""

    type: str | None
    items: tuple[tuple[str, Any], ...]


@dataclass
class Array:
    """An array value, row-major, indices from 1 (``None`` elements: invalid)."""

    type: str
    dims: tuple[int, ...]
    data: list[Any]

    def offset(self, idx: Sequence[Any]) -> int:
        """The position of element ``idx`` in :attr:`data`.

        Raises:
            KrlError: wrong number of indices, an index that is not INT, or out of range.
        """
        if len(idx) != len(self.dims):
            raise KrlError(f"{len(idx)} indices for an array of {len(self.dims)} dimensions")
        k = 0
        for i, n in zip(idx, self.dims):
            if isinstance(i, bool) or not isinstance(i, int):
                raise KrlError(f"array index must be INT, got {i!r}")
            if not 1 <= i <= n:
                raise KrlError(f"array index {i} out of range 1..{n}")
            k = k * n + (i - 1)
        return k


def frame_values(T: np.ndarray) -> dict[str, float]:
    """``{X, Y, Z, A, B, C}`` of a transform (units of its translation, degrees)."""
    abc = np.degrees(tait_bryan_zyx_from_matrix(T[:3, :3]))
    return dict(zip("XYZABC", (*map(float, T[:3, 3]), *map(float, abc))))


def frame_matrix(values: Mapping[str, Any], what: str = "frame") -> np.ndarray:
    """``(4, 4)`` of ``{X, Y, Z, A, B, C}`` (translation unchanged, angles in degrees).

    Raises:
        KrlError: a component is invalid.
    """
    missing = [c for c in "XYZABC" if values.get(c) is None]
    if missing:
        raise KrlError(f"{what}: component(s) {', '.join(missing)} invalid")
    a, b, c = (math.radians(values[k]) for k in "ABC")
    p = [values[k] for k in "XYZ"]
    return make_transform(matrix_from_tait_bryan_zyx(a, b, c), p)


def to_metres(T_mm: np.ndarray) -> np.ndarray:
    """A copy of a transform with its translation in metres instead of millimetres."""
    T = np.array(T_mm, dtype=float)
    T[:3, 3] /= 1000.0
    return T


def f32(x: float) -> float:
    """``x`` rounded to the nearest IEEE 754 single (a KRL REAL on the controller)."""
    return float(np.float32(x))


def round_real(value: Any) -> Any:
    """``value`` with every REAL in it (a float, the float components of a structure, nested)
    rounded to single precision; structures are rounded in place."""
    if isinstance(value, float):
        return f32(value)
    if isinstance(value, Struct):
        for k, v in value.f.items():
            value.f[k] = round_real(v)
    return value


def _family(typ: str) -> set[str] | None:
    return next((f for f in FAMILIES if typ in f), None)


def _round_int(v: float) -> int:
    """KRL's REAL to INT: rounded, halves away from zero."""
    return math.floor(abs(v) + 0.5) * (1 if v >= 0 else -1)


def _is_num(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def _kind(v: Any) -> str:
    if isinstance(v, bool):
        return "BOOL"
    if isinstance(v, int):
        return "INT"
    if isinstance(v, float):
        return "REAL"
    if isinstance(v, str):
        return "CHAR"
    if isinstance(v, EnumVal):
        return f"#{v.name}"
    if isinstance(v, Struct):
        return v.type
    if isinstance(v, AggValue):
        return "aggregate"
    if isinstance(v, Array):
        return f"{v.type} array"
    return type(v).__name__


def _arith(op: str, a: Any, b: Any) -> Any:
    if not (_is_num(a) and _is_num(b)):
        raise KrlError(f"no operator {op} for {_kind(a)} and {_kind(b)}")
    if op == "+":
        return a + b
    if op == "-":
        return a - b
    if op == "*":
        return a * b
    if b == 0:
        raise KrlError("division by zero")
    if isinstance(a, int) and isinstance(b, int):
        return int(a / b)  # INT / INT truncates towards zero
    return a / b


def _compare(op: str, a: Any, b: Any) -> bool:
    if op in ("==", "<>"):
        same_kind = (_is_num(a) and _is_num(b)) or (
            type(a) is type(b) and isinstance(a, bool | str | EnumVal)
        )
        if not same_kind:
            raise KrlError(f"cannot compare {_kind(a)} with {_kind(b)}")
        return (a == b) if op == "==" else (a != b)
    if not (_is_num(a) and _is_num(b)):
        raise KrlError(f"no operator {op} for {_kind(a)} and {_kind(b)}")
    return {"<": a < b, ">": a > b, "<=": a <= b, ">=": a >= b}[op]


def _logic(op: str, a: Any, b: Any) -> Any:
    if op in ("AND", "OR", "EXOR"):
        if not (isinstance(a, bool) and isinstance(b, bool)):
            raise KrlError(f"{op} needs BOOL operands, got {_kind(a)} and {_kind(b)}")
        return {"AND": a and b, "OR": a or b, "EXOR": a != b}[op]
    if not all(isinstance(v, int) and not isinstance(v, bool) for v in (a, b)):
        raise KrlError(f"{op} needs INT operands, got {_kind(a)} and {_kind(b)}")
    return {"B_AND": a & b, "B_OR": a | b, "B_EXOR": a ^ b}[op]


def _deg_fn(fn: Callable[[float], float]) -> Callable[[Any], float]:
    def f(x: Any) -> float:
        if not _is_num(x):
            raise KrlError(f"numeric argument expected, got {_kind(x)}")
        return fn(float(x))

    return f


def _atan2(y: Any, x: Any) -> float:
    if not (_is_num(y) and _is_num(x)):
        raise KrlError("ATAN2 needs numeric arguments")
    if y == 0 and x == 0:
        raise KrlError("ATAN2(0, 0) is undefined")
    return math.degrees(math.atan2(y, x))


def _sqrt(x: float) -> float:
    if x < 0:
        raise KrlError(f"SQRT of a negative number ({x})")
    return math.sqrt(x)


def _acos(x: float) -> float:
    if not -1.0 <= x <= 1.0:
        raise KrlError(f"ACOS of {x}, outside [-1, 1]")
    return math.degrees(math.acos(x))


def _abs(x: Any) -> Any:
    if not _is_num(x):
        raise KrlError(f"ABS needs a number, got {_kind(x)}")
    return abs(x)


#: Built-in functions of numbers (angles in degrees); INV_POS is a method of the machine.
FUNCTIONS: dict[str, Callable[..., Any]] = {
    "ABS": _abs,
    "SQRT": _deg_fn(_sqrt),
    "SIN": _deg_fn(lambda a: math.sin(math.radians(a))),
    "COS": _deg_fn(lambda a: math.cos(math.radians(a))),
    "TAN": _deg_fn(lambda a: math.tan(math.radians(a))),
    "ACOS": _deg_fn(_acos),
    "ATAN2": _atan2,
}


# ------------------------------------------------------------------------------ variables
@dataclass
class Slot:
    """A variable.

    Attributes:
        name: its name (upper case).
        type: its type, or ``None`` for an :OUT parameter until its DECL names it.
        value: its value (``Struct``, ``Array``, a scalar, or ``None``: invalid).
        dims: array dimensions, or ``None``.
        writable: whether a program may assign it.
        getter: computes the value instead of :attr:`value` (``$POS_ACT``, signals, references).
        setter: stores the value instead of :attr:`value`.
        signal: ``("$IN" | "$OUT", n)`` for a signal.
        ref_type: for an :OUT parameter, the type of what the caller passed.
    """

    name: str
    type: str | None
    value: Any = None
    dims: tuple[int, ...] | None = None
    writable: bool = True
    getter: Callable[[], Any] | None = None
    setter: Callable[[Any], None] | None = None
    signal: tuple[str, int] | None = None
    ref_type: str | None = None

    def get(self) -> Any:
        """The stored value (``None``: invalid)."""
        return self.getter() if self.getter is not None else self.value

    def put(self, value: Any) -> None:
        """Store ``value`` (already of the slot's type).

        Raises:
            KrlError: the variable is write-protected.
        """
        if not self.writable:
            raise KrlError(f"{self.name} is write-protected")
        if self.setter is not None:
            self.setter(value)
        else:
            self.value = value


@dataclass
class Place:
    """Where an assignment or an :OUT parameter stores: a variable, an element or a component."""

    what: str
    type: str
    dims: tuple[int, ...] | None
    get: Callable[[], Any]
    set: Callable[[Any], None]
    writable: bool = True


@dataclass
class _Frame:
    routine: Routine
    scope: dict[str, Slot]
    depth: int


@dataclass
class _Interrupt:
    prio: int
    decl: IntDecl
    depth: int | None
    reads_sensor: bool
    on: bool = False
    enabled: bool = True
    last: bool = False


@dataclass(eq=False)
class Motion:
    """One executed motion statement (robot base frame, metres).

    Attributes:
        kind: ``"PTP"``, ``"LIN"``, ``"PTP_REL"`` or ``"LIN_REL"``.
        where: the statement.
        start_m: ``(4, 4)`` TCP pose before it, or ``None`` when unknown (after an axis PTP).
        target_m: ``(4, 4)`` commanded TCP pose, or ``None`` for an axis target.
        end_m: ``(4, 4)`` where the TCP stopped (an interrupt may end it early), or ``None``.
        axes_deg: the axis values of an axis-specific PTP, degrees, else ``None``.
        base_m: ``(4, 4)`` ``$BASE`` during the motion.
        tool_m: ``(4, 4)`` ``$TOOL`` during the motion (flange to TCP).
        events: the search callback's answers during it: ``(3,)`` points (m) or strings.
        interrupts: priorities of the interrupts that fired during it.
    """

    kind: str
    where: Src
    start_m: np.ndarray | None
    target_m: np.ndarray | None
    base_m: np.ndarray
    tool_m: np.ndarray
    end_m: np.ndarray | None = None
    axes_deg: tuple[float, ...] | None = None
    events: list[np.ndarray | str] = field(default_factory=list)
    interrupts: list[int] = field(default_factory=list)

    @property
    def is_search(self) -> bool:
        """Whether the search callback was asked during this motion."""
        return bool(self.events)

    @property
    def flange_end_m(self) -> np.ndarray | None:
        """``(4, 4)`` the flange where the motion ended (``end_m @ inv(tool_m)``)."""
        return None if self.end_m is None else self.end_m @ invert_transform(self.tool_m)


@dataclass(frozen=True)
class SearchCall:
    """One call of the search callback (robot base, metres) and its answer."""

    start_m: np.ndarray
    end_m: np.ndarray
    sensor_axis: np.ndarray
    neg_flank: bool
    result: np.ndarray | str


# ------------------------------------------------------------------------------ the machine
class KrlMachine:
    """Runs a KRL module (``{".src": text, ".dat": text}``) against a simulated robot.

    Args:
        files: the module's files; ``".dat"`` is optional.
        search: the sensor search callback (module docstring), robot base, metres.
        sensor: ``sensor(tcp_m, sensor_axis) -> bool``, the input after an ordinary motion
            (robot base, metres); ``None``: FALSE after every motion that moved.
        sensor_input: the number of the input the sensor drives (``$IN[n]``).
        start_tcp_m: ``(4, 4)`` the TCP pose at the start, robot base, metres (``None``:
            unknown until the first Cartesian motion).
        real_float32: round every REAL to single precision, as the controller stores it
            (module docstring); ``False``: float64.

    Raises:
        KrlError: the module does not compile (the message names the line).
    """

    def __init__(
        self,
        files: Mapping[str, str],
        search: SearchFn,
        *,
        sensor: SensorFn | None = None,
        sensor_input: int = 1,
        start_tcp_m: np.ndarray | None = None,
        real_float32: bool = False,
    ) -> None:
        if ".src" not in files:
            raise KrlError(f"no .src among {sorted(files)}")
        self.routines = parse_src(files[".src"])
        self.main = next(iter(self.routines.values()))
        self.search = search
        self.sensor = sensor
        self.real_float32 = real_float32
        self.sensor_input = sensor_input
        self.structs: dict[str, tuple[tuple[str, str], ...]] = dict(STRUCTS)
        self.enums: dict[str, tuple[str, ...]] = {}
        self.inputs: list[bool] = [False] * N_IO
        self.outputs: list[bool] = [False] * N_IO
        self.system: dict[str, Slot] = {}
        self.data: dict[str, Slot] = {}
        self.motions: list[Motion] = []
        self.search_calls: list[SearchCall] = []
        self.halted: Src | None = None
        self.finished = False
        self._tcp: np.ndarray | None = None if start_tcp_m is None else _mm(start_tcp_m)
        self._axes: Struct | None = None
        self._st: tuple[Any, Any] = (None, None)
        self._stack: list[_Frame] = []
        self._interrupts: dict[int, _Interrupt] = {}
        self._isr: list[_Interrupt] = []
        self._steps = 0
        self._init_system()
        if ".dat" in files:
            self._load_dat(files[".dat"])

    # -- public API
    def run(self) -> KrlMachine:
        """Run the main program (the first DEF) to its end, a HALT or an error.

        Raises:
            KrlError: a run-time error (the message names the line).
        """
        if self.main.returns is not None or self.main.params:
            raise KrlError(f"main program {self.main.name} must be a DEF without parameters")
        try:
            self._call(self.main, [])
        except _Halt as h:
            self.halted = h.where
        self.finished = True
        return self

    def call(self, name: str, *args: Any) -> Any:
        """Call the module's routine ``name`` (a ``DEF`` or ``DEFFCT``) as a statement of the
        main program would, with ``args`` the values of its ``:IN`` parameters (INT, REAL,
        BOOL, CHAR or a :class:`Struct`, converted to each parameter's declared type as KRL
        converts them), on the data list and the robot as they are now (after :meth:`run`: as
        the program left them). Returns a function's value (``None`` for a ``DEF``).

        Raises:
            KrlError: no such routine, a wrong number of arguments, an ``:OUT`` parameter (it
                needs a variable of the caller), or a run-time error.
        """
        r = self.routines.get(name.upper())
        if r is None:
            raise KrlError(f"unknown routine {name}")
        if len(args) != len(r.params):
            raise KrlError(f"{r.name} takes {len(r.params)} arguments, got {len(args)}")
        out = [p for p, mode, _ in r.params if mode == "OUT"]
        if out:
            raise KrlError(f"{r.name}: :OUT parameter(s) {', '.join(out)} need a variable")
        try:
            return self._call(r, [copy.deepcopy(a) for a in args])
        except _Halt as h:
            self.halted = h.where
            return None

    def set_input(self, number: int, value: bool) -> None:
        """Set ``$IN[number]`` (as the cell would)."""
        self.inputs[number - 1] = bool(value)

    def value(self, name: str) -> Any:
        """A copy of the value of a data-list or system variable (``Struct``, ``Array`` or a
        scalar; ``None``: invalid)."""
        return copy.deepcopy(self._lookup(name.upper(), None).get())

    def frame_m(self, value: str | Struct) -> np.ndarray:
        """``(4, 4)`` a FRAME/POS/E6POS (or the variable named so), translation in metres.

        Raises:
            KrlError: not a Cartesian value, or a component is invalid.
        """
        v = self.value(value) if isinstance(value, str) else value
        if not (isinstance(v, Struct) and _family(v.type) is FAMILIES[0]):
            raise KrlError(f"{_kind(v)} is not a frame")
        return to_metres(frame_matrix(v.f))

    def base_m(self) -> np.ndarray:
        """``(4, 4)`` the current ``$BASE`` (robot base frame), metres."""
        return self.frame_m("$BASE")

    def tool_m(self) -> np.ndarray:
        """``(4, 4)`` the current ``$TOOL`` (flange frame), metres."""
        return self.frame_m("$TOOL")

    def tcp_m(self) -> np.ndarray | None:
        """``(4, 4)`` the TCP pose now, robot base, metres (``None``: unknown)."""
        return None if self._tcp is None else to_metres(self._tcp)

    def frames_m(self, name: str = "xMeas") -> dict[int, np.ndarray]:
        """``{i: (4, 4)}`` the valid elements of a 1-D FRAME/POS/E6POS array, metres.

        An element counts when its X, Y, Z, A, B, C are all valid; others are left out.
        """
        arr = self.value(name)
        if not isinstance(arr, Array) or len(arr.dims) != 1:
            raise KrlError(f"{name} is not a 1-D array")
        out = {}
        for i, v in enumerate(arr.data, start=1):
            if isinstance(v, Struct) and all(v.f.get(c) is not None for c in "XYZABC"):
                out[i] = to_metres(frame_matrix(v.f))
        return out

    def measured_m(self, name: str = "xMeas") -> dict[int, np.ndarray]:
        """``{i: (3,)}`` the positions the program recorded in ``name`` (what the KRL writer
        records: ``xMeas[i]``, the point in the robot base), metres; unset elements left out."""
        return {i: T[:3, 3] for i, T in self.frames_m(name).items()}

    def ints(self, name: str = "nFail") -> dict[int, int | None]:
        """``{i: value}`` of a 1-D INT array (``None``: never assigned)."""
        arr = self.value(name)
        if not isinstance(arr, Array) or arr.type != "INT":
            raise KrlError(f"{name} is not an INT array")
        return dict(enumerate(arr.data, start=1))

    @property
    def searches(self) -> list[Motion]:
        """The motions during which the search callback was asked."""
        return [m for m in self.motions if m.is_search]

    # -- set-up
    def _init_system(self) -> None:
        zero = self._struct_of("FRAME", dict.fromkeys("XYZABC", 0.0))
        load = self._struct_of("LOAD", {"M": -1.0, "CM": dict.fromkeys("XYZABC", 0.0)})
        load.f["J"] = self._struct_of("INERTIA", dict.fromkeys("XYZ", 0.0))
        sys: list[Slot] = [
            Slot("$BASE", "FRAME", copy.deepcopy(zero)),
            Slot("$TOOL", "FRAME", copy.deepcopy(zero)),
            Slot("$LOAD", "LOAD", copy.deepcopy(load)),
            Slot("$WORLD", "FRAME", copy.deepcopy(zero), writable=False),
            Slot("$NULLFRAME", "FRAME", copy.deepcopy(zero), writable=False),
            Slot("$ROBROOT", "FRAME", copy.deepcopy(zero), writable=False),
            Slot("$VEL", "CP", self._struct_of("CP", {"CP": 2.0, "ORI1": 200.0, "ORI2": 200.0})),
            Slot("$ACC", "CP", self._struct_of("CP", {"CP": 2.3, "ORI1": 400.0, "ORI2": 400.0})),
            Slot("$APO", "APO", self._struct_of("APO", {"CVEL": 100, "CPTP": 0, "CDIS": 0.0})),
            Slot("$ADVANCE", "INT", 3),
            Slot("$OV_PRO", "INT", 100),
            Slot("$ACT_BASE", "INT", -1),
            Slot("$ACT_TOOL", "INT", -1),
            Slot("$VEL_AXIS", "INT", Array("INT", (12,), [100] * 12), dims=(12,)),
            Slot("$ACC_AXIS", "INT", Array("INT", (12,), [100] * 12), dims=(12,)),
            Slot("$IN", "BOOL", Array("BOOL", (N_IO,), self.inputs), (N_IO,), writable=False),
            Slot("$OUT", "BOOL", Array("BOOL", (N_IO,), self.outputs), (N_IO,)),
            Slot("$POS_ACT", "E6POS", writable=False, getter=self._pos_act),
            Slot("$AXIS_ACT", "E6AXIS", writable=False, getter=self._axis_act),
            Slot("$POS_INT", "E6POS", self._default("E6POS"), writable=False),
            Slot("$AXIS_INT", "E6AXIS", self._default("E6AXIS"), writable=False),
            Slot("BASE_DATA", "FRAME", self._filled("FRAME", zero, 32), dims=(32,)),
            Slot("TOOL_DATA", "FRAME", self._filled("FRAME", zero, 16), dims=(16,)),
            Slot("LOAD_DATA", "LOAD", self._filled("LOAD", load, 16), dims=(16,)),
        ]
        self.system = {s.name: s for s in sys}

    def _filled(self, typ: str, value: Struct, n: int) -> Array:
        return Array(typ, (n,), [copy.deepcopy(value) for _ in range(n)])

    def _struct_of(self, typ: str, values: Mapping[str, Any]) -> Struct:
        s = self._default(typ)
        assert isinstance(s, Struct)
        for k, v in values.items():
            ctype = dict(self.structs[typ])[k]
            s.f[k] = self._struct_of(ctype, v) if isinstance(v, Mapping) else v
        return s

    def _load_dat(self, text: str) -> None:
        name, stmts = parse_dat(text)
        if name != self.main.name:
            raise KrlError(f"DEFDAT {name} does not match the module's main DEF {self.main.name}")
        for stmt in stmts:
            try:
                if isinstance(stmt, Assign):
                    self._assign(stmt, None)
                else:
                    self._declare(stmt, self.data, None)
            except KrlError as e:
                raise e.at(stmt.where) from None

    # -- declarations and values
    def _default(self, typ: str) -> Any:
        if typ in self.structs:
            return Struct(typ, {c: self._default(t) for c, t in self.structs[typ]})
        if typ in SIMPLE or typ in self.enums:
            return None
        raise KrlError(f"unknown data type {typ}")

    def _declare(self, stmt: Stmt, scope: dict[str, Slot], frame: _Frame | None) -> None:
        if isinstance(stmt, StrucDecl):
            self._new_type(stmt.name)
            for _, t in stmt.comps:
                self._default(t)
            self.structs[stmt.name] = stmt.comps
            return
        if isinstance(stmt, EnumDecl):
            self._new_type(stmt.name)
            self.enums[stmt.name] = stmt.values
            return
        if isinstance(stmt, SignalDecl):
            self._unique(stmt.name, scope)
            scope[stmt.name] = self._signal(stmt)
            return
        assert isinstance(stmt, Decl)
        self._default(stmt.type)
        for item in stmt.items:
            self._declare_item(stmt, item, scope, frame)

    def _new_type(self, name: str) -> None:
        if name in self.structs or name in self.enums or name in SIMPLE:
            raise KrlError(f"type {name} declared twice")

    def _unique(self, name: str, scope: dict[str, Slot]) -> None:
        if name in scope:
            raise KrlError(f"name {name} declared twice (KRL names are case-insensitive)")
        if name in self.routines:
            raise KrlError(f"name {name} is also a routine")

    def _signal(self, s: SignalDecl) -> Slot:
        if not 1 <= s.number <= N_IO:
            raise KrlError(f"SIGNAL {s.name}: {s.io}[{s.number}] out of range")
        bits = self.inputs if s.io == "$IN" else self.outputs
        k = s.number - 1
        return Slot(
            s.name,
            "BOOL",
            writable=s.io == "$OUT",
            getter=lambda: bits[k],
            setter=lambda v: bits.__setitem__(k, v),
            signal=(s.io, s.number),
        )

    def _declare_item(
        self, stmt: Decl, item: DeclItem, scope: dict[str, Slot], frame: _Frame | None
    ) -> None:
        if frame is not None and item.name in frame.scope and frame.scope[item.name].type is None:
            self._type_parameter(frame.scope[item.name], stmt, item)
            return
        self._unique(item.name, scope)
        if item.dims is not None:
            if any(n is None or n < 1 for n in item.dims) or len(item.dims) > 3:
                raise KrlError(f"array {item.name} needs 1 to 3 positive sizes")
            dims = tuple(int(n or 0) for n in item.dims)
            data = [self._default(stmt.type) for _ in range(math.prod(dims))]
            slot = Slot(item.name, stmt.type, Array(stmt.type, dims, data), dims)
            if item.init is not None:
                self._store(self._slot_place(slot), self._eval(item.init, frame))
        else:
            slot = Slot(item.name, stmt.type, self._default(stmt.type))
            if item.init is not None:
                slot.value = self._coerce(self._eval(item.init, frame), stmt.type, slot.value)
        if stmt.const:
            if item.init is None:
                raise KrlError(f"CONST {item.name} needs a value")
            slot.writable = False
        scope[item.name] = slot

    def _type_parameter(self, slot: Slot, stmt: Decl, item: DeclItem) -> None:
        """The DECL of a parameter: gives it its type (and checks what the caller passed)."""
        if item.init is not None or stmt.const:
            raise KrlError(f"parameter {item.name} cannot have a value or be CONST")
        is_array = item.dims is not None
        if is_array != (slot.dims is not None):
            raise KrlError(f"parameter {item.name}: array and non-array mixed")
        if slot.ref_type is not None:  # :OUT, by reference: the caller's type must match
            if slot.ref_type != stmt.type:
                raise KrlError(
                    f":OUT parameter {item.name} is {stmt.type}, the caller passed {slot.ref_type}"
                )
        elif isinstance(slot.value, Array):
            if slot.value.type != stmt.type:
                raise KrlError(f"parameter {item.name} is {stmt.type}, got {slot.value.type}")
        else:
            slot.value = self._coerce(slot.value, stmt.type, self._default(stmt.type))
        slot.type = stmt.type

    def _coerce(self, value: Any, typ: str, old: Any = None) -> Any:
        """``value`` as a value of ``typ`` (``old``: the target's value, for aggregates that
        set only some components).

        Raises:
            KrlError: ``value`` cannot be converted.
        """
        if value is None:
            raise KrlError(f"invalid value assigned to a {typ}")
        if isinstance(value, Array):
            raise KrlError("an array cannot be assigned as a whole")
        if typ in SIMPLE:
            out = self._simple(value, typ)
            return f32(out) if self.real_float32 and typ == "REAL" else out
        if typ in self.enums:
            if not isinstance(value, EnumVal) or value.name not in self.enums[typ]:
                raise KrlError(f"{_kind(value)} is not a value of ENUM {typ}")
            return value
        if typ not in self.structs:
            raise KrlError(f"unknown data type {typ}")
        return self._coerce_struct(value, typ, old)

    def _coerce_struct(self, value: Any, typ: str, old: Any) -> Struct:
        comps = dict(self.structs[typ])
        base = copy.deepcopy(old) if isinstance(old, Struct) and old.type == typ else None
        if base is None:
            base = self._default(typ)
        if isinstance(value, AggValue):
            if value.type is not None and value.type != typ:
                fam = _family(typ)
                if fam is None or value.type not in fam:
                    raise KrlError(f"{{{value.type}: ...}} aggregate assigned to a {typ}")
            for c, v in value.items:
                if c not in comps:
                    raise KrlError(f"{typ} has no component {c}")
                base.f[c] = self._coerce(v, comps[c], base.f[c])
            return base
        if isinstance(value, Struct):
            if value.type == typ:
                return copy.deepcopy(value)
            fam = _family(typ)
            if fam is not None and value.type in fam:
                for c in comps:
                    if c in value.f:
                        base.f[c] = copy.deepcopy(value.f[c])
                return base
        raise KrlError(f"cannot assign {_kind(value)} to {typ}")

    @staticmethod
    def _simple(value: Any, typ: str) -> Any:
        if typ == "INT" and _is_num(value):
            return value if isinstance(value, int) else _round_int(value)
        if typ == "REAL" and _is_num(value):
            return float(value)
        if typ == "BOOL" and isinstance(value, bool):
            return value
        if typ == "CHAR" and isinstance(value, str) and len(value) == 1:
            return value
        raise KrlError(f"cannot assign {_kind(value)} to {typ}")

    # -- names and places
    def _lookup(self, name: str, frame: _Frame | None) -> Slot:
        for scope in (frame.scope if frame else {}, self.data, self.system):
            if name in scope:
                return scope[name]
        if name.startswith("$"):
            raise KrlError(f"system variable {name} is not supported by this interpreter")
        raise KrlError(f"unknown name {name}")

    def _slot_place(self, slot: Slot) -> Place:
        return Place(
            slot.name, slot.type or "?", slot.dims, slot.get, slot.put, writable=slot.writable
        )

    def _place(self, e: Expr, frame: _Frame | None) -> Place:
        if isinstance(e, Name):
            return self._slot_place(self._lookup(e.name, frame))
        if isinstance(e, Index):
            base = self._place(e.base, frame)
            if not e.indices:  # name[]: the whole array (strings, :OUT array parameters)
                if base.dims is None:
                    raise KrlError(f"{base.what} is not an array")
                return base
            arr = base.get()
            if not isinstance(arr, Array):
                raise KrlError(f"{base.what} is not an array")
            k = arr.offset([self._eval(i, frame) for i in e.indices])
            return Place(
                f"{base.what}[..]",
                arr.type,
                None,
                lambda: arr.data[k],
                lambda v: arr.data.__setitem__(k, v),
                base.writable,
            )
        if isinstance(e, Member):
            base = self._place(e.base, frame)
            s = base.get()
            if not isinstance(s, Struct):
                raise KrlError(f"{base.what} ({_kind(s)}) has no components")
            comps = dict(self.structs[s.type])
            if e.name not in comps:
                raise KrlError(f"{s.type} has no component {e.name}")
            return Place(
                f"{base.what}.{e.name}",
                comps[e.name],
                None,
                lambda: s.f[e.name],
                lambda v: s.f.__setitem__(e.name, v),
                base.writable,
            )
        raise KrlError("not a variable")

    def _store(self, place: Place, value: Any) -> None:
        if not place.writable:
            raise KrlError(f"{place.what} is write-protected")
        if place.dims is not None:
            arr = place.get()
            if place.type == "CHAR" and isinstance(value, str) and len(place.dims) == 1:
                if len(value) > place.dims[0]:
                    raise KrlError(f"string of {len(value)} characters for CHAR[{arr.dims[0]}]")
                arr.data[: len(value)] = list(value)
                return
            raise KrlError(f"{place.what}: an array cannot be assigned as a whole")
        place.set(self._coerce(value, place.type, place.get()))

    # -- expressions
    def _real(self, value: Any) -> Any:
        """A value just made: its REALs rounded to single precision when :attr:`real_float32`."""
        return round_real(value) if self.real_float32 else value

    def _eval(self, e: Expr, frame: _Frame | None) -> Any:
        if isinstance(e, Lit):
            return self._real(e.value)
        if isinstance(e, Name | Index):
            place = self._place(e, frame)
            if place.dims is not None:
                raise KrlError(f"array {place.what} used as a value")
            return self._valid(place.get(), place.what)
        if isinstance(e, Member):
            s = self._eval(e.base, frame)
            if isinstance(s, AggValue):
                s = self._coerce(s, s.type or "FRAME")
            if not isinstance(s, Struct):
                raise KrlError(f"{_kind(s)} has no component {e.name}")
            if e.name not in s.f:
                raise KrlError(f"{s.type} has no component {e.name}")
            return self._valid(s.f[e.name], f"component {e.name}")
        if isinstance(e, Agg):
            return AggValue(e.type, tuple((c, self._eval(v, frame)) for c, v in e.items))
        if isinstance(e, Unary):
            return self._unary(e.op, self._eval(e.operand, frame))
        if isinstance(e, Binary):
            v = self._binary(e.op, self._eval(e.left, frame), self._eval(e.right, frame))
            return self._real(v)
        if isinstance(e, Call):
            return self._real(self._function(e, frame))
        raise KrlError(f"cannot evaluate {e!r}")

    @staticmethod
    def _valid(value: Any, what: str) -> Any:
        if value is None:
            raise KrlError(f"{what} is invalid (never assigned)")
        return value

    @staticmethod
    def _unary(op: str, v: Any) -> Any:
        if op == "NOT" and isinstance(v, bool):
            return not v
        if op == "B_NOT" and isinstance(v, int) and not isinstance(v, bool):
            return ~v
        if op in ("-", "+") and _is_num(v):
            return -v if op == "-" else v
        raise KrlError(f"no operator {op} for {_kind(v)}")

    def _binary(self, op: str, a: Any, b: Any) -> Any:
        if op == ":":
            return self._geometric(a, b)
        if op in ("+", "-", "*", "/"):
            return _arith(op, a, b)
        if op in ("==", "<>", "<", ">", "<=", ">="):
            return _compare(op, a, b)
        return _logic(op, a, b)

    def _cartesian(self, v: Any, what: str) -> Struct:
        """``v`` (a FRAME/POS/E6POS or an aggregate of one; untyped: E6POS) as a structure."""
        if isinstance(v, AggValue):
            v = self._coerce(v, v.type or "E6POS")
        if not (isinstance(v, Struct) and v.type in FAMILIES[0]):
            raise KrlError(f"{what} must be a FRAME, POS or E6POS, got {_kind(v)}")
        return v

    def _geometric(self, a: Any, b: Any) -> Struct:
        """``a:b``: the pose ``b`` given in frame ``a``; the type of ``b``."""
        left = self._cartesian(a, "left operand of ':'")
        right = copy.deepcopy(self._cartesian(b, "right operand of ':'"))
        T = frame_matrix(left.f, "left operand of ':'") @ frame_matrix(
            right.f, "right operand of ':'"
        )
        right.f.update(frame_values(T))
        return right

    def _inv_pos(self, v: Any) -> Struct:
        out = copy.deepcopy(self._cartesian(v, "INV_POS argument"))
        out.f.update(frame_values(invert_transform(frame_matrix(out.f, "INV_POS argument"))))
        return out

    def _function(self, e: Call, frame: _Frame | None) -> Any:
        if e.name in self.routines:
            r = self.routines[e.name]
            if r.returns is None:
                raise KrlError(f"{e.name} is a DEF, not a function (DEFFCT)")
            return self._call(r, self._args(r, e.args, frame))
        args = [self._eval(a, frame) for a in e.args]
        if e.name == "INV_POS" and len(args) == 1:
            return self._inv_pos(args[0])
        fn = FUNCTIONS.get(e.name)
        if fn is None:
            raise KrlError(f"unknown function {e.name}")
        try:
            return fn(*args)
        except TypeError:
            raise KrlError(f"{e.name}: wrong number of arguments ({len(args)})") from None

    # -- routines
    def _args(self, r: Routine, exprs: tuple[Expr, ...], frame: _Frame | None) -> list[Any]:
        if len(exprs) != len(r.params):
            raise KrlError(f"{r.name} takes {len(r.params)} arguments, got {len(exprs)}")
        out: list[Any] = []
        for (pname, mode, _), e in zip(r.params, exprs):
            if mode == "OUT":
                if not isinstance(e, Name | Index | Member):
                    raise KrlError(f"{r.name}: :OUT parameter {pname} needs a variable")
                out.append(self._place(e, frame))
            else:
                out.append(self._eval_arg(e, frame))
        return out

    def _eval_arg(self, e: Expr, frame: _Frame | None) -> Any:
        if isinstance(e, Name):
            slot = self._lookup(e.name, frame)
            if slot.dims is not None:
                return copy.deepcopy(slot.get())
        return copy.deepcopy(self._eval(e, frame))

    def _call(self, r: Routine, args: list[Any]) -> Any:
        frame = _Frame(r, {}, len(self._stack) + 1)
        for (pname, mode, is_array), arg in zip(r.params, args):
            frame.scope[pname] = self._bind(pname, mode, is_array, arg)
        for d in r.decls:
            try:
                self._declare(d, frame.scope, frame)
            except KrlError as e:
                raise e.at(d.where) from None
        untyped = [n for n, s in frame.scope.items() if s.type is None]
        if untyped:
            raise KrlError(f"{r.name}: parameter(s) {', '.join(untyped)} without DECL", r.where)
        self._stack.append(frame)
        try:
            self._block(r.body, frame)
        except _Return as ret:
            return self._returned(r, ret)
        except _Exit as ex:
            raise KrlError("EXIT outside a loop", ex.where) from None
        finally:
            self._stack.pop()
            self._drop_interrupts(frame.depth)
        if r.returns is not None:
            raise KrlError(f"function {r.name} ended without RETURN", r.where)
        return None

    def _bind(self, pname: str, mode: str, is_array: bool, arg: Any) -> Slot:
        if mode == "OUT":
            assert isinstance(arg, Place)
            if is_array != (arg.dims is not None):
                raise KrlError(f"parameter {pname}: array and non-array mixed")
            return Slot(
                pname,
                None,
                dims=arg.dims,
                writable=arg.writable,
                getter=arg.get,
                setter=arg.set,
                ref_type=arg.type,
            )
        dims = arg.dims if isinstance(arg, Array) else None
        if is_array != (dims is not None):
            raise KrlError(f"parameter {pname}: array and non-array mixed")
        return Slot(pname, None, arg, dims)

    def _returned(self, r: Routine, ret: _Return) -> Any:
        if r.returns is None:
            if ret.value is not None:
                raise KrlError(f"DEF {r.name} cannot return a value", ret.where)
            return None
        if ret.value is None:
            raise KrlError(f"function {r.name} must return a value", ret.where)
        try:
            return self._coerce(ret.value, r.returns)
        except KrlError as e:
            raise e.at(ret.where) from None

    # -- statements
    def _block(self, stmts: tuple[Stmt, ...], frame: _Frame) -> None:
        for s in stmts:
            self._steps += 1
            if self._steps > MAX_STEPS:
                raise KrlError(f"more than {MAX_STEPS} statements: an endless loop?", s.where)
            try:
                _HANDLERS[type(s)](self, s, frame)
            except KrlError as e:
                raise e.at(s.where) from None
            self._poll(frame, s.where)

    def _assign(self, s: Assign, frame: _Frame | None) -> None:
        self._store(self._place(s.target, frame), self._eval(s.value, frame))

    def _cond(self, e: Expr, frame: _Frame | None, what: str) -> bool:
        v = self._eval(e, frame)
        if not isinstance(v, bool):
            raise KrlError(f"{what} must be BOOL, got {_kind(v)}")
        return v

    def _call_stmt(self, s: CallStmt, frame: _Frame) -> None:
        name = s.call.name
        if name not in self.routines and name == "BAS":
            self._bas([self._eval(a, frame) for a in s.call.args])
            return
        if name not in self.routines:
            raise KrlError(f"unknown subprogram {name}")
        r = self.routines[name]
        if r.returns is not None:
            raise KrlError(f"{name} is a function (DEFFCT): use its value")
        try:
            self._call(r, self._args(r, s.call.args, frame))
        except _Unwind as u:
            if u.depth != frame.depth:
                raise

    def _if(self, s: If, frame: _Frame) -> None:
        self._block(s.then if self._cond(s.cond, frame, "IF condition") else s.other, frame)

    def _for(self, s: For, frame: _Frame) -> None:
        place = self._place(Name(s.var), frame)
        if place.type != "INT" or place.dims is not None:
            raise KrlError(f"FOR counter {s.var} must be an INT variable")
        lo, hi = self._eval(s.lo, frame), self._eval(s.hi, frame)
        step = 1 if s.step is None else self._eval(s.step, frame)
        if not all(isinstance(v, int) and not isinstance(v, bool) for v in (lo, hi, step)):
            raise KrlError("FOR bounds and STEP must be INT")
        if step == 0:
            raise KrlError("FOR STEP 0")
        v = lo
        try:
            while (step > 0 and v <= hi) or (step < 0 and v >= hi):
                self._store(place, v)
                self._block(s.body, frame)
                v += step
        except _Exit:
            return

    def _while(self, s: While, frame: _Frame) -> None:
        try:
            while self._cond(s.cond, frame, "WHILE condition"):
                self._block(s.body, frame)
        except _Exit:
            return

    def _repeat(self, s: Repeat, frame: _Frame) -> None:
        try:
            while True:
                self._block(s.body, frame)
                if self._cond(s.cond, frame, "UNTIL condition"):
                    return
        except _Exit:
            return

    def _loop(self, s: Loop, frame: _Frame) -> None:
        try:
            while True:
                self._block(s.body, frame)
        except _Exit:
            return

    def _switch(self, s: Switch, frame: _Frame) -> None:
        v = self._eval(s.value, frame)
        if not (isinstance(v, int | str | EnumVal) and not isinstance(v, bool)):
            raise KrlError(f"SWITCH needs INT, CHAR or ENUM, got {_kind(v)}")
        for values, body in s.cases:
            if any(_compare("==", v, self._eval(x, frame)) for x in values):
                self._block(body, frame)
                return
        if s.default is not None:
            self._block(s.default, frame)

    def _raise_exit(self, s: Exit, frame: _Frame) -> None:
        raise _Exit(s.where)

    def _return(self, s: Return, frame: _Frame) -> None:
        raise _Return(None if s.value is None else self._eval(s.value, frame), s.where)

    def _halt(self, s: Halt, frame: _Frame) -> None:
        raise _Halt(s.where)

    def _wait_sec(self, s: WaitSec, frame: _Frame) -> None:
        t = self._eval(s.seconds, frame)
        if not _is_num(t) or t < 0:
            raise KrlError(f"WAIT SEC needs a time >= 0, got {t!r}")

    def _wait_for(self, s: WaitFor, frame: _Frame) -> None:
        if not self._cond(s.cond, frame, "WAIT FOR condition"):
            raise KrlError("WAIT FOR waits forever: its condition is FALSE and nothing changes it")

    def _nop(self, s: Stmt, frame: _Frame) -> None:
        return

    def _bas(self, args: list[Any]) -> None:
        """The BAS package's commands a program may call (values as the KSS defaults)."""
        if not args or not isinstance(args[0], EnumVal):
            raise KrlError("BAS needs a command such as #INITMOV")
        cmd, value = args[0].name, (args[1] if len(args) > 1 else 0)
        sys = self.system
        if cmd == "INITMOV":
            sys["$VEL"].value = self._struct_of("CP", {"CP": 2.0, "ORI1": 200.0, "ORI2": 200.0})
            sys["$ACC"].value = self._struct_of("CP", {"CP": 2.3, "ORI1": 400.0, "ORI2": 400.0})
            sys["$VEL_AXIS"].value.data[:] = [100] * 12
            sys["$ACC_AXIS"].value.data[:] = [100] * 12
            sys["$ADVANCE"].value = 3
        elif cmd in ("TOOL", "BASE"):
            if not isinstance(value, int) or isinstance(value, bool):
                raise KrlError(f"BAS(#{cmd}, n) needs an INT number")
            table = sys[f"{cmd}_DATA"].value
            frame = sys["$NULLFRAME"].value if value == 0 else table.data[table.offset([value])]
            sys[f"${cmd}"].value = copy.deepcopy(frame)
            sys[f"$ACT_{cmd}"].value = value
        elif cmd in ("VEL_PTP", "ACC_PTP"):
            name = "$VEL_AXIS" if cmd == "VEL_PTP" else "$ACC_AXIS"
            sys[name].value.data[:] = [_round_int(float(value))] * 12
        elif cmd in ("VEL_CP", "ACC_CP"):
            sys["$VEL" if cmd == "VEL_CP" else "$ACC"].value.f["CP"] = float(value)
        else:
            raise KrlError(f"BAS(#{cmd}) is not supported by this interpreter")

    # -- interrupts
    def _int_decl(self, s: IntDecl, frame: _Frame) -> None:
        prio = self._eval(s.prio, frame)
        if isinstance(prio, bool) or not isinstance(prio, int) or prio not in PRIORITIES:
            raise KrlError(f"interrupt priority {prio!r} not allowed (1, 2, 4-39, 81-128)")
        r = self.routines.get(s.call.name)
        if r is None or r.returns is not None:
            raise KrlError(f"interrupt {prio}: {s.call.name} is not a DEF of this module")
        reads = self._reads_sensor(s.cond)
        self._interrupts[prio] = _Interrupt(prio, s, frame.depth, reads)

    def _reads_sensor(self, e: Expr) -> bool:
        """Whether an interrupt condition reads the sensor input (found without evaluating)."""
        if isinstance(e, Name):
            slot = self._lookup(e.name, None)
            return slot.signal == ("$IN", self.sensor_input)
        if isinstance(e, Index):
            if e.base == Name("$IN"):
                i = e.indices[0] if len(e.indices) == 1 else None
                return not isinstance(i, Lit) or i.value == self.sensor_input
            return self._reads_sensor(e.base) or any(self._reads_sensor(i) for i in e.indices)
        if isinstance(e, Member):
            return self._reads_sensor(e.base)
        if isinstance(e, Unary):
            return self._reads_sensor(e.operand)
        if isinstance(e, Binary):
            return self._reads_sensor(e.left) or self._reads_sensor(e.right)
        if isinstance(e, Call):
            return any(self._reads_sensor(a) for a in e.args)
        if isinstance(e, Agg):
            return any(self._reads_sensor(v) for _, v in e.items)
        return False

    def _int_ctl(self, s: IntCtl, frame: _Frame) -> None:
        if s.prio is None:
            chosen = list(self._interrupts.values())
        else:
            prio = self._eval(s.prio, frame)
            if prio not in self._interrupts:
                raise KrlError(f"INTERRUPT {s.action} {prio}: not declared at this level")
            chosen = [self._interrupts[prio]]
        for it in chosen:
            if s.action == "ON":
                it.on, it.last = True, self._condition(it)
            elif s.action == "OFF":
                it.on = False
            else:
                it.enabled = s.action == "ENABLE"

    def _condition(self, it: _Interrupt) -> bool:
        try:
            return self._cond(it.decl.cond, None, f"condition of interrupt {it.prio}")
        except KrlError as e:
            raise KrlError(f"{e.message} (declared at {it.decl.where})") from None

    def _active(self) -> list[_Interrupt]:
        return sorted(
            (it for it in self._interrupts.values() if it.on and it.enabled),
            key=lambda it: it.prio,
        )

    def _drop_interrupts(self, depth: int) -> None:
        for prio, it in list(self._interrupts.items()):
            if it.depth is not None and it.depth >= depth:
                if it.decl.is_global:
                    it.depth = None  # still known; RESUME from it has no level to go back to
                else:
                    del self._interrupts[prio]

    def _poll(self, frame: _Frame, where: Src) -> None:
        """Fire the interrupts whose condition turned TRUE during the last statement."""
        if self._isr:
            return
        for it in self._active():
            now = self._condition(it)
            if now and not it.last:
                it.last = True
                self._fire(it, frame.depth, where)
            else:
                it.last = now

    def _fire(self, it: _Interrupt, interrupted_depth: int, where: Src) -> None:
        """Run ``it``'s routine (the interrupted statement goes on when it returns).

        Raises:
            _Unwind: RESUME goes back to the declaring routine, above the interrupted one.
            KrlError: RESUME where KRL refuses it (module docstring).
        """
        r = self.routines[it.decl.call.name]
        args = self._args(r, it.decl.call.args, None)
        self._isr.append(it)
        try:
            self._call(r, args)
        except _Resume as res:
            if it.depth is None:
                raise KrlError(
                    f"RESUME for GLOBAL interrupt {it.prio}, whose declaring routine has ended",
                    res.where,
                ) from None
            if interrupted_depth > it.depth:
                raise _Unwind(it.depth, res.where) from None
            raise KrlError(
                f"RESUME for interrupt {it.prio} (declared at {it.decl.where}) while the "
                f"interrupted statement {where} runs in the declaring routine itself: RESUME "
                "goes on after the call into the level below the declaring one, so the motion "
                "it ends must run in a subprogram called from there (KSS: impermissible program "
                "structure for RESUME)",
                res.where,
            ) from None
        finally:
            self._isr.pop()

    def _brake(self, s: Brake, frame: _Frame) -> None:
        if not self._isr:
            raise KrlError("BRAKE outside an interrupt routine")

    def _resume(self, s: Resume, frame: _Frame) -> None:
        if not self._isr:
            raise KrlError("RESUME outside an interrupt routine")
        raise _Resume(s.where)

    # -- motion
    def _pos_act(self) -> Struct:
        if self._tcp is None:
            raise KrlError("$POS_ACT: the TCP pose is unknown (after an axis-specific PTP)")
        return self._pose_struct(self._tcp)

    def _axis_act(self) -> Struct:
        if self._axes is None:
            raise KrlError("$AXIS_ACT: unknown (no axis-specific motion yet; no kinematics here)")
        return copy.deepcopy(self._axes)

    def _pose_struct(self, T_world_mm: np.ndarray) -> Struct:
        """An E6POS of a world TCP pose in the current ``$BASE``."""
        T = invert_transform(self._frame_var("$BASE")) @ T_world_mm
        s = self._default("E6POS")
        s.f.update(frame_values(T))
        s.f.update({f"E{k}": 0.0 for k in range(1, 7)})
        s.f["S"], s.f["T"] = self._st
        return self._real(s)

    def _frame_var(self, name: str) -> np.ndarray:
        return frame_matrix(self.system[name].value.f, name)

    def _move(self, s: Move, frame: _Frame) -> None:
        value = self._eval(s.target, frame)
        if self._is_axis(value):
            self._move_axes(s, value)
            return
        goal = self._goal(s, self._cartesian(value, f"{s.kind} target"))
        sensing = [it for it in self._active() if it.reads_sensor]
        motion = Motion(
            s.kind,
            s.where,
            None if self._tcp is None else to_metres(self._tcp),
            to_metres(goal),
            to_metres(self._frame_var("$BASE")),
            to_metres(self._frame_var("$TOOL")),
        )
        self.motions.append(motion)
        try:
            if sensing:
                if s.kind.startswith("PTP"):
                    raise KrlError("PTP with a sensor interrupt on: its path is not modelled")
                self._search_move(motion, goal, frame)
            else:
                self._go(goal)
        finally:
            motion.end_m = None if self._tcp is None else to_metres(self._tcp)

    def _is_axis(self, v: Any) -> bool:
        if isinstance(v, Struct):
            return v.type in FAMILIES[1]
        if isinstance(v, AggValue):
            if v.type is not None:
                return v.type in FAMILIES[1]
            return any(re.fullmatch(r"A[1-6]", c) for c, _ in v.items)
        return False

    def _move_axes(self, s: Move, value: Any) -> None:
        if s.kind != "PTP":
            raise KrlError(f"{s.kind} to an axis-specific target")
        if any(it.reads_sensor for it in self._active()):
            raise KrlError("PTP with a sensor interrupt on: its path is not modelled")
        axes = self._coerce(value, "E6AXIS", self._axes)
        missing = [c for c, _ in _AXES if axes.f[c] is None]
        if missing:
            raise KrlError(f"axis target without {', '.join(missing)}")
        self._axes = axes
        base, tool = self._frame_var("$BASE"), self._frame_var("$TOOL")
        start = None if self._tcp is None else to_metres(self._tcp)
        deg = tuple(float(axes.f[c]) for c, _ in _AXES)
        self.motions.append(
            Motion("PTP", s.where, start, None, to_metres(base), to_metres(tool), axes_deg=deg)
        )
        self._tcp = None
        self._set_sensor_after_move(True)

    def _goal(self, s: Move, target: Struct) -> np.ndarray:
        """``(4, 4)`` the world TCP pose a motion goes to, mm."""
        comps = {c: target.f.get(c) for c in "XYZABC"}
        if s.kind.endswith("_REL"):
            return self._relative_goal(s, comps)
        if any(v is None for v in comps.values()):
            if self._tcp is None:
                raise KrlError(f"{s.kind} target lacks components and the TCP pose is unknown")
            now = frame_values(invert_transform(self._frame_var("$BASE")) @ self._tcp)
            comps = {c: now[c] if v is None else v for c, v in comps.items()}
        if "S" in target.f:
            self._st = (target.f["S"], target.f["T"])
        return self._frame_var("$BASE") @ frame_matrix(comps, f"{s.kind} target")

    def _relative_goal(self, s: Move, comps: dict[str, Any]) -> np.ndarray:
        if self._tcp is None:
            raise KrlError(f"{s.kind}: the TCP pose is unknown")
        rel = {c: 0.0 if v is None else v for c, v in comps.items()}
        if s.rel_frame == "TOOL":
            return self._tcp @ frame_matrix(rel)
        if any(rel[c] != 0.0 for c in "ABC"):
            raise KrlError(f"{s.kind} #BASE with a rotation is not supported by this interpreter")
        goal = self._tcp.copy()
        goal[:3, 3] += self._frame_var("$BASE")[:3, :3] @ np.array([rel[c] for c in "XYZ"])
        return goal

    def _go(self, goal: np.ndarray) -> None:
        moved = self._tcp is None or np.linalg.norm(goal[:3, 3] - self._tcp[:3, 3]) > MOVE_TOL_MM
        self._tcp = goal
        self._set_sensor_after_move(bool(moved))

    def _set_sensor_after_move(self, moved: bool) -> None:
        """The sensor input after a motion that reached its target: ``sensor`` there when
        given (and the pose is known), else FALSE when it moved, else as it was."""
        k = self.sensor_input - 1
        if self.sensor is not None and self._tcp is not None:
            T = to_metres(self._tcp)
            self.inputs[k] = bool(self.sensor(T[:3, 3].copy(), T[:3, 2].copy()))
        elif moved:
            self.inputs[k] = False

    def _search_move(self, motion: Motion, goal: np.ndarray, frame: _Frame) -> None:
        """A LIN with the sensor interrupt on: ask the callback, flip the input, fire."""
        if self._tcp is None:
            raise KrlError("LIN search from an unknown TCP pose")
        start = self._tcp.copy()
        k = self.sensor_input - 1
        for _ in range(8):
            a, b = self._tcp[:3, 3] / 1000.0, goal[:3, 3] / 1000.0
            if np.linalg.norm(b - a) * 1000.0 <= MOVE_TOL_MM:
                break
            axis = goal[:3, 2].copy()
            level = self.inputs[k]
            res = self.search(a.copy(), b.copy(), axis, level)
            res = res if isinstance(res, str) else np.array(res, dtype=float)
            self.search_calls.append(SearchCall(a.copy(), b.copy(), axis, level, res))
            motion.events.append(res)
            if isinstance(res, str) and res == "ERR_SIGSUPSEARCH":  # switched before: no edge
                self.inputs[k] = not level
                for it in self._active():
                    it.last = self._condition(it)
            if isinstance(res, str):
                break
            self._tcp = self._pose_on_line(start, goal, res * 1000.0)
            self.inputs[k] = not level
            self._interrupt_at(motion, frame)
        else:
            raise KrlError("the sensor input changed more than 8 times during one motion")
        self._tcp = goal
        if self.sensor is not None:
            self._set_sensor_after_move(True)

    def _pose_on_line(self, start: np.ndarray, goal: np.ndarray, p_mm: np.ndarray) -> np.ndarray:
        """The commanded pose where the TCP passes ``p_mm`` on the line start -> goal.

        Raises:
            KrlError: the point is not on the segment (a callback answering another search).
        """
        if p_mm.shape != (3,) or not np.all(np.isfinite(p_mm)):
            raise KrlError(f"search callback returned {p_mm!r}, not a (3,) point")
        d = goal[:3, 3] - start[:3, 3]
        L = float(np.linalg.norm(d))
        t = float((p_mm - start[:3, 3]) @ d / L) if L > 0 else 0.0
        off = np.linalg.norm(p_mm - start[:3, 3] - t * d / max(L, 1e-300))
        if off > LINE_TOL_MM or t < -LINE_TOL_MM or t > L + LINE_TOL_MM:
            raise KrlError(
                f"search callback returned a point {off:.3g} mm off the commanded line, "
                f"{t:.3f} mm along it (length {L:.3f} mm)"
            )
        s = min(max(t / L, 0.0), 1.0) if L > 0 else 1.0
        R0 = start[:3, :3]
        R = R0 @ matrix_from_rotvec(s * rotvec_from_matrix(R0.T @ goal[:3, :3]))
        return make_transform(R, p_mm)

    def _interrupt_at(self, motion: Motion, frame: _Frame) -> None:
        """Fire the interrupts whose condition turned TRUE at the current pose (a RESUME ends
        the motion there: :class:`_Unwind`)."""
        assert self._tcp is not None
        self.system["$POS_INT"].value = self._pose_struct(self._tcp)
        for it in self._active():
            now = self._condition(it)
            if now and not it.last:
                it.last = True
                motion.interrupts.append(it.prio)
                self._fire(it, frame.depth, motion.where)
            else:
                it.last = now


def _mm(T_m: np.ndarray) -> np.ndarray:
    T = np.array(T_m, dtype=float)
    T[:3, 3] *= 1000.0
    return T


_HANDLERS: dict[type, Callable[[KrlMachine, Any, _Frame], None]] = {
    Assign: KrlMachine._assign,
    CallStmt: KrlMachine._call_stmt,
    If: KrlMachine._if,
    For: KrlMachine._for,
    While: KrlMachine._while,
    Repeat: KrlMachine._repeat,
    Loop: KrlMachine._loop,
    Switch: KrlMachine._switch,
    Exit: KrlMachine._raise_exit,
    Return: KrlMachine._return,
    Halt: KrlMachine._halt,
    WaitSec: KrlMachine._wait_sec,
    WaitFor: KrlMachine._wait_for,
    Nop: KrlMachine._nop,
    Move: KrlMachine._move,
    IntDecl: KrlMachine._int_decl,
    IntCtl: KrlMachine._int_ctl,
    Brake: KrlMachine._brake,
    Resume: KrlMachine._resume,
}
