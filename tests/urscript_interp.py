"""An interpreter, for tests, of the URScript subset that ``planner.export.urscript`` emits.

It runs a ``.script`` text against a simulated robot and an ideal sensor so tests can check
what a program *does*: which searches it commands, what it records, which frames it computes.

Language (checked when the text is loaded, as the controller compiles a program before it runs
it: a syntax error, an unknown function, a wrong argument count or an undefined variable is a
:class:`UrSyntaxError` naming the line, even on a path the run never takes):

- one statement per line, ``#`` comments; ``def``/``thread``/``if``/``elif``/``else``/``while``
  blocks closed by ``end``; ``return``, ``halt``, ``break``, ``continue``, ``global``,
  ``local``, ``run``/``join``/``kill`` of threads, ``enter_critical``/``exit_critical``;
- values: ``int``, ``float``, ``bool`` (``True``/``False``), strings, lists and poses
  ``p[x, y, z, rx, ry, rz]`` (metres, rotation vector in radians), indexing and element
  assignment; ``+ - * / %``, comparisons, ``and``/``or``/``xor``/``not`` (short-circuit);
  conditions must be ``bool``; ``int / int`` is refused (the manual does not say whether it
  truncates);
- the block keywords (``def``, ``end``, ``if`` ...) are reserved: none can name a variable or a
  parameter;
- scoping as the URScript manual: when the text is one ``def`` (a program), the variables of its
  first level are global; in a function or a thread a name is local when it is a parameter,
  declared ``local``, or assigned without being a global; any other name is global. Lists are
  values (copied on assignment and in calls);
- built-ins: the pose functions (``pose_trans``, ``pose_inv``, ``pose_add``, ``pose_sub``,
  ``point_dist``, ``interpolate_pose``, ``rotvec2rpy``, ``rpy2rotvec``), math (``sqrt``,
  ``sin`` ... ``atan2``, ``pow``, ``log``, ``floor``, ``ceil``, ``d2r``, ``r2d``, ``norm``,
  ``normalize``, ``length``), strings (``to_str``, ``str_cat``, ``str_len``), motion
  (``movej``, ``movel``, ``movep``, ``stopl``, ``stopj``, ``sync``, ``sleep``), robot state
  (``get_actual_tcp_pose``, ``get_target_tcp_pose``, ``get_tcp_offset``, ``set_tcp``,
  ``set_payload``), I/O (``get_standard_digital_in``, ``get_tool_digital_in``,
  ``get_digital_in``, ``write_output_{integer,float,boolean}_register``), ``textmsg``,
  ``popup`` and ``socket_{open,close,send_string,send_line}``. ``pose_dist`` is refused: UR
  does not document its formula. Anything else is unknown and refused.

Time and threads: threads run in control frames, in the order they were started; each runs
until it waits (``sync()``, ``sleep``, a blocking motion, ``join``). The clock advances between
frames to the next *event* (a motion ending, the sensor input switching, a sleep ending), or by
``cycle_s`` when given: a thread that polls with ``sync()`` sees every event at the instant it
happens, as with an ideal controller whose input has no latency. A motion issued in a frame
begins at the next frame, at the same instant. A loop that runs ``spin_limit`` times (a
million) without waiting is an error, as the controller stops such a thread; so is a run
longer than ``max_time_s`` of robot time or ``max_frames`` frames.
``enter_critical``/``exit_critical`` need nothing: a thread is never interrupted between two
waits.

Motion (frames: robot base, metres): ``movel``/``movep`` move the TCP on a straight line at the
commanded speed (no acceleration phases; a blend radius ``r`` is accepted and every move still
ends at its target); ``movej`` to a pose puts the TCP there (the path is not modelled; it takes
its straight distance at 0.25 m/s), ``movej`` to joint values is recorded and leaves the TCP as
is (no forward kinematics). ``kill`` of the thread that runs a motion, ``stopl`` and ``stopj``
stop it where it is (ideal stop). ``set_tcp`` keeps the flange still and moves the TCP with the
offset.

Sensor: one digital input (``sensor_input``) is the proximity sensor. Its level is known at the
start (off) and after every joint move (``rest_level(T_base_tcp)``, off by default: the
program's joint moves end clear of the part). A linear motion changes it only through the
search callback ``search(start_m, end_m, sensor_axis, neg_flank)`` (base frame, metres, the
sensor axis being the target pose's +z), the contract of ``tests/rapid_interp.py``: it returns
the ``(3,)`` TCP position where the input leaves the level it had at the start of the motion
(``neg_flank``: it was on), or a string: ``"ERR_SIGSUPSEARCH"`` (already at the searched level
at the start: the input switches as the motion begins) or any other (no switching on the
line). The callback is asked lazily, once per motion, when the program reads the input during
that motion or after it (before the next joint move): a retreat that no one watches is never
asked about. So a thread's ``movel`` interrupted by a polling loop, and a loop of small
blocking moves, are both searches, and the TCP is where the controller is when it sees the
input switch.

API: ``UrMachine(text, search, ...).run()``, then :attr:`UrMachine.variables`,
:meth:`UrMachine.measurements` (``meas_<ID>``), :meth:`UrMachine.frame`,
:attr:`UrMachine.motions`, :attr:`UrMachine.searches`, :attr:`UrMachine.messages`;
:meth:`UrMachine.call` computes one of the program's functions on its globals (e.g. the
adaptive A-H program's ``slot_target`` after the run).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Generator, Iterator
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

#: ``search(start_m, end_m, sensor_axis, neg_flank) -> (3,) point (base, m) or a string``.
SearchFn = Callable[[np.ndarray, np.ndarray, np.ndarray, bool], Any]
#: The callback's answer meaning "already at the searched level at the start".
AT_START = "ERR_SIGSUPSEARCH"
KEYWORDS = frozenset(
    (
        *("def", "end", "thread", "if", "elif", "else", "while", "return", "global", "local"),
        *("halt", "break", "continue", "run", "join", "kill", "and", "or", "xor", "not"),
        *("True", "False"),
    )
)
#: A loop that runs this often without waiting (sync, sleep, a motion) is an error.
SPIN_LIMIT = 1_000_000
#: Polling step when nothing is scheduled (the e-Series control cycle, 500 Hz), s.
DEFAULT_CYCLE_S = 0.002
#: Distances (m) and times (s) below this are equal.
EPS = 1e-12


# ====================================================================== errors
class UrScriptError(Exception):
    """Any error of a URScript program; the message names the line."""


class UrSyntaxError(UrScriptError):
    """The program does not compile: syntax, unknown name or function, wrong arguments."""


class UrRuntimeError(UrScriptError):
    """The program failed while running (the controller would stop it)."""


class _Problem(Exception):
    """A value problem inside a built-in; re-raised as :class:`UrRuntimeError` with the line."""


class _Return(Exception):
    def __init__(self, value: Any) -> None:
        self.value = value


class _Break(Exception):
    pass


class _Continue(Exception):
    pass


class _Halt(Exception):
    pass


# ====================================================================== values
@dataclass(frozen=True)
class Pose:
    """A URScript pose: ``x, y, z`` (m) and a rotation vector ``rx, ry, rz`` (rad)."""

    v: tuple[float, float, float, float, float, float]

    @classmethod
    def from_matrix(cls, T: np.ndarray) -> Pose:
        """The pose of a ``(4, 4)`` transform (m)."""
        r = rotvec_from_matrix(T[:3, :3])
        return cls((*map(float, T[:3, 3]), *map(float, r)))  # type: ignore[arg-type]

    def matrix(self) -> np.ndarray:
        """``(4, 4)`` transform, metres."""
        return make_transform(matrix_from_rotvec(self.v[3:]), self.v[:3])

    @property
    def position_m(self) -> np.ndarray:
        """``(3,)`` the position, metres."""
        return np.array(self.v[:3])

    def __str__(self) -> str:
        return "p[" + ", ".join(_text(x) for x in self.v) + "]"


@dataclass(frozen=True, eq=False)
class ThreadHandle:
    """What ``run`` returns: the thread's number and name."""

    number: int
    name: str


def _text(value: Any) -> str:
    """A value as ``textmsg`` and ``to_str`` write it."""
    if isinstance(value, bool):
        return "True" if value else "False"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, list):
        return "[" + ", ".join(_text(x) for x in value) + "]"
    return str(value)


def _type_name(value: Any) -> str:
    for typ, name in ((bool, "bool"), (int, "int"), (float, "float"), (str, "string")):
        if isinstance(value, typ):
            return name
    kinds = {Pose: "pose", list: "list", ThreadHandle: "thread", type(None): "no value"}
    return kinds.get(type(value), type(value).__name__)


def _copy(value: Any) -> Any:
    """URScript values are copied on assignment: lists deeply, the rest is immutable."""
    return [_copy(x) for x in value] if isinstance(value, list) else value


