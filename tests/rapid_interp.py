"""A small interpreter for the subset of ABB RAPID that ``planner.export.rapid`` emits.

It runs a generated module against a simulated robot so tests can check what the program
*does*, not only what it says: records (``num``, ``bool``, ``string``, ``pos``, ``orient``,
``pose``, ``confdata``, ``robtarget``, ``wobjdata``, ``tooldata``, ``speeddata``...), arrays
``x{n}``, components, assignments, arithmetic (``pos`` + - and scaling), comparisons and logic,
``IF``/``ELSEIF``/``ELSE`` (block and one-line), ``FOR``, ``PROC``/``FUNC`` with ``ERROR``
handlers, ``RETURN``/``RAISE``/``EXIT``/``Stop`` and the functions ``PoseVect``, ``PoseInv``,
``PoseMult``, ``CrossProd``, ``DotProd``, ``VectMagn``, ``NOrient``, ``OrientZYX``, ``ATan2``,
``Sqrt``, ``Sin``, ``Cos``, ``Tan``, ``Abs``, ``NumToStr`` (angles in degrees, as RAPID).

Motion: ``MoveJ``/``MoveL`` put the sensor TCP at the target (``MoveAbsJ``, a via, is recorded
and leaves it: no FK here); ``SearchL`` asks a callback
``search(start_m, end_m, sensor_axis, neg_flank) -> (3,) hit or "ERR_..."`` (base frame,
metres) and stores the hit in the result robtarget in the work object, as the controller does.
The world frame is the robot base. One statement per line, as the generator writes.

Arithmetic is float64 unless ``Machine(..., num_float32=True)``: then, as on a controller whose
``num`` is an IEEE 754 single (RAPID's ``num`` holds integers exactly only up to 8388608, the
24-bit significand of a single), every ``num`` value is rounded to float32 where it is made or
stored: literals, the result of each ``+ - * /`` (so scalar arithmetic is exactly single
precision), the result of each built-in function (components of a ``pos``, ``orient`` or
``pose`` result too; inside a built-in the maths is float64, how the controller computes there
is not documented) and every value stored in a variable, a parameter or a record component
(the hit ``SearchL`` stores included). Motion targets are taken from the stored values.
"""

from __future__ import annotations

import contextlib
import copy
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from calib.frames import (
    make_transform,
    matrix_from_quat_wxyz,
    matrix_from_tait_bryan_zyx,
    quat_wxyz_from_matrix,
)

SCHEMA: dict[str, list[tuple[str, str]]] = {
    "pos": [("x", "num"), ("y", "num"), ("z", "num")],
    "orient": [("q1", "num"), ("q2", "num"), ("q3", "num"), ("q4", "num")],
    "pose": [("trans", "pos"), ("rot", "orient")],
    "confdata": [("cf1", "num"), ("cf4", "num"), ("cf6", "num"), ("cfx", "num")],
    "extjoint": [(f"eax_{c}", "num") for c in "abcdef"],
    "robtarget": [
        ("trans", "pos"),
        ("rot", "orient"),
        ("robconf", "confdata"),
        ("extax", "extjoint"),
    ],
    "wobjdata": [
        ("robhold", "bool"),
        ("ufprog", "bool"),
        ("ufmec", "string"),
        ("uframe", "pose"),
        ("oframe", "pose"),
    ],
    "loaddata": [
        ("mass", "num"),
        ("cog", "pos"),
        ("aom", "orient"),
        ("ix", "num"),
        ("iy", "num"),
        ("iz", "num"),
    ],
    "tooldata": [("robhold", "bool"), ("tframe", "pose"), ("tload", "loaddata")],
    "speeddata": [("v_tcp", "num"), ("v_ori", "num"), ("v_leax", "num"), ("v_reax", "num")],
}
ERRNOS = {"ERR_WHLSEARCH": 1, "ERR_SIGSUPSEARCH": 2}
TOKEN = re.compile(
    r'\s*(?:(?P<num>\d+(?:\.\d*)?(?:[Ee][+-]?\d+)?)|(?P<str>"(?:[^"]|"")*")'
    r"|(?P<id>[A-Za-z_]\w*)|(?P<op>:=|<>|<=|>=|[-+*/(),\[\]{}.=<>;\\]))"
)


