"""Cell filters on property values: ``PORO > 0.2 and PERMX > 100``, evaluated safely.

The expression is parsed with :mod:`ast` and only this subset is evaluated (nothing is passed
to ``eval``): property names, numbers, ``and or not``, comparisons ``< <= > >= == !=`` (also
chained, ``0.1 < PORO <= 0.3``), ``+ - * /``, unary ``-``, parentheses and the functions
``abs`` and ``log10``.  Comparisons with NaN are false, so cells without a value fail every
comparison.

Bounds, checked before anything is evaluated: at most :data:`MAX_LENGTH` characters, a syntax
tree at most :data:`MAX_DEPTH` levels deep (``not not ...``, ``- - ...``, ``1 + 1 + ...``,
parentheses), and numbers that are finite as float64.
"""

from __future__ import annotations

import ast
import operator
from typing import NoReturn

import numpy as np

from geoshade.errors import InputError

_COMPARE = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
            ast.GtE: operator.ge, ast.Eq: operator.eq, ast.NotEq: operator.ne}
_ARITH = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
          ast.Div: operator.truediv}
_FUNCS = {"abs": np.abs, "log10": np.log10}
#: longest expression (characters) and deepest syntax tree a filter may have
MAX_LENGTH, MAX_DEPTH = 2000, 64


def _shown(expr) -> str:
    """The expression for a message: quoted, cut after 60 characters."""
    text = str(expr)
    return repr(text if len(text) <= 60 else text[:57] + "...")


def _number_text(v) -> str:
    text = str(v)
    return text if len(text) <= 24 else f"{text[:12]}... ({len(text)} digits)"


#: what each kind of expression is called in messages, and an example of one
_KINDS = {"filter": "'PORO > 0.2 and PERMX > 100'", "property": "'log10(PERMX)' or 'PORO * NTG'"}


def _parse(expr, what: str = "filter") -> ast.Expression:
    """The checked syntax tree of ``expr``: length, nesting depth and numbers bounded (one
    line each), syntax errors as one line (``what``: "filter" or "property", for messages)."""
    example = _KINDS[what]
    if not isinstance(expr, str) or not expr.strip():
        raise InputError(f"{what} {expr!r}: expected an expression such as {example}")
    text = expr.strip()
    if len(text) > MAX_LENGTH:
        raise InputError(f"{what} {_shown(text)}: {len(text)} characters; at most {MAX_LENGTH}")
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as err:
        raise InputError(f"{what} {_shown(expr)}: not a valid expression ({err.msg}); expected "
                         f"e.g. {example}") from None
    except (RecursionError, MemoryError, ValueError):  # the parser's own limits
        raise InputError(f"{what} {_shown(text)}: nested too deeply; at most {MAX_DEPTH} "
                         "levels of operators and parentheses") from None
    todo: list[tuple[ast.AST, int]] = [(tree, 1)]
    while todo:  # iterative: the tree may be deep
        node, depth = todo.pop()
        if depth > MAX_DEPTH:
            raise InputError(f"{what} {_shown(text)}: nested more than {MAX_DEPTH} levels deep "
                             "(operators, 'not', parentheses); simplify it")
        value = node.value if isinstance(node, ast.Constant) else None
        if isinstance(value, int | float) and not isinstance(value, bool):
            try:
                finite = bool(np.isfinite(float(value)))
            except OverflowError:
                finite = False
            if not finite:
                num = ast.get_source_segment(text, node) or str(value)
                raise InputError(f"{what} {_shown(text)}: number {_number_text(num)} is not a "
                                 "finite float64 (|x| < 1.8e308)")
        todo.extend((child, depth + 1) for child in ast.iter_child_nodes(node))
    return tree


def _is_bool(v) -> bool:
    return isinstance(v, bool | np.bool_) or (isinstance(v, np.ndarray) and v.dtype == bool)