def _num(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _Problem(f"{what} must be a number, got {_type_name(value)}")
    return value


def _int(value: Any, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise _Problem(f"{what} must be an int, got {_type_name(value)}")
    return value


def _bool(value: Any, what: str) -> bool:
    if not isinstance(value, bool):
        raise _Problem(f"{what} must be a bool, got {_type_name(value)}")
    return value


def _str(value: Any, what: str) -> str:
    if not isinstance(value, str):
        raise _Problem(f"{what} must be a string, got {_type_name(value)}")
    return value


def _pose(value: Any, what: str) -> Pose:
    if not isinstance(value, Pose):
        raise _Problem(f"{what} must be a pose, got {_type_name(value)}")
    return value


def _vector(value: Any, what: str, n: int | None = None) -> list[float]:
    if not isinstance(value, list) or (n is not None and len(value) != n):
        size = f" of {n} numbers" if n else ""
        raise _Problem(f"{what} must be a list{size}, got {_type_name(value)} {_text(value)}")
    return [_num(x, f"{what} element") for x in value]


# ====================================================================== lexer
TOKEN = re.compile(
    r"(?P<ws>[ \t]+)|(?P<comment>#.*)"
    r"|(?P<num>(?:\d+\.\d*|\.\d+|\d+)(?:[eE][+-]?\d+)?)"
    r"|(?P<str>\"[^\"\n]*\"|'[^'\n]*')"
    r"|(?P<name>[A-Za-z_]\w*)"
    r"|(?P<op>==|!=|<=|>=|[-+*/%<>=()\[\],:])"
)


@dataclass(frozen=True)
class Token:
    """One token: ``kind`` is num, str, name, kw or op."""

    kind: str
    text: str
    line: int


def tokenize_line(text: str, line: int) -> list[Token]:
    """The tokens of one source line (comments dropped)."""
    out: list[Token] = []
    pos = 0
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if m is None:
            raise UrSyntaxError(f"line {line}: cannot read {text[pos:]!r}")
        pos = m.end()
        kind = m.lastgroup or ""
        if kind in ("ws", "comment"):
            continue
        word = m.group(kind)
        out.append(Token("kw" if kind == "name" and word in KEYWORDS else kind, word, line))
    return out


def logical_lines(text: str) -> list[list[Token]]:
    """The statements of ``text``, one token list each; a line with an open bracket goes on."""
    out: list[list[Token]] = []
    pending: list[Token] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        pending += tokenize_line(raw, number)
        depth = sum(t.text in "([" for t in pending if t.kind == "op")
        depth -= sum(t.text in ")]" for t in pending if t.kind == "op")
        if pending and depth <= 0:
            out.append(pending)
            pending = []
    if pending:
        raise UrSyntaxError(f"line {pending[0].line}: unclosed bracket")
    return out


# ====================================================================== syntax tree
@dataclass(frozen=True)
class Lit:
    value: Any
    line: int


@dataclass(frozen=True)
class Name:
    id: str
    line: int


@dataclass(frozen=True)
class ListExpr:
    items: tuple[Any, ...]
    line: int


@dataclass(frozen=True)
class PoseExpr:
    items: tuple[Any, ...]
    line: int


@dataclass(frozen=True)
class Index:
    target: Any
    index: Any
    line: int


@dataclass(frozen=True)
class Call:
    name: str
    args: tuple[Any, ...]
    kwargs: tuple[tuple[str, Any], ...]
    line: int


@dataclass(frozen=True)
class RunExpr:
    """``run name()``: starts a thread, gives its handle."""

    thread: str
    line: int


@dataclass(frozen=True)
class Unary:
    op: str
    operand: Any
    line: int


@dataclass(frozen=True)
class Binary:
    op: str
    left: Any
    right: Any
    line: int


@dataclass(frozen=True)
class Assign:
    """``[global|local] target = value``."""

    target: Any
    value: Any
    qualifier: str | None
    line: int


@dataclass(frozen=True)
class Declare:
    """``global name`` or ``local name`` without a value."""

    qualifier: str
    name: str
    line: int


@dataclass(frozen=True)
class ExprStmt:
    expr: Any
    line: int


@dataclass(frozen=True)
class If:
    arms: tuple[tuple[Any, tuple[Any, ...]], ...]
    orelse: tuple[Any, ...]
    line: int


@dataclass(frozen=True)
class While:
    cond: Any
    body: tuple[Any, ...]
    line: int


@dataclass(frozen=True)
class Return:
    value: Any
    line: int


@dataclass(frozen=True)
class Simple:
    """``halt``, ``break``, ``continue``, ``enter_critical``, ``exit_critical``."""

    word: str
    line: int


@dataclass(frozen=True)
class ThreadOp:
    """``kill handle`` or ``join handle``."""

    op: str
    handle: Any
    line: int


@dataclass
class FuncDef:
    """A ``def`` or a ``thread`` (no parameters); ``local_names`` is filled by the checker."""

    kind: str
    name: str
    params: tuple[str, ...]
    defaults: dict[str, Any]
    body: tuple[Any, ...]
    line: int
    local_names: frozenset[str] = frozenset()


# ====================================================================== parser
class _Expr:
    """A recursive-descent parser of the expression in a statement's tokens."""

    def __init__(self, toks: list[Token], line: int) -> None:
        self.t, self.i, self.line = toks, 0, line

    def peek(self, k: int = 0) -> Token | None:
        j = self.i + k
        return self.t[j] if j < len(self.t) else None

    def at(self, text: str) -> bool:
        tok = self.peek()
        return tok is not None and tok.text == text and tok.kind in ("op", "kw")

    def take(self, text: str | None = None) -> Token:
        tok = self.peek()
        if tok is None:
            raise UrSyntaxError(f"line {self.line}: unexpected end of line")
        if text is not None and not (tok.text == text and tok.kind in ("op", "kw")):
            raise UrSyntaxError(f"line {self.line}: expected {text!r}, got {tok.text!r}")
        self.i += 1
        return tok

    def done(self) -> bool:
        return self.i >= len(self.t)

    def expect_end(self) -> None:
        if not self.done():
            raise UrSyntaxError(f"line {self.line}: unexpected {self.t[self.i].text!r}")

    def expr(self) -> Any:
        e = self.and_()
        while self.at("or") or self.at("xor"):
            op = self.take().text
            e = Binary(op, e, self.and_(), self.line)
        return e

    def and_(self) -> Any:
        e = self.not_()
        while self.at("and"):
            self.take()
            e = Binary("and", e, self.not_(), self.line)
        return e

    def not_(self) -> Any:
        if self.at("not"):
            self.take()
            return Unary("not", self.not_(), self.line)
        return self.compare()

    def compare(self) -> Any:
        e = self.sum()
        tok = self.peek()
        if tok is not None and tok.kind == "op" and tok.text in ("==", "!=", "<", ">", "<=", ">="):
            self.take()
            e = Binary(tok.text, e, self.sum(), self.line)
        return e

    def sum(self) -> Any:
        e = self.product()
        while self.at("+") or self.at("-"):
            op = self.take().text
            e = Binary(op, e, self.product(), self.line)
        return e

    def product(self) -> Any:
        e = self.unary()
        while self.at("*") or self.at("/") or self.at("%"):
            op = self.take().text
            e = Binary(op, e, self.unary(), self.line)
        return e

    def unary(self) -> Any:
        if self.at("-") or self.at("+"):
            op = self.take().text
            return Unary(op, self.unary(), self.line)
        return self.postfix()

    def postfix(self) -> Any:
        e = self.primary()
        while self.at("["):
            self.take()
            e = Index(e, self.expr(), self.line)
            self.take("]")
        return e

    def items(self, close: str) -> tuple[Any, ...]:
        out = []
        while not self.at(close):
            out.append(self.expr())
            if not self.at(close):
                self.take(",")
        self.take(close)
        return tuple(out)

    def primary(self) -> Any:
        tok = self.take()
        if tok.kind == "num":
            is_int = re.fullmatch(r"\d+", tok.text) is not None
            return Lit(int(tok.text) if is_int else float(tok.text), self.line)
        if tok.kind == "str":
            return Lit(tok.text[1:-1], self.line)
        if tok.kind == "kw" and tok.text in ("True", "False"):
            return Lit(tok.text == "True", self.line)
        if tok.kind == "op" and tok.text == "(":
            e = self.expr()
            self.take(")")
            return e
        if tok.kind == "op" and tok.text == "[":
            return ListExpr(self.items("]"), self.line)
        if tok.kind == "name":
            if tok.text == "p" and self.at("["):
                self.take()
                return PoseExpr(self.items("]"), self.line)
            if self.at("("):
                self.take()
                return self.call(tok.text)
            return Name(tok.text, self.line)
        raise UrSyntaxError(f"line {self.line}: unexpected {tok.text!r}")

    def call(self, name: str) -> Call:
        args: list[Any] = []
        kwargs: list[tuple[str, Any]] = []
        while not self.at(")"):
            nxt = self.peek(1)
            tok = self.peek()
            if tok and tok.kind == "name" and nxt and nxt.kind == "op" and nxt.text == "=":
                self.i += 2
                kwargs.append((tok.text, self.expr()))
            elif kwargs:
                raise UrSyntaxError(f"line {self.line}: {name}(): positional after keyword")
            else:
                args.append(self.expr())
            if not self.at(")"):
                self.take(",")
        self.take(")")
        return Call(name, tuple(args), tuple(kwargs), self.line)


def _name_token(p: _Expr, what: str) -> str:
    tok = p.take()
    if tok.kind != "name":
        raise UrSyntaxError(f"line {p.line}: {tok.text!r} cannot be {what} (a reserved word?)")
    if tok.text == "p":
        raise UrSyntaxError(f"line {p.line}: 'p' cannot be {what}: it starts a pose p[...]")
    return tok.text


class _Parser:
    """Statements and blocks of a program's logical lines."""

    def __init__(self, text: str) -> None:
        self.lines = logical_lines(text)
        self.k = 0

    def block(self, stops: tuple[str, ...]) -> tuple[tuple[Any, ...], Token | None]:
        """Statements up to a line starting with one of ``stops`` (which is not consumed)."""
        body: list[Any] = []
        while self.k < len(self.lines):
            toks = self.lines[self.k]
            if toks[0].kind == "kw" and toks[0].text in stops:
                return tuple(body), toks[0]
            self.k += 1
            body.append(self.statement(toks))
        return tuple(body), None

    def closed(self, what: str, line: int) -> tuple[Any, ...]:
        body, stop = self.block(("end",))
        if stop is None:
            raise UrSyntaxError(f"line {line}: {what} has no end")
        self._bare(self.lines[self.k], "end")
        self.k += 1
        return body

    def _bare(self, toks: list[Token], word: str) -> None:
        if len(toks) != 1:
            raise UrSyntaxError(f"line {toks[0].line}: unexpected text after {word!r}")

    def statement(self, toks: list[Token]) -> Any:
        head, line = toks[0], toks[0].line
        if len(toks) == 1 and head.text in ("enter_critical", "exit_critical"):
            return Simple(head.text, line)
        if head.kind == "kw":
            return self.keyword_statement(head.text, toks, line)
        eq = [i for i, t in enumerate(toks) if t.kind == "op" and t.text == "="]
        if eq and _depth_at(toks, eq[0]) == 0:
            return self.assignment(toks[: eq[0]], toks[eq[0] + 1 :], None, line)
        if len(toks) > 1 and head.kind == "name" and toks[1].kind in ("name", "kw", "num"):
            raise UrSyntaxError(f"line {line}: unknown statement {head.text!r}")
        p = _Expr(toks, line)
        e = p.expr()
        p.expect_end()
        if not isinstance(e, Call):
            raise UrSyntaxError(f"line {line}: not a statement (an expression that is no call)")
        if e.name in ("enter_critical", "exit_critical"):
            raise UrSyntaxError(f"line {line}: {e.name} is written without parentheses")
        return ExprStmt(e, line)

    def assignment(
        self, lhs: list[Token], rhs: list[Token], qualifier: str | None, line: int
    ) -> Assign:
        p = _Expr(lhs, line)
        target = p.postfix()
        p.expect_end()
        base = target
        while isinstance(base, Index):
            base = base.target
        if not isinstance(base, Name) or (qualifier and base is not target):
            raise UrSyntaxError(f"line {line}: cannot assign to this")
        if not rhs:
            raise UrSyntaxError(f"line {line}: nothing after '='")
        if rhs[0].kind == "kw" and rhs[0].text == "run":
            return Assign(target, self.run_expr(rhs, line), qualifier, line)
        q = _Expr(rhs, line)
        value = q.expr()
        q.expect_end()
        return Assign(target, value, qualifier, line)

    def run_expr(self, toks: list[Token], line: int) -> RunExpr:
        p = _Expr(toks, line)
        p.take("run")
        name = _name_token(p, "a thread name")
        p.take("(")
        p.take(")")
        p.expect_end()
        return RunExpr(name, line)

    def keyword_statement(self, word: str, toks: list[Token], line: int) -> Any:
        p = _Expr(toks[1:], line)
        if word in ("def", "thread"):
            return self.definition(word, p, line)
        if word == "if":
            return self.if_block(p, line)
        if word == "while":
            cond = self.header(p)
            return While(cond, self.closed("while", line), line)
        if word == "return":
            value = None if p.done() else p.expr()
            p.expect_end()
            return Return(value, line)
        if word in ("global", "local"):
            return self.qualified(word, toks[1:], line)
        if word in ("halt", "break", "continue"):
            p.expect_end()
            return Simple(word, line)
        if word in ("kill", "join"):
            handle = p.expr()
            p.expect_end()
            return ThreadOp(word, handle, line)
        if word == "run":
            return ExprStmt(self.run_expr(toks, line), line)
        raise UrSyntaxError(f"line {line}: unexpected {word!r}")

    def header(self, p: _Expr) -> Any:
        cond = p.expr()
        p.take(":")
        p.expect_end()
        return cond

    def definition(self, word: str, p: _Expr, line: int) -> FuncDef:
        name = _name_token(p, "a function name")
        p.take("(")
        params: list[str] = []
        defaults: dict[str, Any] = {}
        while not p.at(")"):
            param = _name_token(p, "a parameter name")
            if p.at("="):
                p.take()
                defaults[param] = p.expr()
            elif defaults:
                raise UrSyntaxError(f"line {line}: parameter {param} without default after one")
            params.append(param)
            if not p.at(")"):
                p.take(",")
        p.take(")")
        p.take(":")
        p.expect_end()
        if word == "thread" and params:
            raise UrSyntaxError(f"line {line}: a thread takes no parameters")
        if len(set(params)) != len(params):
            raise UrSyntaxError(f"line {line}: repeated parameter name")
        body = self.closed(word, line)
        return FuncDef(word, name, tuple(params), defaults, body, line)

    def if_block(self, p: _Expr, line: int) -> If:
        arms = []
        cond = self.header(p)
        while True:
            body, stop = self.block(("elif", "else", "end"))
            arms.append((cond, body))
            if stop is None:
                raise UrSyntaxError(f"line {line}: if has no end")
            toks = self.lines[self.k]
            self.k += 1
            if stop.text == "elif":
                cond = self.header(_Expr(toks[1:], stop.line))
                continue
            orelse: tuple[Any, ...] = ()
            if stop.text == "else":
                q = _Expr(toks[1:], stop.line)
                q.take(":")
                q.expect_end()
                orelse = self.closed("else", stop.line)
            else:
                self._bare(toks, "end")
            return If(tuple(arms), orelse, line)

    def qualified(self, word: str, toks: list[Token], line: int) -> Any:
        eq = [i for i, t in enumerate(toks) if t.kind == "op" and t.text == "="]
        if eq:
            return self.assignment(toks[: eq[0]], toks[eq[0] + 1 :], word, line)
        p = _Expr(toks, line)
        name = _name_token(p, "a variable name")
        p.expect_end()
        return Declare(word, name, line)


def _depth_at(toks: list[Token], i: int) -> int:
    depth = 0
    for t in toks[:i]:
        if t.kind == "op" and t.text in "([":
            depth += 1
        elif t.kind == "op" and t.text in ")]":
            depth -= 1
    return depth


# ====================================================================== pure built-ins
@dataclass(frozen=True)
class Builtin:
    """A built-in function: its parameters (with defaults) and its implementation.

    ``fn`` takes the bound arguments by name; a ``machine`` built-in is a method of
    :class:`UrMachine` and a ``blocking`` one is a generator that may wait.
    """

    params: tuple[str, ...]
    defaults: dict[str, Any]
    fn: Callable[..., Any]
    blocking: bool = False


def _rotation(p: Pose) -> np.ndarray:
    return matrix_from_rotvec(p.v[3:])


def _pose_of(R: np.ndarray, t: np.ndarray) -> Pose:
    return Pose.from_matrix(make_transform(R, t))


def _pose_trans(p_from: Any, p_from_to: Any) -> Pose:
    a, b = _pose(p_from, "p_from"), _pose(p_from_to, "p_from_to")
    return Pose.from_matrix(a.matrix() @ b.matrix())


def _pose_inv(p_from: Any) -> Pose:
    return Pose.from_matrix(invert_transform(_pose(p_from, "p_from").matrix()))


def _pose_add(p_1: Any, p_2: Any) -> Pose:
    a, b = _pose(p_1, "p_1"), _pose(p_2, "p_2")
    return _pose_of(_rotation(a) @ _rotation(b), a.position_m + b.position_m)


def _pose_sub(p_to: Any, p_from: Any) -> Pose:
    a, b = _pose(p_to, "p_to"), _pose(p_from, "p_from")
    return _pose_of(_rotation(b).T @ _rotation(a), a.position_m - b.position_m)


def _pose_dist(p_from: Any, p_to: Any) -> float:
    raise _Problem("pose_dist: UR does not document its formula; not modelled here")


def _point_dist(p_from: Any, p_to: Any) -> float:
    a, b = _pose(p_from, "p_from"), _pose(p_to, "p_to")
    return float(np.linalg.norm(a.position_m - b.position_m))


def _interpolate_pose(p_from: Any, p_to: Any, alpha: Any) -> Pose:
    a, b, f = _pose(p_from, "p_from"), _pose(p_to, "p_to"), _num(alpha, "alpha")
    R0 = _rotation(a)
    R = R0 @ matrix_from_rotvec(f * rotvec_from_matrix(R0.T @ _rotation(b)))
    return _pose_of(R, a.position_m + f * (b.position_m - a.position_m))


def _rotvec2rpy(rotation_vector: Any) -> list[float]:
    alpha, beta, gamma = tait_bryan_zyx_from_matrix(
        matrix_from_rotvec(_vector(rotation_vector, "rotation_vector", 3))
    )
    return [float(gamma), float(beta), float(alpha)]  # roll, pitch, yaw: Rz(yaw)Ry(pitch)Rx(roll)


def _rpy2rotvec(rpy_vector: Any) -> list[float]:
    roll, pitch, yaw = _vector(rpy_vector, "rpy_vector", 3)
    return [float(x) for x in rotvec_from_matrix(matrix_from_tait_bryan_zyx(yaw, pitch, roll))]


def _norm(a: Any) -> float | int:
    if isinstance(a, Pose):
        return float(np.linalg.norm(a.v))
    if isinstance(a, list):
        return float(np.linalg.norm(_vector(a, "a")))
    return abs(_num(a, "a"))


def _normalize(v: Any) -> list[float]:
    x = np.array(_vector(v, "v"))
    n = float(np.linalg.norm(x))
    if n == 0.0:
        raise _Problem("normalize of a zero vector")
    return [float(c) for c in x / n]


def _length(v: Any) -> int:
    if not isinstance(v, list | str):
        raise _Problem(f"v must be a list or a string, got {_type_name(v)}")
    return len(v)


def _domain(fn: Callable[[float], float], lo: float, hi: float, name: str) -> Callable[..., float]:
    def checked(f: Any) -> float:
        x = _num(f, "f")
        if not lo <= x <= hi:
            raise _Problem(f"{name}({x}): outside [{lo}, {hi}]")
        return fn(x)

    return checked


def _pow(base: Any, exponent: Any) -> float:
    b, e = _num(base, "base"), _num(exponent, "exponent")
    if (b < 0 and float(e) != int(e)) or (b == 0 and e < 0):
        raise _Problem(f"pow({b}, {e}) is undefined")
    return float(b) ** e


def _log(b: Any, f: Any) -> float:
    base, x = _num(b, "b"), _num(f, "f")
    if base <= 0 or base == 1 or x <= 0:
        raise _Problem(f"log({base}, {x}) is undefined")
    return math.log(x) / math.log(base)


def _unary_math(fn: Callable[[float], Any]) -> Callable[..., Any]:
    return lambda f: fn(_num(f, "f"))


def _b(params: str, fn: Callable[..., Any], **defaults: Any) -> Builtin:
    return Builtin(tuple(params.split()), defaults, fn)


PURE: dict[str, Builtin] = {
    "pose_trans": _b("p_from p_from_to", _pose_trans),
    "pose_inv": _b("p_from", _pose_inv),
    "pose_add": _b("p_1 p_2", _pose_add),
    "pose_sub": _b("p_to p_from", _pose_sub),
    "pose_dist": _b("p_from p_to", _pose_dist),
    "point_dist": _b("p_from p_to", _point_dist),
    "interpolate_pose": _b("p_from p_to alpha", _interpolate_pose),
    "rotvec2rpy": _b("rotation_vector", _rotvec2rpy),
    "rpy2rotvec": _b("rpy_vector", _rpy2rotvec),
    "sqrt": _b("f", _domain(math.sqrt, 0.0, math.inf, "sqrt")),
    "sin": _b("f", _unary_math(math.sin)),
    "cos": _b("f", _unary_math(math.cos)),
    "tan": _b("f", _unary_math(math.tan)),
    "asin": _b("f", _domain(math.asin, -1.0, 1.0, "asin")),
    "acos": _b("f", _domain(math.acos, -1.0, 1.0, "acos")),
    "atan": _b("f", _unary_math(math.atan)),
    "atan2": _b("x y", lambda x, y: math.atan2(_num(x, "x"), _num(y, "y"))),
    "pow": _b("base exponent", _pow),
    "log": _b("b f", _log),
    "floor": _b("f", _unary_math(math.floor)),
    "ceil": _b("f", _unary_math(math.ceil)),
    "d2r": _b("d", lambda d: math.radians(_num(d, "d"))),
    "r2d": _b("r", lambda r: math.degrees(_num(r, "r"))),
    "norm": _b("a", _norm),
    "normalize": _b("v", _normalize),
    "length": _b("v", _length),
    "get_list_length": _b("v", _length),
    "to_str": _b("val", lambda val: _text(val)),
    "str_cat": _b("op1 op2", lambda op1, op2: _text(op1) + _text(op2)),
    "str_len": _b("str", lambda **kw: len(_str(kw["str"], "str"))),
}
#: Read-only variables every program has.
CONSTANTS: dict[str, Any] = {"pi": math.pi}


def _binary(op: str, a: Any, b: Any) -> Any:
    """``a op b`` for the arithmetic and comparison operators."""
    if op in ("==", "!="):
        if isinstance(a, bool) != isinstance(b, bool):
            raise _Problem(f"cannot compare {_type_name(a)} with {_type_name(b)}")
        return (a == b) == (op == "==")
    x, y = _num(a, f"left of {op}"), _num(b, f"right of {op}")
    if op in ("<", ">", "<=", ">="):
        return {"<": x < y, ">": x > y, "<=": x <= y, ">=": x >= y}[op]
    if op == "/":
        if isinstance(x, int) and isinstance(y, int):
            raise _Problem("int / int: write one operand as a float (truncation not modelled)")
        if y == 0:
            raise _Problem("division by zero")
        return x / y
    if op == "%":
        if x < 0 or y <= 0:
            raise _Problem(f"{x} % {y}: negative operands not modelled")
        return x % y
    return {"+": x + y, "-": x - y, "*": x * y}[op]


# ====================================================================== static checks
def _walk(body: tuple[Any, ...]) -> Iterator[Any]:
    """Every statement of ``body``, nested blocks included, function bodies excluded."""
    for st in body:
        yield st
        if isinstance(st, If):
            for _, arm in st.arms:
                yield from _walk(arm)
            yield from _walk(st.orelse)
        elif isinstance(st, While):
            yield from _walk(st.body)


def _assigned(body: tuple[Any, ...]) -> set[str]:
    """Names assigned in ``body`` (element assignments name their variable)."""
    out = set()
    for st in _walk(body):
        if isinstance(st, Assign):
            target = st.target
            while isinstance(target, Index):
                target = target.target
            out.add(target.id)
    return out


def _declared(body: tuple[Any, ...], qualifier: str) -> set[str]:
    out = set()
    for st in _walk(body):
        if isinstance(st, Declare) and st.qualifier == qualifier:
            out.add(st.name)
        elif isinstance(st, Assign) and st.qualifier == qualifier:
            out.add(st.target.id)
    return out


def _functions(body: tuple[Any, ...]) -> Iterator[FuncDef]:
    for st in _walk(body):
        if isinstance(st, FuncDef):
            yield st
            yield from _functions(st.body)


def _children(e: Any) -> tuple[Any, ...]:
    """The sub-expressions of expression ``e``."""
    if isinstance(e, Index):
        return (e.target, e.index)
    if isinstance(e, Call):
        return e.args + tuple(v for _, v in e.kwargs)
    if isinstance(e, ListExpr | PoseExpr):
        return e.items
    if isinstance(e, Unary):
        return (e.operand,)
    if isinstance(e, Binary):
        return (e.left, e.right)
    return ()


def _expressions(e: Any) -> Iterator[Any]:
    """``e`` and every expression under it."""
    if e is None:
        return
    yield e
    for child in _children(e):
        yield from _expressions(child)


def _bind(
    name: str,
    params: tuple[str, ...],
    defaults: dict[str, Any],
    n_args: int,
    keywords: tuple[str, ...],
    line: int,
) -> None:
    """Raise :class:`UrSyntaxError` unless the arguments bind to ``params``."""
    sig = ", ".join(p + (f"={defaults[p]!r}" if p in defaults else "") for p in params)
    if n_args > len(params):
        raise UrSyntaxError(
            f"line {line}: {name}() takes at most {len(params)} arguments ({sig}), got {n_args}"
        )
    given = set(params[:n_args])
    for k in keywords:
        if k not in params or k in given:
            raise UrSyntaxError(f"line {line}: {name}(): bad keyword argument {k!r} ({sig})")
        given.add(k)
    missing = [p for p in params if p not in given and p not in defaults]
    if missing:
        raise UrSyntaxError(f"line {line}: {name}(): missing {', '.join(missing)} ({sig})")


@dataclass
class Program:
    """A checked program: its body, functions and threads, and its global names."""

    body: tuple[Any, ...]
    functions: dict[str, FuncDef]
    globals: frozenset[str]


def compile_program(text: str, builtins: dict[str, Builtin]) -> Program:
    """Parse and check ``text`` (module docstring) against the ``builtins`` it may call."""
    parser = _Parser(text)
    top, stop = parser.block(("end", "elif", "else"))
    if stop is not None:
        raise UrSyntaxError(f"line {stop.line}: {stop.text!r} without a block")
    body = top
    if len(top) == 1 and isinstance(top[0], FuncDef) and top[0].kind == "def":
        if top[0].params:
            raise UrSyntaxError(f"line {top[0].line}: a program takes no parameters")
        body = top[0].body
    functions: dict[str, FuncDef] = {}
    for f in _functions(body):
        if f.name in functions or f.name in builtins or f.name in PURE:
            raise UrSyntaxError(f"line {f.line}: {f.name} is defined twice or is a built-in")
        functions[f.name] = f
    names = _assigned(body) | _declared(body, "global")
    for f in functions.values():
        names |= _declared(f.body, "global")
    for f in functions.values():
        own = (_assigned(f.body) - names) | _declared(f.body, "local") | set(f.params)
        f.local_names = frozenset(own - _declared(f.body, "global"))
    program = Program(body, functions, frozenset(names))
    _check_body(program, body, frozenset(), builtins, in_loop=False)
    for f in functions.values():
        for d in f.defaults.values():
            _check_expr(program, d, frozenset(), builtins)
        _check_body(program, f.body, f.local_names, builtins, in_loop=False)
    return program


def _check_body(
    prog: Program,
    body: tuple[Any, ...],
    local: frozenset[str],
    builtins: dict[str, Builtin],
    in_loop: bool,
) -> None:
    for st in body:
        if isinstance(st, FuncDef):
            continue
        if isinstance(st, Simple) and st.word in ("break", "continue") and not in_loop:
            raise UrSyntaxError(f"line {st.line}: {st.word} outside a loop")
        if isinstance(st, If):
            for cond, arm in st.arms:
                _check_expr(prog, cond, local, builtins)
                _check_body(prog, arm, local, builtins, in_loop)
            _check_body(prog, st.orelse, local, builtins, in_loop)
        elif isinstance(st, While):
            _check_expr(prog, st.cond, local, builtins)
            _check_body(prog, st.body, local, builtins, in_loop=True)
        elif isinstance(st, Assign):
            if isinstance(st.target, Index):
                _check_expr(prog, st.target, local, builtins)
            _check_expr(prog, st.value, local, builtins)
        elif isinstance(st, ExprStmt):
            _check_expr(prog, st.expr, local, builtins)
        elif isinstance(st, Return):
            _check_expr(prog, st.value, local, builtins)
        elif isinstance(st, ThreadOp):
            _check_expr(prog, st.handle, local, builtins)


def _check_expr(prog: Program, e: Any, local: frozenset[str], builtins: dict[str, Builtin]) -> None:
    for node in _expressions(e):
        if isinstance(node, Name) and not (
            node.id in local or node.id in prog.globals or node.id in CONSTANTS
        ):
            raise UrSyntaxError(f"line {node.line}: variable {node.id!r} is not defined")
        if isinstance(node, RunExpr):
            f = prog.functions.get(node.thread)
            if f is None or f.kind != "thread":
                raise UrSyntaxError(f"line {node.line}: run {node.thread}(): no such thread")
        if isinstance(node, Call):
            _check_call(prog, node, builtins)


def _check_call(prog: Program, c: Call, builtins: dict[str, Builtin]) -> None:
    keys = tuple(k for k, _ in c.kwargs)
    f = prog.functions.get(c.name)
    if f is not None:
        if f.kind == "thread":
            raise UrSyntaxError(f"line {c.line}: {c.name} is a thread: start it with run")
        _bind(c.name, f.params, f.defaults, len(c.args), keys, c.line)
        return
    b = builtins.get(c.name) or PURE.get(c.name)
    if b is None:
        raise UrSyntaxError(f"line {c.line}: unknown function {c.name}()")
    _bind(c.name, b.params, b.defaults, len(c.args), keys, c.line)


# ====================================================================== robot records
@dataclass
class SearchRecord:
    """What the sensor callback was asked about one linear motion, and its answer.

    Attributes:
        start_m: ``(3,)`` TCP at the start of the motion, base frame, m.
        end_m: ``(3,)`` commanded TCP target, base frame, m.
        sensor_axis: ``(3,)`` the target pose's +z, base frame.
        neg_flank: the input was on at the start (the search looks for it going off).
        answer: the callback's answer: ``(3,)`` switching point (base, m) or a string.
        switch_m: distance from the start where the input switches, m, or ``None``.
    """

    start_m: np.ndarray
    end_m: np.ndarray
    sensor_axis: np.ndarray
    neg_flank: bool
    answer: Any
    switch_m: float | None


@dataclass
class Motion:
    """One commanded motion.

    Attributes:
        kind: ``"movej"``, ``"movel"`` or ``"movep"``.
        line: the program line that commanded it.
        thread: the name of the thread that commanded it (``"main"`` for the program);
            ``owner``: its number.
        target: the commanded pose or joint values (rad).
        start_T: ``(4, 4)`` TCP at the start, base frame, m (``None``: not known).
        end_T: ``(4, 4)`` commanded TCP target of a pose move, base frame, m; a joint move to
            joint values keeps ``start_T``.
        t_start: when it began, s; ``duration_s``: how long it takes when not stopped, s.
        linear: the TCP moves on a straight line (``movel``, ``movep``).
        stop_T: ``(4, 4)`` where the TCP stopped, base frame, m (``None`` while it runs).
        stopped: stopped early (``kill``, ``stopl``, ``stopj``); ``t_stop``: when it ended, s.
        search: what the sensor callback said about it, when the program watched the input.
    """

    kind: str
    line: int
    thread: str
    owner: int
    target: Any
    start_T: np.ndarray | None
    end_T: np.ndarray | None
    t_start: float
    duration_s: float
    linear: bool
    started_frame: int = 0
    stop_T: np.ndarray | None = None
    t_stop: float | None = None
    stopped: bool = False
    search: SearchRecord | None = None

    @property
    def length_m(self) -> float:
        """Straight-line length of a pose move, m (0 for joint values)."""
        if self.start_T is None or self.end_T is None:
            return 0.0
        return float(np.linalg.norm(self.end_T[:3, 3] - self.start_T[:3, 3]))

    @property
    def t_end(self) -> float:
        """When it ends (or ended), s."""
        return self.t_start + self.duration_s if self.t_stop is None else self.t_stop

    @property
    def start_m(self) -> np.ndarray | None:
        """``(3,)`` TCP at the start, base frame, m."""
        return None if self.start_T is None else self.start_T[:3, 3].copy()

    @property
    def stop_m(self) -> np.ndarray | None:
        """``(3,)`` where the TCP stopped, base frame, m."""
        return None if self.stop_T is None else self.stop_T[:3, 3].copy()


# ====================================================================== waits and threads
@dataclass(frozen=True)
class _Sync:
    pass


@dataclass(frozen=True)
class _Until:
    t: float


@dataclass(frozen=True)
class _OnMotion:
    motion: Motion


@dataclass(frozen=True)
class _OnThread:
    thread: _Thread


Gen = Generator[Any, None, Any]


@dataclass(eq=False)
class _Thread:
    number: int
    name: str
    gen: Gen
    wait: Any = None
    last_frame: int = -1
    done: bool = False


@dataclass
class _Scope:
    """The variables of one call of a function or thread (the program's are global)."""

    local_names: frozenset[str]
    values: dict[str, Any] = field(default_factory=dict)


# ====================================================================== the machine
class UrMachine:
    """Runs a URScript program against a simulated robot and ``search`` (module docstring).

    Args:
        text: the program text (``planner.export.export_files(job, "urscript")[".script"]``).
        search: the sensor callback ``search(start_m, end_m, sensor_axis, neg_flank)``.
        sensor_input: ``("standard" | "tool", n)``, the digital input of the sensor.
        rest_level: the sensor input's level with the TCP at rest at ``T_base_tcp`` (``(4, 4)``,
            m) after a joint move; ``None``: off.
        tcp_start: ``(4, 4)`` TCP at the start, base frame, m, or ``None`` (not known).
        cycle_s: poll every ``cycle_s`` seconds instead of jumping to the next event.
        inputs: ``{("standard" | "tool", n): level}`` of the other digital inputs (off).
        max_time_s: simulated time after which the run is an error, s.
        max_frames: control frames after which the run is an error.
        spin_limit: loop iterations without a wait after which the run is an error.

    Raises:
        UrSyntaxError: the program does not compile.
    """

    def __init__(
        self,
        text: str,
        search: SearchFn,
        *,
        sensor_input: tuple[str, int] = ("standard", 0),
        rest_level: Callable[[np.ndarray], bool] | None = None,
        tcp_start: np.ndarray | None = None,
        cycle_s: float | None = None,
        inputs: dict[tuple[str, int], bool] | None = None,
        max_time_s: float = 36_000.0,
        max_frames: int = 1_000_000,
        spin_limit: int = SPIN_LIMIT,
    ) -> None:
        self.builtins = self._machine_builtins()
        self.program = compile_program(text, self.builtins)
        self.search = search
        self.sensor_input = sensor_input
        self.rest_level = rest_level
        self.cycle_s = cycle_s
        self.inputs = dict(inputs or {})
        self.max_time_s = max_time_s
        self.max_frames = max_frames
        self.spin_limit = spin_limit
        self.clock_s = 0.0
        self.globals: dict[str, Any] = {}
        self.messages: list[str] = []
        self.motions: list[Motion] = []
        self.registers: dict[tuple[str, int], Any] = {}
        self.sockets: dict[str, list[str]] = {}
        self.tcp_offset = Pose((0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
        self.payload: tuple[float, list[float]] | None = None
        self.finished = False
        self.halted = False
        self._tcp: np.ndarray | None = None if tcp_start is None else np.array(tcp_start, float)
        self._active: Motion | None = None
        self._anchor_level = False
        self._since_anchor: list[Motion] = []
        self._threads: list[_Thread] = []
        self._current: _Thread | None = None
        self._frame = 0
        self._spins = 0
        self._line = 0

    # ------------------------------------------------------------------ public API
    def run(self) -> UrMachine:
        """Run the program to its end (or ``halt``).

        Raises:
            UrRuntimeError: the program failed; the message names the line.
        """
        main = self._start("main", self._program())
        while not main.done and not self.halted:
            self._run_frame()
            if main.done or self.halted:
                break
            self._advance_clock()
        for th in self._threads:  # the program's end stops every thread and motion
            if not th.done:
                self._stop_thread(th)
        if self._active is not None:
            self._stop_motion(self._active)
        self.finished = True
        return self

    @property
    def variables(self) -> dict[str, Any]:
        """The program's global variables (copies)."""
        return {k: _copy(v) for k, v in self.globals.items()}

    def measurements(self, prefix: str = "meas_") -> dict[str, Any]:
        """``{ID: value}`` of the global variables named ``<prefix><ID>``."""
        return {k[len(prefix) :]: _copy(v) for k, v in self.globals.items() if k.startswith(prefix)}

    def frame(self, name: str) -> np.ndarray:
        """``(4, 4)`` of the pose variable ``name`` (e.g. a work object), base frame, m."""
        value = self.globals.get(name)
        if not isinstance(value, Pose):
            raise KeyError(f"{name} is not a pose variable: {_text(value)}")
        return value.matrix()

    def call(self, name: str, *args: Any) -> Any:
        """The value of the program's function ``name`` called with ``args`` (URScript values:
        ``int``, ``float``, ``bool``, ``str``, lists, :class:`Pose`) on the globals as they
        stand (e.g. after :meth:`run`), as a ``def`` called from the program would compute it.
        For functions that only compute: one that waits (a motion, ``sync``, ``sleep``) or
        halts is an error here.

        Raises:
            KeyError: the program has no ``def`` of that name.
            UrSyntaxError: the arguments do not bind to its parameters.
            UrRuntimeError: it failed, waited or halted.
        """
        f = self.program.functions.get(name)
        if f is None or f.kind != "def":
            raise KeyError(f"the program has no function {name}()")
        _bind(name, f.params, f.defaults, len(args), (), f.line)
        gen = self._invoke(f, [_copy(a) for a in args], {})
        try:
            gen.send(None)
        except StopIteration as done:
            return done.value
        except _Halt:
            raise UrRuntimeError(f"{name}() halted the program") from None
        gen.close()
        raise UrRuntimeError(f"{name}() waits (a motion, sync or sleep): run it in the program")

    @property
    def searches(self) -> list[Motion]:
        """The motions the sensor callback was asked about, in order."""
        return [m for m in self.motions if m.search is not None]

    @property
    def tcp_T(self) -> np.ndarray | None:
        """``(4, 4)`` the TCP now, base frame, m (``None``: not known)."""
        return self._tcp_now()

    # ------------------------------------------------------------------ scheduler
    def _start(self, name: str, gen: Gen) -> _Thread:
        th = _Thread(len(self._threads), name, gen)
        self._threads.append(th)
        return th

    def _run_frame(self) -> None:
        self._frame += 1
        self._settle()
        k = 0
        while k < len(self._threads):  # threads started in this frame run in it too
            th = self._threads[k]
            k += 1
            if not th.done and self._ready(th):
                self._step(th)
                if self.halted:
                    return

    def _ready(self, th: _Thread, new_frame: bool = False) -> bool:
        w = th.wait
        if w is None:
            return True
        if isinstance(w, _Sync):
            return new_frame or th.last_frame < self._frame
        if isinstance(w, _Until):
            return self.clock_s >= w.t - EPS
        if isinstance(w, _OnMotion):
            return w.motion.stop_T is not None or self._active is not w.motion
        return w.thread.done

    def _step(self, th: _Thread) -> None:
        self._current, self._spins = th, 0
        try:
            th.wait = th.gen.send(None)
            th.last_frame = self._frame
        except StopIteration:
            th.done = True
        except _Halt:
            th.done = self.halted = True
        finally:
            self._current = None

    def _advance_clock(self) -> None:
        """Move the clock to the next frame: the next event, or one poll step."""
        live = [th for th in self._threads if not th.done]
        polling = any(isinstance(th.wait, _Sync) for th in live)
        times = (
            [self.clock_s]
            if any(
                self._ready(th, new_frame=True) and not isinstance(th.wait, _Sync) for th in live
            )
            else []
        )
        m = self._active
        if m is not None:
            times.append(m.t_end)
            if m.started_frame == self._frame:
                times.append(m.t_start)  # the motion begins: the pollers see it at once
            switch = self._switch_time(m)
            if switch is not None and switch > self.clock_s + EPS:
                times.append(switch)
        times += [th.wait.t for th in live if isinstance(th.wait, _Until)]
        if polling and (self.cycle_s is not None or not times):
            times.append(self.clock_s + (self.cycle_s or DEFAULT_CYCLE_S))
        if not times:
            raise UrRuntimeError(f"line {self._line}: every thread waits for ever (a join?)")
        self.clock_s = max(self.clock_s, min(times))
        if self.clock_s > self.max_time_s or self._frame >= self.max_frames:
            raise UrRuntimeError(
                f"line {self._line}: still running after {self.clock_s:g} s of robot time "
                f"and {self._frame} frames (limits {self.max_time_s:g} s, {self.max_frames})"
            )

    def _settle(self) -> None:
        """End the active motion when its time is up."""
        m = self._active
        if m is not None and self.clock_s >= m.t_start + m.duration_s - EPS:
            m.t_stop = m.t_start + m.duration_s
            m.stop_T = m.end_T if m.end_T is not None else m.start_T
            self._finish_motion(m)

    def _finish_motion(self, m: Motion) -> None:
        """``m`` has ended (``stop_T`` set; ``None`` for a joint move stopped half way)."""
        self._active = None
        self._tcp = None if m.stop_T is None else m.stop_T.copy()
        if not m.linear:  # the level after a joint move: the sensor at rest there
            T = self._tcp
            self._anchor_level = (
                bool(self.rest_level(T)) if self.rest_level and T is not None else False
            )
            self._since_anchor = []

    # ------------------------------------------------------------------ program and calls
    def _program(self) -> Gen:
        scope = _Scope(frozenset(), self.globals)
        try:
            yield from self._exec_block(self.program.body, scope)
        except _Return:
            return

    def _thread_body(self, f: FuncDef) -> Gen:
        try:
            yield from self._exec_block(f.body, _Scope(f.local_names))
        except _Return:
            return

    def _invoke(self, f: FuncDef, args: list[Any], kwargs: dict[str, Any]) -> Gen:
        scope = _Scope(f.local_names)
        for name, value in zip(f.params, args, strict=False):
            scope.values[name] = _copy(value)
        for name, value in kwargs.items():
            scope.values[name] = _copy(value)
        for name in f.params:
            if name not in scope.values:
                scope.values[name] = yield from self._eval(f.defaults[name], _Scope(frozenset()))
        try:
            yield from self._exec_block(f.body, scope)
        except _Return as ret:
            return _copy(ret.value)
        return None

    # ------------------------------------------------------------------ statements
    def _exec_block(self, body: tuple[Any, ...], scope: _Scope) -> Gen:
        for st in body:
            self._line = st.line
            yield from self._exec(st, scope)

    def _exec(self, st: Any, scope: _Scope) -> Gen:
        if isinstance(st, Assign):
            value = yield from self._eval(st.value, scope)
            yield from self._assign(st.target, value, scope)
        elif isinstance(st, ExprStmt):
            yield from self._eval(st.expr, scope)
        elif isinstance(st, If):
            yield from self._exec_if(st, scope)
        elif isinstance(st, While):
            yield from self._exec_while(st, scope)
        elif isinstance(st, Return):
            value = None if st.value is None else (yield from self._eval(st.value, scope))
            raise _Return(value)
        elif isinstance(st, ThreadOp):
            yield from self._thread_op(st, scope)
        elif isinstance(st, Simple):
            self._simple(st)
        elif not isinstance(st, FuncDef | Declare):
            raise UrRuntimeError(f"line {st.line}: cannot run {type(st).__name__}")

    def _simple(self, st: Simple) -> None:
        if st.word == "halt":
            raise _Halt()
        if st.word == "break":
            raise _Break()
        if st.word == "continue":
            raise _Continue()

    def _condition(self, e: Any, scope: _Scope, what: str) -> Gen:
        value = yield from self._eval(e, scope)
        if not isinstance(value, bool):
            raise UrRuntimeError(f"line {e.line}: {what} condition is {_type_name(value)}")
        return value

    def _exec_if(self, st: If, scope: _Scope) -> Gen:
        for cond, body in st.arms:
            if (yield from self._condition(cond, scope, "if")):
                yield from self._exec_block(body, scope)
                return
        yield from self._exec_block(st.orelse, scope)

    def _exec_while(self, st: While, scope: _Scope) -> Gen:
        while (yield from self._condition(st.cond, scope, "while")):
            self._spins += 1
            if self._spins > self.spin_limit:
                raise UrRuntimeError(
                    f"line {st.line}: the loop ran {self.spin_limit} times without waiting "
                    "(sync, sleep or a motion): the controller stops such a thread"
                )
            try:
                yield from self._exec_block(st.body, scope)
            except _Break:
                return
            except _Continue:
                continue

    def _thread_op(self, st: ThreadOp, scope: _Scope) -> Gen:
        handle = yield from self._eval(st.handle, scope)
        if not isinstance(handle, ThreadHandle):
            raise UrRuntimeError(f"line {st.line}: {st.op} of a {_type_name(handle)}")
        th = self._threads[handle.number]
        if th is self._current:
            raise UrRuntimeError(f"line {st.line}: a thread cannot {st.op} itself")
        if st.op == "join":
            if not th.done:
                yield _OnThread(th)
        elif not th.done:  # kill of a finished thread: nothing to do
            self._stop_thread(th)

    def _stop_thread(self, th: _Thread) -> None:
        if self._active is not None and self._active.owner == th.number:
            self._stop_motion(self._active)
        th.gen.close()
        th.done = True

    # ------------------------------------------------------------------ variables
    def _variables(self, name: str, scope: _Scope) -> dict[str, Any]:
        return scope.values if name in scope.local_names else self.globals

    def _read(self, e: Name, scope: _Scope) -> Any:
        env = self._variables(e.id, scope)
        if e.id in env:
            return env[e.id]
        if e.id in CONSTANTS and env is self.globals:
            return CONSTANTS[e.id]
        raise UrRuntimeError(f"line {e.line}: variable {e.id!r} is used before it is assigned")

    def _assign(self, target: Any, value: Any, scope: _Scope) -> Gen:
        if isinstance(target, Name):
            if target.id in CONSTANTS:
                raise UrRuntimeError(f"line {target.line}: {target.id} cannot be assigned")
            self._variables(target.id, scope)[target.id] = _copy(value)
            return
        container = yield from self._eval(target.target, scope)
        index = yield from self._eval(target.index, scope)
        updated = self._with_element(container, index, value, target.line)
        yield from self._assign(target.target, updated, scope)

    def _with_element(self, container: Any, index: Any, value: Any, line: int) -> Any:
        k = self._checked_index(container, index, line)
        if isinstance(container, Pose):
            if not isinstance(value, int | float) or isinstance(value, bool):
                raise UrRuntimeError(f"line {line}: a pose element must be a number")
            v = list(container.v)
            v[k] = float(value)
            return Pose(tuple(v))  # type: ignore[arg-type]
        out = list(container)
        out[k] = _copy(value)
        return out

    def _checked_index(self, container: Any, index: Any, line: int) -> int:
        if not isinstance(container, list | Pose):
            raise UrRuntimeError(f"line {line}: cannot index a {_type_name(container)}")
        if isinstance(index, bool) or not isinstance(index, int):
            raise UrRuntimeError(f"line {line}: an index must be an int, got {_type_name(index)}")
        size = len(container.v) if isinstance(container, Pose) else len(container)
        if not 0 <= index < size:
            raise UrRuntimeError(f"line {line}: index {index} out of range (size {size})")
        return index

    # ------------------------------------------------------------------ expressions
    def _eval(self, e: Any, scope: _Scope) -> Gen:
        if isinstance(e, Lit):
            return e.value
        if isinstance(e, Name):
            return self._read(e, scope)
        if isinstance(e, Call):
            return (yield from self._call(e, scope))
        if isinstance(e, Binary):
            return (yield from self._eval_binary(e, scope))
        if isinstance(e, Unary):
            return (yield from self._eval_unary(e, scope))
        if isinstance(e, Index):
            container = yield from self._eval(e.target, scope)
            index = yield from self._eval(e.index, scope)
            k = self._checked_index(container, index, e.line)
            return container.v[k] if isinstance(container, Pose) else _copy(container[k])
        if isinstance(e, ListExpr | PoseExpr):
            items = []
            for item in e.items:
                items.append((yield from self._eval(item, scope)))
            return items if isinstance(e, ListExpr) else self._pose_literal(items, e.line)
        if isinstance(e, RunExpr):
            f = self.program.functions[e.thread]
            th = self._start(e.thread, self._thread_body(f))
            return ThreadHandle(th.number, th.name)
        raise UrRuntimeError(f"line {e.line}: cannot evaluate {type(e).__name__}")

    def _pose_literal(self, items: list[Any], line: int) -> Pose:
        if len(items) != 6:
            raise UrRuntimeError(f"line {line}: a pose has 6 elements, got {len(items)}")
        try:
            return Pose(tuple(float(_num(x, "a pose element")) for x in items))  # type: ignore[arg-type]
        except _Problem as exc:
            raise UrRuntimeError(f"line {line}: {exc}") from None

    def _eval_binary(self, e: Binary, scope: _Scope) -> Gen:
        a = yield from self._eval(e.left, scope)
        if e.op in ("and", "or", "xor"):
            x = self._logic(a, e)
            if (e.op == "and" and not x) or (e.op == "or" and x):
                return x
            y = self._logic((yield from self._eval(e.right, scope)), e)
            return x != y if e.op == "xor" else y
        b = yield from self._eval(e.right, scope)
        try:
            return _binary(e.op, a, b)
        except _Problem as exc:
            raise UrRuntimeError(f"line {e.line}: {exc}") from None

    def _logic(self, value: Any, e: Binary) -> bool:
        if not isinstance(value, bool):
            raise UrRuntimeError(f"line {e.line}: {e.op} of a {_type_name(value)}")
        return value

    def _eval_unary(self, e: Unary, scope: _Scope) -> Gen:
        v = yield from self._eval(e.operand, scope)
        if e.op == "not":
            if not isinstance(v, bool):
                raise UrRuntimeError(f"line {e.line}: not of a {_type_name(v)}")
            return not v
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise UrRuntimeError(f"line {e.line}: {e.op} of a {_type_name(v)}")
        return -v if e.op == "-" else v

    def _call(self, e: Call, scope: _Scope) -> Gen:
        args = []
        for a in e.args:
            args.append((yield from self._eval(a, scope)))
        kwargs = {}
        for k, a in e.kwargs:
            kwargs[k] = yield from self._eval(a, scope)
        f = self.program.functions.get(e.name)
        if f is not None:
            return (yield from self._invoke(f, args, kwargs))
        b = self.builtins.get(e.name) or PURE[e.name]
        bound = dict(zip(b.params, args, strict=False)) | kwargs
        for name, default in b.defaults.items():
            bound.setdefault(name, default)
        try:
            if b.blocking:
                return (yield from b.fn(**bound))
            return b.fn(**bound)
        except _Problem as exc:
            raise UrRuntimeError(f"line {e.line}: {e.name}(): {exc}") from None

    # ------------------------------------------------------------------ machine built-ins
    def _machine_builtins(self) -> dict[str, Builtin]:
        def b(params: str, fn: Callable[..., Any], blocking: bool = False, **d: Any) -> Builtin:
            return Builtin(tuple(params.split()), d, fn, blocking)

        out = {
            "movej": b("q a v t r", self._movej, True, a=1.4, v=1.05, t=0, r=0),
            "movel": b("pose a v t r", self._movel, True, a=1.2, v=0.25, t=0, r=0),
            "movep": b("pose a v r", self._movep, True, a=1.2, v=0.25, r=0),
            "stopl": b("a aRot", self._stop_any, aRot=None),
            "stopj": b("a", self._stop_any),
            "sync": b("", self._sync, True),
            "sleep": b("t", self._sleep, True),
            "get_actual_tcp_pose": b("", self._get_tcp_pose),
            "get_target_tcp_pose": b("", self._get_tcp_pose),
            "get_tcp_offset": b("", lambda: self.tcp_offset),
            "set_tcp": b("pose", self._set_tcp),
            "set_payload": b("m cog", self._set_payload, cog=None),
            "get_standard_digital_in": b("n", lambda n: self._input("standard", n, 8)),
            "get_tool_digital_in": b("n", lambda n: self._input("tool", n, 2)),
            "get_digital_in": b("n", self._get_digital_in),
            "textmsg": b(
                "s1 s2", lambda s1, s2: self.messages.append(_text(s1) + _text(s2)), s2=""
            ),
            "popup": b(
                "s title warning error blocking",
                self._popup,
                title="Popup",
                warning=False,
                error=False,
                blocking=False,
            ),
            "socket_open": b("address port socket_name", self._socket_open, socket_name="socket_0"),
            "socket_close": b("socket_name", self._socket_close, socket_name="socket_0"),
            "socket_send_string": b("str socket_name", self._socket_send, socket_name="socket_0"),
            "socket_send_line": b(
                "str socket_name",
                lambda s, socket_name: self._socket_send(_text(s) + "\n", socket_name),
                socket_name="socket_0",
            ),
        }
        for kind, check in (("integer", _int), ("float", _num), ("boolean", _bool)):
            out[f"write_output_{kind}_register"] = b(
                "address value", self._register_writer(kind, check)
            )
        return out

    def _register_writer(self, kind: str, check: Callable[[Any, str], Any]) -> Callable[..., None]:
        def write(address: Any, value: Any) -> None:
            self.registers[(kind, _int(address, "address"))] = check(value, "value")

        return write

    def _popup(self, s: Any, title: Any, warning: Any, error: Any, blocking: Any) -> None:
        self.messages.append(f"popup {_text(title)}: {_text(s)}")

    def _socket_open(self, address: Any, port: Any, socket_name: Any) -> bool:
        _str(address, "address"), _int(port, "port")
        self.sockets.setdefault(_str(socket_name, "socket_name"), [])
        return True

    def _socket_close(self, socket_name: Any) -> None:
        self.sockets.pop(_str(socket_name, "socket_name"), None)

    def _socket_send(self, s: Any, socket_name: Any) -> bool:
        sent = self.sockets.get(_str(socket_name, "socket_name"))
        if sent is None:
            return False
        sent.append(_str(s, "str"))
        return True

    def _set_payload(self, m: Any, cog: Any) -> None:
        self.payload = (_num(m, "m"), [] if cog is None else _vector(cog, "cog", 3))

    def _set_tcp(self, pose: Any) -> None:
        new = _pose(pose, "pose")
        if self._active is not None:
            raise _Problem("set_tcp while the robot moves is not modelled")
        if self._tcp is not None:
            T_base_flange = self._tcp @ invert_transform(self.tcp_offset.matrix())
            self._tcp = T_base_flange @ new.matrix()
        self.tcp_offset = new

    def _get_tcp_pose(self) -> Pose:
        T = self._tcp_now()
        if T is None:
            raise _Problem("the TCP is not known (no pose move yet, or during a joint move)")
        return Pose.from_matrix(T)

    def _get_digital_in(self, n: Any) -> bool:
        k = _int(n, "n")
        return self._input("tool", k - 8, 2) if k >= 8 else self._input("standard", k, 8)

    def _input(self, kind: str, n: Any, count: int) -> bool:
        k = _int(n, "n")
        if not 0 <= k < count:
            raise _Problem(f"no {kind} digital input {k} (0..{count - 1})")
        if (kind, k) == tuple(self.sensor_input):
            return self._sensor_level()
        return bool(self.inputs.get((kind, k), False))

    def _sync(self) -> Gen:
        yield _Sync()

    def _sleep(self, t: Any) -> Gen:
        yield _Until(self.clock_s + max(0.0, _num(t, "t")))

    def _stop_any(self, **_: Any) -> None:
        if self._active is not None:
            self._stop_motion(self._active)

    # ------------------------------------------------------------------ motion
    def _movel(self, pose: Any, a: Any, v: Any, t: Any, r: Any) -> Gen:
        return (yield from self._linear("movel", pose, v, t))

    def _movep(self, pose: Any, a: Any, v: Any, r: Any) -> Gen:
        return (yield from self._linear("movep", pose, v, 0))

    def _linear(self, kind: str, pose: Any, v: Any, t: Any) -> Gen:
        target = _pose(pose, "pose")
        if self._tcp is None:
            raise _Problem(f"{kind} from an unknown TCP (no pose move before it)")
        end_T = target.matrix()
        length = float(np.linalg.norm(end_T[:3, 3] - self._tcp[:3, 3]))
        speed, duration = _num(v, "v"), _num(t, "t")
        if speed <= 0:
            raise _Problem(f"v must be > 0, got {speed}")
        m = self._begin(kind, target, end_T, duration if duration > 0 else length / speed, True)
        yield _OnMotion(m)

    def _movej(self, q: Any, a: Any, v: Any, t: Any, r: Any) -> Gen:
        duration = max(0.0, _num(t, "t"))
        if isinstance(q, Pose):
            end_T = q.matrix()
            if duration == 0 and self._tcp is not None:
                duration = float(np.linalg.norm(end_T[:3, 3] - self._tcp[:3, 3])) / 0.25
            m = self._begin("movej", q, end_T, duration, False)
        else:
            m = self._begin("movej", _vector(q, "q", 6), None, duration, False)
        yield _OnMotion(m)

    def _begin(
        self, kind: str, target: Any, end_T: np.ndarray | None, duration: float, linear: bool
    ) -> Motion:
        if self._active is not None:
            raise _Problem(
                f"{kind}: another motion (line {self._active.line}) still runs in thread "
                f"{self._active.thread}"
            )
        th = self._current
        m = Motion(
            kind=kind,
            line=self._line,
            thread="main" if th is None else th.name,
            owner=0 if th is None else th.number,
            target=target,
            start_T=None if self._tcp is None else self._tcp.copy(),
            end_T=end_T,
            t_start=self.clock_s,
            duration_s=duration,
            linear=linear,
            started_frame=self._frame,
        )
        self.motions.append(m)
        self._active = m
        if linear:
            self._since_anchor.append(m)
        return m

    def _stop_motion(self, m: Motion) -> None:
        """Stop ``m`` where it is now (ideal stop)."""
        m.stop_T = self._pose_at(m, self.clock_s)
        m.t_stop, m.stopped = self.clock_s, True
        self._finish_motion(m)

    def _travel_m(self, m: Motion, t: float) -> float:
        """Distance the TCP has moved along ``m`` at time ``t``, m."""
        length = m.length_m
        if m.stop_T is not None and m.start_T is not None:
            return float(np.linalg.norm(m.stop_T[:3, 3] - m.start_T[:3, 3]))
        s = length if m.duration_s <= 0 else length * min(1.0, (t - m.t_start) / m.duration_s)
        switch = None if m.search is None else m.search.switch_m
        if switch is not None and abs(s - switch) < 1e-9:
            s = switch  # at the switching instant: exactly where it fired
        return max(0.0, s)

    def _pose_at(self, m: Motion, t: float) -> np.ndarray | None:
        if m.start_T is None or m.end_T is None:
            return m.start_T
        if not m.linear:
            return None  # mid joint move: the path is not modelled
        length = m.length_m
        s = self._travel_m(m, t)
        f = 1.0 if length <= EPS else s / length
        if length <= EPS and m.duration_s > 0:
            f = min(1.0, (t - m.t_start) / m.duration_s)
        R0 = m.start_T[:3, :3]
        R = R0 @ matrix_from_rotvec(f * rotvec_from_matrix(R0.T @ m.end_T[:3, :3]))
        p = m.start_T[:3, 3] + f * (m.end_T[:3, 3] - m.start_T[:3, 3])
        return make_transform(R, p)

    def _tcp_now(self) -> np.ndarray | None:
        m = self._active
        if m is None:
            return None if self._tcp is None else self._tcp.copy()
        return self._pose_at(m, self.clock_s)

    # ------------------------------------------------------------------ sensor
    def _sensor_level(self) -> bool:
        """The sensor input now: the level at the last joint move, switched by each linear
        motion since (asking the callback about each one the first time)."""
        level = self._anchor_level
        for m in self._since_anchor:
            self._resolve(m, level)
            switch = None if m.search is None else m.search.switch_m
            if switch is not None and self._travel_m(m, self.clock_s) >= switch - 1e-9:
                level = not level
        return level

    def _resolve(self, m: Motion, level: bool) -> None:
        """Ask the callback once about ``m`` (started with the input at ``level``)."""
        if m.search is not None or m.length_m <= EPS:
            return
        assert m.start_T is not None and m.end_T is not None
        start, end = m.start_T[:3, 3].copy(), m.end_T[:3, 3].copy()
        axis = m.end_T[:3, 2].copy()
        answer = self.search(start.copy(), end.copy(), axis.copy(), level)
        m.search = SearchRecord(start, end, axis, level, answer, self._switch_m(m, answer))

    def _switch_m(self, m: Motion, answer: Any) -> float | None:
        if isinstance(answer, str):
            return 0.0 if answer == AT_START else None
        hit = np.asarray(answer, dtype=float)
        assert m.start_T is not None and m.end_T is not None
        start, end = m.start_T[:3, 3], m.end_T[:3, 3]
        u = (end - start) / m.length_m
        d = float((hit - start) @ u)
        off = float(np.linalg.norm(hit - start - d * u))
        if hit.shape != (3,) or not np.all(np.isfinite(hit)) or off > 1e-9:
            raise UrRuntimeError(
                f"line {m.line}: the search callback answered {answer!r}, not a point on the "
                f"commanded line ({off:.3g} m off)"
            )
        if not -1e-9 <= d <= m.length_m + 1e-9:
            raise UrRuntimeError(
                f"line {m.line}: the search callback's point lies {d:.6g} m along a "
                f"{m.length_m:.6g} m line"
            )
        return min(max(d, 0.0), m.length_m)

    def _switch_time(self, m: Motion) -> float | None:
        if m.search is None or m.search.switch_m is None or m.length_m <= EPS:
            return None
        return m.t_start + m.duration_s * m.search.switch_m / m.length_m