class RapidError(Exception):
    """A RAPID run-time error with its ``ERRNO``."""

    def __init__(self, errno: int) -> None:
        super().__init__(errno)
        self.errno = errno


class ProgramExit(Exception):
    """``EXIT`` or ``Stop``: the program ended."""


class _Return(Exception):
    def __init__(self, value: Any) -> None:
        self.value = value


@dataclass
class Rec:
    """A record value: its type name and its components."""

    type: str
    f: dict[str, Any]


def tokenize(line: str) -> list[tuple[str, str]]:
    """``[(kind, text)]`` of one line; kind is num, str, id or op."""
    out, pos = [], 0
    line = line.rstrip()
    while pos < len(line):
        m = TOKEN.match(line, pos)
        if not m or m.end() == pos:
            raise SyntaxError(f"cannot tokenize {line[pos:]!r}")
        pos = m.end()
        kind = m.lastgroup
        out.append((kind, m.group(kind)))
    return out


def coerce(value: Any, typ: str) -> Any:
    """``value`` (aggregate list, record, scalar) as a value of RAPID type ``typ``."""
    if typ in SCHEMA:
        if isinstance(value, Rec):
            if value.type != typ:
                raise TypeError(f"{value.type} is not {typ}")
            return copy.deepcopy(value)
        fields = SCHEMA[typ]
        if not isinstance(value, list) or len(value) != len(fields):
            raise TypeError(f"{value!r} is not a {typ}")
        return Rec(typ, {n: coerce(v, t) for (n, t), v in zip(fields, value, strict=True)})
    if typ == "num":
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise TypeError(f"{value!r} is not a num")
        return float(value)
    if typ == "bool" and not isinstance(value, bool):
        raise TypeError(f"{value!r} is not a bool")
    if typ == "string" and not isinstance(value, str):
        raise TypeError(f"{value!r} is not a string")
    return value


def f32(x: float) -> float:
    """``x`` rounded to the nearest IEEE 754 single (a RAPID ``num`` on the controller)."""
    return float(np.float32(x))


def round_num(value: Any) -> Any:
    """``value`` with every ``num`` in it (a float, the float components of a record, the
    elements of a list) rounded to single precision; records are rounded in place."""
    if isinstance(value, float):
        return f32(value)
    if isinstance(value, Rec):
        for k, v in value.f.items():
            value.f[k] = round_num(v)
        return value
    if isinstance(value, list):
        return [round_num(v) for v in value]
    return value


def _vec(p: Any) -> np.ndarray:
    if isinstance(p, list):
        p = coerce(p, "pos")
    if not (isinstance(p, Rec) and p.type == "pos"):
        raise TypeError(f"{p!r} is not a pos")
    return np.array([p.f["x"], p.f["y"], p.f["z"]])


def _pos(v: np.ndarray) -> Rec:
    return Rec("pos", {"x": float(v[0]), "y": float(v[1]), "z": float(v[2])})


def _rot(o: Rec) -> np.ndarray:
    q = np.array([o.f[k] for k in ("q1", "q2", "q3", "q4")])
    return matrix_from_quat_wxyz(q / np.linalg.norm(q))


def _orient(R: np.ndarray) -> Rec:
    return Rec("orient", dict(zip(("q1", "q2", "q3", "q4"), map(float, quat_wxyz_from_matrix(R)))))


def pose_matrix(p: Rec) -> np.ndarray:
    """``(4, 4)`` of a pose (or robtarget) record, translation in mm."""
    return make_transform(_rot(p.f["rot"]), _vec(p.f["trans"]))


def _pose(T: np.ndarray) -> Rec:
    return Rec("pose", {"trans": _pos(T[:3, 3]), "rot": _orient(T[:3, :3])})