class _Eval:
    def __init__(self, expr: str, properties: dict, what: str = "filter", shape=None):
        self.expr = expr
        self.what = what
        self.props = properties
        self.shape = shape  # checked for the properties the expression reads, and only them
        self.upper: dict[str, list] = {}
        for name in properties:
            self.upper.setdefault(str(name).upper(), []).append(name)

    def _checked(self, name, arr: np.ndarray) -> np.ndarray:
        if self.shape is not None and arr.shape != self.shape:
            raise InputError(f"{self.what}: property {name} has shape {arr.shape}, expected "
                             f"{self.shape}")
        return arr

    def fail(self, what: str) -> NoReturn:
        raise InputError(f"{self.what} {self.expr!r}: {what}; expected property names, "
                         "numbers, and/or/not, comparisons, + - * /, parentheses, abs(), log10()")

    def condition(self, node, where: str):
        v = self.value(node)
        if not _is_bool(v):
            raise InputError(f"{self.what} {self.expr!r}: {where} must be a condition such as "
                             "'PORO > 0.2', not a number")
        return v

    def value(self, node):
        if isinstance(node, ast.Expression):
            return self.value(node.body)
        if isinstance(node, ast.BoolOp):
            # combined as they are evaluated: one operand at a time in memory (166 `or` terms
            # at 1e7 cells held 1.2 GB when every operand was materialised first)
            combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
            out = self.condition(node.values[0], "each side of and/or")
            owned = False  # out is an array made here (never a property's own array)
            for v in node.values[1:]:
                term = self.condition(v, "each side of and/or")
                if owned and out.shape == np.shape(term):
                    combine(out, term, out=out)  # in place: no new array per operand
                else:
                    out = combine(out, term)
                    owned = isinstance(out, np.ndarray)
                del term
            return out
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.Not):
                return np.logical_not(self.condition(node.operand, "the operand of not"))
            if isinstance(node.op, ast.USub | ast.UAdd):
                v = self.number(node.operand)
                return -v if isinstance(node.op, ast.USub) else v
            self.fail(f"operator {type(node.op).__name__} is not allowed")
        if isinstance(node, ast.Compare):
            left = self.number(node.left)
            out = None
            for op, right_node in zip(node.ops, node.comparators, strict=True):
                if type(op) not in _COMPARE:
                    self.fail(f"comparison {type(op).__name__} is not allowed")
                right = self.number(right_node)
                with np.errstate(invalid="ignore"):
                    r = _COMPARE[type(op)](left, right)
                out = r if out is None else np.logical_and(out, r)
                left = right
            return out
        if isinstance(node, ast.BinOp):
            if type(node.op) not in _ARITH:
                self.fail(f"operator {type(node.op).__name__} is not allowed")
            a, b = self.number(node.left), self.number(node.right)
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                return _ARITH[type(node.op)](a, b)
        if isinstance(node, ast.Call):
            name = node.func.id if isinstance(node.func, ast.Name) else None
            if name not in _FUNCS or len(node.args) != 1 or node.keywords:
                self.fail(f"function {name or ast.unparse(node.func)!r} is not allowed "
                          "(only abs(x) and log10(x))")
            with np.errstate(divide="ignore", invalid="ignore"):
                return _FUNCS[name](self.number(node.args[0]))
        if isinstance(node, ast.Name):
            return self.name(node.id)
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, int | float):
                self.fail(f"constant {node.value!r} is not a number")
            return float(node.value)
        self.fail(f"{type(node).__name__} ({ast.unparse(node)!r}) is not allowed")
        return None  # pragma: no cover

    def number(self, node):
        v = self.value(node)
        if _is_bool(v):
            raise InputError(f"{self.what} {self.expr!r}: {ast.unparse(node)!r} is a condition "
                             "where a number is expected")
        return v

    def name(self, ident: str):
        if ident in self.props:
            return self._checked(ident, np.asarray(self.props[ident]))
        cands = self.upper.get(ident.upper(), [])
        if len(cands) == 1:
            return self._checked(cands[0], np.asarray(self.props[cands[0]]))
        names = ", ".join(sorted(str(n) for n in self.props)) or "(none)"
        raise InputError(f"{self.what} {self.expr!r}: unknown property {ident!r}; available: "
                         f"{names}")