def _arith(op: str, a: Any, b: Any) -> Any:
    if isinstance(a, list):
        a = coerce(a, "pos")
    if isinstance(b, list):
        b = coerce(b, "pos")
    if isinstance(a, float | int) and isinstance(b, float | int):
        if op == "/":
            return a / b
        return {"+": a + b, "-": a - b, "*": a * b}[op]
    if isinstance(a, str) and isinstance(b, str) and op == "+":
        return a + b
    if op in "+-" and isinstance(a, Rec) and isinstance(b, Rec):
        return _pos(_vec(a) + _vec(b) if op == "+" else _vec(a) - _vec(b))
    if op == "*" and isinstance(a, float | int) and isinstance(b, Rec):
        return _pos(a * _vec(b))
    if op == "*" and isinstance(a, Rec) and isinstance(b, float | int):
        return _pos(b * _vec(a))
    raise TypeError(f"no operator {op} for {a!r} and {b!r}")


def _deg(x: float) -> float:
    return math.degrees(x)


BUILTINS: dict[str, Callable[..., Any]] = {
    "PoseVect": lambda p, v: _pos(pose_matrix(p)[:3, :3] @ _vec(v) + pose_matrix(p)[:3, 3]),
    "PoseInv": lambda p: _pose(np.linalg.inv(pose_matrix(p))),
    "PoseMult": lambda p, q: _pose(pose_matrix(p) @ pose_matrix(q)),
    "CrossProd": lambda a, b: _pos(np.cross(_vec(a), _vec(b))),
    "DotProd": lambda a, b: float(_vec(a) @ _vec(b)),
    "VectMagn": lambda a: float(np.linalg.norm(_vec(a))),
    "NOrient": lambda o: _orient(_rot(o)),
    "OrientZYX": lambda z, y, x: _orient(
        matrix_from_tait_bryan_zyx(math.radians(z), math.radians(y), math.radians(x))
    ),
    "ATan2": lambda y, x: _deg(math.atan2(y, x)),
    "Sqrt": math.sqrt,
    "Sin": lambda a: math.sin(math.radians(a)),
    "Cos": lambda a: math.cos(math.radians(a)),
    "Tan": lambda a: math.tan(math.radians(a)),
    "Abs": abs,
    "NumToStr": lambda v, d: f"{v:.{int(d)}f}",
}


# ---------------------------------------------------------------- parsing
@dataclass
class Routine:
    """A PROC or FUNC."""

    name: str
    params: list[tuple[str, str]]
    body: list[Any] = field(default_factory=list)
    handler: list[Any] | None = None


class _Parser:
    """Expressions and statements of one line's tokens."""

    def __init__(self, toks: list[tuple[str, str]]) -> None:
        self.t, self.i = toks, 0

    def peek(self, k: int = 0) -> str | None:
        j = self.i + k
        return self.t[j][1] if j < len(self.t) else None

    def take(self, want: str | None = None) -> str:
        _kind, text = self.t[self.i]
        if want is not None and text.upper() != want.upper():
            raise SyntaxError(f"expected {want!r}, got {text!r}")
        self.i += 1
        return text

    def done(self) -> bool:
        return self.i >= len(self.t) or self.peek() == ";"

    # expressions: ("num", v) ("str", s) ("var", name) ("field", e, f) ("index", e, i)
    # ("call", name, args) ("agg", items) ("bin", op, a, b) ("not", e) ("neg", e)
    def expr(self) -> Any:
        e = self.and_()
        while (self.peek() or "").upper() == "OR":
            self.take()
            e = ("bin", "OR", e, self.and_())
        return e

    def and_(self) -> Any:
        e = self.not_()
        while (self.peek() or "").upper() == "AND":
            self.take()
            e = ("bin", "AND", e, self.not_())
        return e

    def not_(self) -> Any:
        if (self.peek() or "").upper() == "NOT":
            self.take()
            return ("not", self.not_())
        return self.cmp()

    def cmp(self) -> Any:
        e = self.add()
        while self.peek() in ("=", "<>", "<", ">", "<=", ">="):
            e = ("bin", self.take(), e, self.add())
        return e

    def add(self) -> Any:
        e = self.mul()
        while self.peek() in ("+", "-"):
            e = ("bin", self.take(), e, self.mul())
        return e

    def mul(self) -> Any:
        e = self.unary()
        while self.peek() in ("*", "/"):
            e = ("bin", self.take(), e, self.unary())
        return e

    def unary(self) -> Any:
        if self.peek() == "-":
            self.take()
            return ("neg", self.unary())
        return self.postfix()

    def postfix(self) -> Any:
        e = self.primary()
        while self.peek() in (".", "{"):
            if self.take() == ".":
                e = ("field", e, self.take())
            else:
                e = ("index", e, self.expr())
                self.take("}")
        return e

    def primary(self) -> Any:
        kind, text = self.t[self.i]
        self.i += 1
        if kind == "num":
            return ("num", float(text))
        if kind == "str":
            return ("str", text[1:-1].replace('""', '"'))
        if text == "(":
            e = self.expr()
            self.take(")")
            return e
        if text == "[":
            items = [self.expr()]
            while self.peek() == ",":
                self.take()
                items.append(self.expr())
            self.take("]")
            return ("agg", items)
        if kind == "id":
            if text.upper() in ("TRUE", "FALSE"):
                return ("bool", text.upper() == "TRUE")
            if self.peek() == "(":
                self.take()
                args = []
                if self.peek() != ")":
                    args.append(self.expr())
                    while self.peek() == ",":
                        self.take()
                        args.append(self.expr())
                self.take(")")
                return ("call", text, args)
            return ("var", text)
        raise SyntaxError(f"unexpected {text!r}")

    def call_args(self) -> list[tuple[str | None, Any]]:
        """``[(switch name or None, expr or None)]`` of a procedure call."""
        args: list[tuple[str | None, Any]] = []
        while not self.done():
            if self.peek() == ",":
                self.take()
                continue
            if self.peek() == "\\":
                self.take()
                name = self.take()
                val = None
                if self.peek() == ":=":
                    self.take()
                    val = self.expr()
                args.append((name, val))
                continue
            args.append((None, self.expr()))
        return args

    def statement(self) -> Any:
        head = self.peek()
        up = (head or "").upper()
        if up == "RETURN":
            self.take()
            return ("return", None if self.done() else self.expr())
        if up in ("EXIT", "RAISE"):
            return (up.lower(),)
        if up == "IF":  # one-line IF
            self.take()
            cond = self.expr()
            return ("if", [(cond, [self.statement()])], [])
        start = self.i
        if self.t[self.i][0] == "id":
            target = self.postfix()
            if self.peek() == ":=":
                self.take()
                return ("assign", target, self.expr())
        self.i = start
        name = self.take()
        return ("pcall", name, self.call_args())


def _strip_comment(line: str) -> str:
    out, in_str = [], False
    for ch in line:
        if ch == '"':
            in_str = not in_str
        if ch == "!" and not in_str:
            break
        out.append(ch)
    return "".join(out).strip()