def cell_filter(expr: str, properties: dict, shape) -> np.ndarray:
    """The (nx, ny, nz) bool mask of the cells that satisfy ``expr``.

    Parameters
    ----------
    expr : str
        e.g. ``"PORO > 0.2 and PERMX > 100"``, ``"0.1 < PORO <= 0.3 or not NTG < 0.5"``,
        ``"log10(PERMX) >= 2"``.  Names match exactly, else case-insensitively when that is
        unambiguous.
    properties : dict
        name -> array of ``shape`` (e.g. ``grid.properties`` merged with a report step's).
    shape : tuple
        (nx, ny, nz).

    Returns
    -------
    (nx, ny, nz) bool array (F-order)

    Raises
    ------
    InputError
        An unknown property (listing the available names), or any syntax outside the subset
        (quoting the expression).

    Examples
    --------
    >>> import numpy as np
    >>> props = {"PORO": np.array([0.1, 0.25, np.nan, 0.3]).reshape(4, 1, 1),
    ...          "PERMX": np.array([500.0, 50.0, 900.0, 200.0]).reshape(4, 1, 1)}
    >>> cell_filter("PORO > 0.2 and PERMX > 100", props, (4, 1, 1)).ravel().tolist()
    [False, False, False, True]
    >>> cell_filter("0.05 < poro < 0.28", props, (4, 1, 1)).ravel().tolist()
    [True, True, False, False]
    """
    shape = tuple(int(s) for s in shape)
    tree = _parse(expr)
    # lazy mappings (report steps, derived SOIL) are read only for the names used
    ev = _Eval(expr, properties, shape=shape)
    out = ev.condition(tree, "the expression")
    out = np.broadcast_to(out, shape)
    return np.asfortranarray(out, dtype=bool)


_ALLOWED = (ast.Expression, ast.BoolOp, ast.And, ast.Or, ast.UnaryOp, ast.Not, ast.USub, ast.UAdd,
            ast.Compare, ast.BinOp, ast.Call, ast.Name, ast.Load, ast.Constant,
            *_COMPARE, *_ARITH)


class _Checked:
    """An expression over cell properties, parsed and checked once (the grammar of
    :func:`cell_filter`); names are matched against a model's case-insensitively."""

    #: "filter" or "property": what the expression is called in messages
    WHAT = "filter"

    def __init__(self, expr: str):
        what = self.WHAT
        tree = _parse(expr, what)
        self.expr = expr.strip()
        names: list[str] = []
        for node in ast.walk(tree):
            if not isinstance(node, _ALLOWED):
                raise InputError(f"{what} {expr!r}: {type(node).__name__} is not allowed; "
                                 "expected property names, numbers, and/or/not, comparisons, "
                                 "+ - * /, parentheses, abs(), log10()")
            if isinstance(node, ast.Call):
                fname = node.func.id if isinstance(node.func, ast.Name) else None
                if fname not in _FUNCS or len(node.args) != 1 or node.keywords:
                    raise InputError(f"{what} {expr!r}: function "
                                     f"{fname or ast.unparse(node.func)!r} is not allowed "
                                     "(only abs(x) and log10(x))")
            elif isinstance(node, ast.Name) and node.id not in names:
                names.append(node.id)
        self.names = tuple(n for n in names if n not in _FUNCS or n in self._called(tree, n))
        self._tree = tree

    @staticmethod
    def _called(tree, name) -> tuple:
        calls = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call)
                 and isinstance(n.func, ast.Name)}
        return () if name in calls else (name,)

    @classmethod
    def parse(cls, value):
        """None or "" -> None; one of this class as is; a string -> a checked one."""
        if value is None or (isinstance(value, str) and not value.strip()):
            return None
        if isinstance(value, cls):
            return value
        return cls(value)

    def resolve(self, available) -> dict[str, str]:
        """``{name used: property name}`` matched case-insensitively; unknown names are errors."""
        avail = [str(a) for a in available]
        out = {}
        for n in self.names:
            if n in avail:
                out[n] = n
                continue
            cands = [a for a in avail if a.upper() == n.upper()]
            if len(cands) != 1:
                names = ", ".join(sorted(avail)) or "(none)"
                raise InputError(f"{self.WHAT} {self.expr!r}: unknown property {n!r}; "
                                 f"available: {names}")
            out[n] = cands[0]
        return out

    def uses(self, names) -> bool:
        """True when the expression names any of ``names`` (case-insensitive)."""
        upper = {str(n).upper() for n in names}
        return any(n.upper() in upper for n in self.names)

    def __eq__(self, other) -> bool:
        return type(other) is type(self) and other.expr == self.expr

    def __hash__(self) -> int:
        return hash((self.WHAT, self.expr))

    def __str__(self) -> str:
        return self.expr

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.expr!r})"