def parse_module(text: str) -> tuple[list[Any], dict[str, Routine]]:
    """``(global declarations, routines)`` of a module's text."""
    lines = [s for s in (_strip_comment(raw) for raw in text.splitlines()) if s]
    decls: list[Any] = []
    routines: dict[str, Routine] = {}
    i = 0

    def block(stop: tuple[str, ...]) -> tuple[list[Any], str]:
        nonlocal i
        body: list[Any] = []
        while i < len(lines):
            line = lines[i]
            word = line.split("(")[0].split()[0].upper().rstrip(";")
            if word in stop:
                return body, word
            i += 1
            if word == "IF" and line.endswith("THEN"):
                cond = _Parser(tokenize(line[2:-4])).expr()
                arms, other = [], []
                then, end = block(("ELSEIF", "ELSE", "ENDIF"))
                arms.append((cond, then))
                while end == "ELSEIF":
                    c = _Parser(tokenize(lines[i][6:-4])).expr()
                    i += 1
                    then, end = block(("ELSEIF", "ELSE", "ENDIF"))
                    arms.append((c, then))
                if end == "ELSE":
                    i += 1
                    other, end = block(("ENDIF",))
                i += 1
                body.append(("if", arms, other))
            elif word == "FOR":
                m = re.match(r"FOR (\w+) FROM (.+) TO (.+) DO$", line)
                assert m, line
                lo = _Parser(tokenize(m.group(2))).expr()
                hi = _Parser(tokenize(m.group(3))).expr()
                inner, _ = block(("ENDFOR",))
                i += 1
                body.append(("for", m.group(1), lo, hi, inner))
            elif word in ("VAR", "PERS", "CONST"):
                body.append(_decl(line))
            else:
                body.append(_Parser(tokenize(line)).statement())
        raise SyntaxError(f"missing {stop}")

    while i < len(lines):
        line = lines[i]
        word = line.split()[0].upper()
        if word in ("MODULE", "ENDMODULE"):
            i += 1
        elif word in ("VAR", "PERS", "CONST"):
            decls.append(_decl(line))
            i += 1
        elif word in ("PROC", "FUNC"):
            m = re.match(r"(?:PROC|FUNC \w+) (\w+)\((.*)\)$", line)
            assert m, line
            params = [tuple(p.split()) for p in m.group(2).split(",") if p]
            r = Routine(m.group(1), [(t, n) for t, n in params])  # type: ignore[misc]
            i += 1
            end_word = "ENDPROC" if word == "PROC" else "ENDFUNC"
            r.body, end = block(("ERROR", end_word))
            if end == "ERROR":
                i += 1
                r.handler, _ = block((end_word,))
            i += 1
            routines[r.name] = r
        else:
            raise SyntaxError(f"unexpected line {line!r}")
    return decls, routines


def _decl(line: str) -> Any:
    m = re.match(r"(VAR|PERS|CONST) (\w+) (\w+)(?:\{(\d+)\})?(?::=(.*))?;$", line)
    if not m:
        raise SyntaxError(f"bad declaration {line!r}")
    init = _Parser(tokenize(m.group(5))).expr() if m.group(5) else None
    size = int(m.group(4)) if m.group(4) else None
    return ("decl", m.group(2), m.group(3), size, init)


# ---------------------------------------------------------------- running
SearchFn = Callable[[np.ndarray, np.ndarray, np.ndarray, bool], "np.ndarray | str"]


@dataclass
class Motion:
    """One commanded motion: ``kind`` MoveJ/MoveL/SearchL, TCP start and target, base, m."""

    kind: str
    start_m: np.ndarray | None
    target_m: np.ndarray
    neg_flank: bool = False