class Filter(_Checked):
    """A cell filter expression (``"PORO > 0.2 and PERMX > 100"``), parsed and checked once.

    The syntax is checked when the filter is made (no data needed); the names it uses are
    matched against a model's property names case-insensitively by :meth:`resolve`, so
    ``swat > 0.3`` and ``SWAT > 0.3`` are the same filter.

    Examples
    --------
    >>> f = Filter.parse("swat > 0.3 and log10(PERMX) >= 2")
    >>> f.names
    ('swat', 'PERMX')
    >>> f.uses(["SWAT", "SOIL"]), f.uses(["PORO"])
    (True, False)
    >>> Filter.parse("PORO >")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: filter 'PORO >': not a valid expression (invalid syntax); \
expected e.g. 'PORO > 0.2 and PERMX > 100'
    """

    def mask(self, properties, shape) -> np.ndarray:
        """The ``shape`` bool mask of the cells that pass (see :func:`cell_filter`)."""
        return cell_filter(self.expr, properties, shape)


class Expression(_Checked):
    """A property computed from others, to colour by: ``"log10(PERMX)"``, ``"PORO * NTG"``,
    ``"1 - SWAT"`` -- the grammar of a filter, giving a number instead of a condition.

    Examples
    --------
    >>> import numpy as np
    >>> e = Expression.parse("log10(permx)")
    >>> e.names, e.resolve(["PERMX", "PORO"])
    (('permx',), {'permx': 'PERMX'})
    >>> e.values({"PERMX": np.array([1.0, 100.0, 0.0]).reshape(3, 1, 1)}, (3, 1, 1)).ravel()
    array([  0.,   2., -inf])
    >>> Expression("PORO > 0.2")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: property 'PORO > 0.2': a condition, not a number; colour by a \
number such as 'log10(PERMX)' (conditions belong in --filter)
    >>> is_expression("PERMX"), is_expression("log10(PERMX)"), is_expression(None)
    (False, True, False)
    """

    WHAT = "property"

    def __init__(self, expr: str):
        super().__init__(expr)
        body = self._tree.body
        if isinstance(body, ast.Compare | ast.BoolOp) or (
                isinstance(body, ast.UnaryOp) and isinstance(body.op, ast.Not)):
            raise InputError(f"property {self.expr!r}: a condition, not a number; colour by a "
                             "number such as 'log10(PERMX)' (conditions belong in --filter)")
        if not self.names:
            raise InputError(f"property {self.expr!r}: names no property; expected e.g. "
                             f"{_KINDS['property']}")

    def values(self, properties, shape) -> np.ndarray:
        """The ``shape`` float64 values (F-order) of the expression over ``properties``
        (name -> array of ``shape``; only the names it uses are read). Undefined results
        (log10 of a negative, 0/0) are NaN: cells without a value."""
        shape = tuple(int(s) for s in shape)
        used = self.resolve(list(properties))
        props = {n: properties[p] for n, p in used.items()}
        for name, arr in props.items():
            if np.shape(arr) != shape:
                raise InputError(f"property {self.expr!r}: {name} has shape {np.shape(arr)}, "
                                 f"expected {shape}")
        out = _Eval(self.expr, props, "property").number(self._tree)
        out = np.asarray(np.broadcast_to(np.asarray(out, np.float64), shape))
        return np.asfortranarray(out)


def is_expression(name) -> bool:
    """True when ``name`` is an expression rather than one property name (it is not a plain
    identifier such as ``PERMX`` or ``SWAT``)."""
    return isinstance(name, str) and bool(name.strip()) and not name.strip().isidentifier()


def _num(v: float) -> str:
    """The shortest text that reads back as ``v`` (``100``, ``0.1``, ``1e-05``)."""
    r = repr(float(v))
    return r[:-2] if r.endswith(".0") else r


def _bound(text: str, where: str) -> float | None:
    text = text.strip()
    if not text:
        return None
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not np.isfinite(v):
        raise InputError(f"range {where}: {text!r} is not a finite number")
    return v


class Ranges:
    """Value ranges of properties, the cells shown being those with ``LO <= NAME <= HI`` for
    every entry (ResInsight's range filters; with the typed filter, both hold): the range
    sliders of a viewer and ``--ranges NAME=LO:HI`` of the command line. An end left out is
    open.

    Given as text (``"PORO=0.1:0.3,PERMX=100:"``), a list of such texts (``--ranges`` repeated),
    a mapping ``{NAME: (LO, HI)}`` or a list of ``[NAME, LO, HI]``.

    Examples
    --------
    >>> r = Ranges.parse({"poro": (0.1, 0.3), "PERMX": [100, None]})
    >>> r.text(), r.expr
    ('poro=0.1:0.3,PERMX=100:', '(poro >= 0.1 and poro <= 0.3) and (PERMX >= 100)')
    >>> Ranges.parse(["PORO=0.2:"]) == Ranges.parse("PORO=0.2:"), Ranges.parse({}) is None
    (True, True)
    >>> Ranges.parse("PORO=0.3:0.1")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: range PORO=0.3:0.1: LO 0.3 is above HI 0.1
    """

    def __init__(self, items):
        self.items = tuple((str(n), lo, hi) for n, lo, hi in items)

    @classmethod
    def parse(cls, value) -> Ranges | None:
        """None, "", ``{}`` or ``[]`` -> None; see the class for the forms."""
        if value is None or isinstance(value, cls):
            return value
        if isinstance(value, str):
            value = [v for v in value.split(",") if v.strip()]
        items: list[tuple[str, float | None, float | None]] = []
        entries = list(value.items()) if isinstance(value, dict) else list(value)
        for e in entries:
            if isinstance(e, str):
                name, sep, rest = e.partition("=")
                lo_t, sep2, hi_t = rest.partition(":")
                if not sep or not sep2:
                    raise InputError(f"range {e.strip()!r}: expected NAME=LO:HI (either end "
                                     "may be left out, e.g. PORO=0.2:)")
                lo, hi = _bound(lo_t, e.strip()), _bound(hi_t, e.strip())
            else:
                try:
                    name, pair = (e[0], e[1:]) if len(e) == 3 else (e[0], tuple(e[1]))
                    lo, hi = (None if v is None else _bound(str(v), str(name)) for v in pair)
                except (TypeError, ValueError, IndexError):
                    raise InputError(f"range {e!r}: expected [NAME, LO, HI] or NAME: (LO, HI)"
                                     ) from None
            name = str(name).strip()
            if not name.isidentifier():
                raise InputError(f"range {name!r}: expected a property name such as PORO")
            if lo is not None and hi is not None and lo > hi:
                raise InputError(f"range {name}={lo:g}:{hi:g}: LO {lo:g} is above HI {hi:g}")
            if lo is None and hi is None:
                continue   # the whole range: no cut
            items = [it for it in items if it[0].upper() != name.upper()] + [(name, lo, hi)]
        return cls(items) if items else None

    def text(self) -> str:
        """``NAME=LO:HI`` entries joined by commas (what :meth:`parse` reads back)."""
        return ",".join(f"{n}={'' if lo is None else _num(lo)}:{'' if hi is None else _num(hi)}"
                        for n, lo, hi in self.items)

    @property
    def expr(self) -> str:
        """The ranges as a filter expression."""
        parts = []
        for n, lo, hi in self.items:
            cond = [c for c in (None if lo is None else f"{n} >= {_num(lo)}",
                                None if hi is None else f"{n} <= {_num(hi)}") if c]
            parts.append("(" + " and ".join(cond) + ")")
        return " and ".join(parts)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(n for n, _, _ in self.items)

    def caption(self) -> str:
        """The ranges as a picture's title says them.

        >>> Ranges.parse("PORO=0.1:0.3,PERMX=100:").caption()
        '0.1 ≤ PORO ≤ 0.3, PERMX ≥ 100'
        """
        return ", ".join(f"{_num(lo)} ≤ {n} ≤ {_num(hi)}" if lo is not None and hi is not None
                         else f"{n} ≥ {_num(lo)}" if lo is not None else f"{n} ≤ {_num(hi)}"
                         for n, lo, hi in self.items)

    def as_dict(self) -> dict[str, list]:
        """``{NAME: [LO, HI]}`` (None: open), what a viewer's sliders show."""
        return {n: [lo, hi] for n, lo, hi in self.items}

    def __eq__(self, other) -> bool:
        return type(other) is type(self) and other.items == self.items

    def __hash__(self) -> int:
        return hash(self.items)

    def __str__(self) -> str:
        return self.text()

    def __repr__(self) -> str:
        return f"Ranges({self.text()!r})"


def shown_filter(filter: Filter | None, ranges: Ranges | None) -> Filter | None:
    """The cells shown: the typed ``filter`` and the ``ranges`` both hold (None: every cell).

    >>> str(shown_filter(Filter.parse("SWAT > 0.3"), Ranges.parse("PORO=0.1:")))
    '(SWAT > 0.3) and ((PORO >= 0.1))'
    >>> shown_filter(None, None) is None
    True
    """
    if ranges is None:
        return filter
    if filter is None:
        return Filter(ranges.expr)
    return Filter(f"({filter.expr}) and ({ranges.expr})")