class Machine:
    """Runs a parsed module against ``search``."""

    def __init__(self, text: str, search: SearchFn, *, num_float32: bool = False) -> None:
        self.decls, self.routines = parse_module(text)
        self.search = search
        #: every ``num`` made or stored is rounded to single precision (module docstring)
        self.num_float32 = num_float32
        self.globals: dict[str, Any] = {}
        self.types: dict[str, str] = {}
        self.tcp_m: np.ndarray | None = None
        self.motions: list[Motion] = []
        self.tp: list[str] = []
        self.files: dict[str, str] = {}
        self._open: str | None = None
        for d in self.decls:
            self._declare(d, self.globals, self.types, [])

    def _declare(self, d: Any, env: dict, types: dict, scopes: list) -> None:
        _, typ, name, size, init = d
        types[name] = typ
        if size is not None:
            vals = self.eval(init, scopes) if init else [self._default(typ)] * size
            env[name] = [self._coerce(v, typ) for v in vals]
        else:
            env[name] = self._coerce(self.eval(init, scopes), typ) if init else self._default(typ)

    def _coerce(self, value: Any, typ: str) -> Any:
        """:func:`coerce`, then rounded to single precision when :attr:`num_float32`."""
        out = coerce(value, typ)
        return round_num(out) if self.num_float32 else out

    def _num(self, value: Any) -> Any:
        """A value just made: rounded to single precision when :attr:`num_float32`."""
        return round_num(value) if self.num_float32 else value

    def _default(self, typ: str) -> Any:
        if typ in SCHEMA:
            return Rec(typ, {n: self._default(t) for n, t in SCHEMA[typ]})
        return {"num": 0.0, "bool": False, "string": ""}.get(typ)

    # -- values
    def _scope_of(self, name: str, scopes: list) -> tuple[dict, dict]:
        for env, types in reversed(scopes):
            if name in env:
                return env, types
        if name in self.globals:
            return self.globals, self.types
        raise NameError(name)

    def eval(self, e: Any, scopes: list) -> Any:
        k = e[0]
        if k == "num":
            return self._num(e[1])
        if k in ("str", "bool"):
            return e[1]
        if k == "var":
            if e[1] in ERRNOS:
                return ERRNOS[e[1]]
            env, _ = self._scope_of(e[1], scopes)
            return env[e[1]]
        if k == "field":
            return self.eval(e[1], scopes).f[e[2]]
        if k == "index":
            return self.eval(e[1], scopes)[int(self.eval(e[2], scopes)) - 1]
        if k == "agg":
            return [self.eval(x, scopes) for x in e[1]]
        if k == "neg":
            v = self.eval(e[1], scopes)
            return -v if isinstance(v, float | int) else self._num(_arith("*", -1.0, v))
        if k == "not":
            return not self.eval(e[1], scopes)
        if k == "bin":
            a, b = self.eval(e[2], scopes), self.eval(e[3], scopes)
            op = e[1]
            if op == "AND":
                return a and b
            if op == "OR":
                return a or b
            if op in ("=", "<>", "<", ">", "<=", ">="):
                return {
                    "=": a == b,
                    "<>": a != b,
                    "<": a < b,
                    ">": a > b,
                    "<=": a <= b,
                    ">=": a >= b,
                }[op]
            return self._num(_arith(op, a, b))
        if k == "call":
            args = [self.eval(a, scopes) for a in e[2]]
            if e[1] in BUILTINS:
                return self._num(BUILTINS[e[1]](*args))
            return self.call(e[1], args)
        raise ValueError(f"cannot evaluate {e!r}")

    def _assign(self, target: Any, value: Any, scopes: list) -> None:
        path: list[Any] = []
        while target[0] != "var":
            path.append(target)
            target = target[1]
        env, types = self._scope_of(target[1], scopes)
        typ = types[target[1]]
        if not path:
            env[target[1]] = self._coerce(value, typ)
            return
        path.reverse()
        holder: Any = env
        key: Any = target[1]
        for step in path:
            obj = holder[key]
            if step[0] == "index":
                holder, key = obj, int(self.eval(step[2], scopes)) - 1
            else:
                typ = dict(SCHEMA[obj.type])[step[2]]
                holder, key = obj.f, step[2]
        holder[key] = self._coerce(value, typ)

    # -- statements
    def run(self, body: list, scopes: list) -> None:
        for s in body:
            k = s[0]
            if k == "decl":
                self._declare(s, scopes[-1][0], scopes[-1][1], scopes)
            elif k == "assign":
                self._assign(s[1], self.eval(s[2], scopes), scopes)
            elif k == "if":
                for cond, then in s[1]:
                    if self.eval(cond, scopes):
                        self.run(then, scopes)
                        break
                else:
                    self.run(s[2], scopes)
            elif k == "for":
                env = {s[1]: 0.0}
                scopes.append((env, {s[1]: "num"}))
                lo, hi = int(self.eval(s[2], scopes)), int(self.eval(s[3], scopes))
                for v in range(lo, hi + 1):
                    env[s[1]] = float(v)
                    self.run(s[4], scopes)
                scopes.pop()
            elif k == "return":
                raise _Return(None if s[1] is None else self.eval(s[1], scopes))
            elif k == "exit":
                raise ProgramExit()
            elif k == "raise":
                raise RapidError(self.globals["ERRNO"])
            elif k == "pcall":
                self._pcall(s[1], s[2], scopes)
            else:
                raise ValueError(f"unknown statement {s!r}")

    def call(self, name: str, args: list) -> Any:
        r = self.routines[name]
        env = {n: self._coerce(a, t) for (t, n), a in zip(r.params, args, strict=True)}
        scopes = [(env, {n: t for t, n in r.params})]
        try:
            try:
                self.run(r.body, scopes)
            except RapidError as err:
                if r.handler is None:
                    raise
                self.globals["ERRNO"] = err.errno
                self.run(r.handler, scopes)
        except _Return as ret:
            return ret.value
        return None

    def _pcall(self, name: str, args: list, scopes: list) -> None:
        pos = [a for sw, a in args if sw is None]
        sw = {s: a for s, a in args if s is not None}
        if name in self.routines:
            self.call(name, [self.eval(a, scopes) for a in pos])
        elif name in ("MoveJ", "MoveL"):
            T = self._target_m(self.eval(pos[0], scopes), self.eval(sw["WObj"], scopes))
            self.motions.append(Motion(name, self.tcp_m, T[:3, 3]))
            self.tcp_m = T[:3, 3]
        elif name == "MoveAbsJ":  # a via: joint values (no FK here); the TCP is unknown until
            self.eval(pos[0], scopes)  # the next Cartesian move, which every via precedes
            self.motions.append(Motion(name, self.tcp_m, self.tcp_m))
        elif name == "SearchL":
            self._searchl(pos, sw, scopes)
        elif name in ("ConfJ", "ConfL"):
            pass
        elif name == "TPWrite":
            self.tp.append(self.eval(pos[0], scopes))
        elif name == "Open":
            self._open = str(self.eval(sw["File"], scopes))
            self.files[self._open] = ""
        elif name == "Write":
            assert self._open is not None
            text = self.eval(pos[1], scopes)
            self.files[self._open] += text + ("" if "NoNewLine" in sw else "\n")
        elif name == "Close":
            self._open = None
        elif name == "Stop":
            raise ProgramExit()
        else:
            raise NameError(f"unknown procedure {name}")

    def _target_m(self, target: Rec, wobj: Rec) -> np.ndarray:
        T_base_wobj = pose_matrix(wobj.f["uframe"]) @ pose_matrix(wobj.f["oframe"])
        T = T_base_wobj @ pose_matrix(target)
        T[:3, 3] /= 1000.0
        return T

    def _searchl(self, pos: list, sw: dict, scopes: list) -> None:
        signal, result, target, _speed, _tool = pos
        assert signal == ("var", "diSensor") and "SStop" in sw
        wobj = self.eval(sw["WObj"], scopes)
        T = self._target_m(self.eval(target, scopes), wobj)
        start = self.tcp_m
        assert start is not None, "SearchL before any move"
        self.motions.append(Motion("SearchL", start, T[:3, 3], "NegFlank" in sw))
        hit = self.search(start, T[:3, 3], T[:3, 2], "NegFlank" in sw)
        if isinstance(hit, str):
            self.tcp_m = T[:3, 3]
            raise RapidError(ERRNOS[hit])
        self.tcp_m = np.asarray(hit, float)
        T_base_wobj = pose_matrix(wobj.f["uframe"]) @ pose_matrix(wobj.f["oframe"])
        p_w = np.linalg.solve(T_base_wobj, np.append(self.tcp_m * 1000.0, 1.0))[:3]
        rec = self._coerce(self.eval(target, scopes), "robtarget")
        rec.f["trans"] = _pos(p_w)
        self._assign(result, rec, scopes)

    def main(self) -> None:
        """Run ``main`` to its end (or ``EXIT``)."""
        with contextlib.suppress(ProgramExit):
            self.call("main", [])

    def wobj_matrix_m(self, name: str) -> np.ndarray:
        """``(4, 4)`` ``uframe * oframe`` of a wobjdata variable, metres."""
        w = self.globals[name]
        T = pose_matrix(w.f["uframe"]) @ pose_matrix(w.f["oframe"])
        T[:3, 3] /= 1000.0
        return T
