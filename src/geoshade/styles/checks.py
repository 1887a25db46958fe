"""Checks of option values, and their binding to the fields of an options class.

The plain checks (:func:`check_number`, :func:`check_bool`, :func:`check_choice`,
:func:`check_range`, :func:`check_exaggeration`) turn a value into what an option holds or raise
one :class:`~geoshade.errors.InputError` line naming it. :func:`checks` binds a check to fields
explicitly; :func:`bind_checks` builds an options class's field -> check table when the class is
made, and refuses (``TypeError``) a binding to no field, a ``check_*`` bound to nothing or a
field without a check, so no misspelling turns a check off silently.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable

import numpy as np

from geoshade.errors import InputError
from geoshade.styles.saved_camera import _number


def check_number(value, what: str, lo: float | None = None, hi: float | None = None,
                 integer: bool = False, positive: bool = False, allow_none: bool = False):
    """``value`` as a float (or an int), checked against ``lo <= v <= hi`` / ``v > 0``.

    >>> check_number("3", "patch_level", 1, 64, integer=True)
    3
    >>> check_number(0, "smooth", lo=0), check_number(None, "radius", allow_none=True)
    (0.0, None)
    >>> check_number(-1, "well_radius", positive=True)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: well_radius: expected a positive number, got -1
    """
    if value is None and allow_none:
        return None
    kind = "an integer" if integer else "a positive number" if positive else "a number"
    rng = (f" {lo:g}..{hi:g}" if lo is not None and hi is not None else
           f" >= {lo:g}" if lo is not None else f" <= {hi:g}" if hi is not None else "")
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    bad = (not math.isfinite(v) or isinstance(value, bool) or (positive and v <= 0)
           or (lo is not None and v < lo) or (hi is not None and v > hi)
           or (integer and not float(v).is_integer()))
    if bad:
        raise InputError(f"{what}: expected {kind}{rng}, got {value!r}")
    return int(v) if integer else v


def check_bool(value, what: str) -> bool:
    """``value`` as a bool; strings ``yes/no/true/false/on/off/1/0`` are understood.

    >>> check_bool("off", "cull")
    False
    """
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer) and value in (0, 1):
        return bool(value)
    if isinstance(value, str) and value.lower() in ("yes", "no", "true", "false", "on", "off",
                                                    "1", "0"):
        return value.lower() in ("yes", "true", "on", "1")
    raise InputError(f"{what}: expected true or false, got {value!r}")


def check_choice(value, choices, what: str) -> str:
    """``value`` if it is one of ``choices`` (case-insensitive), else one clear error.

    >>> check_choice("SSBO", ("ssbo", "textures"), "layout")
    'ssbo'
    """
    for c in choices:
        if isinstance(value, str) and value.lower() == str(c).lower():
            return c
        if not isinstance(value, str | bool) and not isinstance(c, str) and value == c:
            return c
    raise InputError(f"{what}: expected one of {', '.join(str(c) for c in choices)}, "
                     f"got {value!r}")


def check_exaggeration(value) -> float:
    """Vertical exaggeration: a positive number.

    >>> check_exaggeration("5")
    5.0
    """
    return _number(value, "exaggeration", positive=True)


def check_range(value, what: str = "range", allow_none: bool = True):
    """``(lo, hi)`` finite with ``lo <= hi`` as floats (None passes when allowed).

    >>> check_range([2, 3])
    (2.0, 3.0)
    """
    if value is None and allow_none:
        return None
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InputError(f"{what}: expected two numbers LO HI, got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
        raise InputError(f"{what}: expected finite LO <= HI, got {lo:g} {hi:g}")
    return (lo, hi)


#: binary units of a size: ``8G``, ``512M``
_UNITS = {"": 1, "b": 1, "k": 2**10, "m": 2**20, "g": 2**30, "t": 2**40}


def parse_bytes(text, what: str = "gpu_memory") -> int:
    """``"8G"``, ``"512M"``, ``"1.5g"``, ``"123456"`` or a number -> bytes (binary units).

    >>> parse_bytes("8G"), parse_bytes("512m"), parse_bytes(1024)
    (8589934592, 536870912, 1024)
    """
    if isinstance(text, int | float) and not isinstance(text, bool):
        value = float(text)
    else:
        m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+)\s*([kmgtKMGT]?)(?:i?[bB])?\s*", str(text))
        if not m:
            raise InputError(f"{what}: expected a size such as 8G, 512M or a number of bytes, "
                             f"got {text!r}")
        value = float(m.group(1)) * _UNITS[m.group(2).lower()]
    if not value > 0:
        raise InputError(f"{what}: expected a positive size, got {text!r}")
    return int(value)


def checks(*names: str) -> Callable:
    """Bind the decorated check ``f(value, model) -> value`` to the option fields ``names``.

    Binding is explicit and checked when the options class is made: a name that is no field of
    the class, a ``check_*`` method bound to nothing, or a field left without a check raises
    ``TypeError`` at import, so no misspelling turns a check off silently.

    >>> from dataclasses import dataclass
    >>> from geoshade.styles.declare import option
    >>> from geoshade.styles.options import ViewOptions
    >>> @dataclass(frozen=True)
    ... class Demo(ViewOptions):
    ...     level: float = option(0.0, help="the level")
    ...     @staticmethod
    ...     @checks("level")
    ...     def check_level(value, model=None):
    ...         return check_number(value, "level")
    >>> Demo.parse(level="2").level
    2.0
    >>> class Typo(ViewOptions):
    ...     level: float = option(0.0, help="the level")
    ...     @staticmethod
    ...     @checks("levle")
    ...     def check_level(value, model=None):
    ...         return value
    Traceback (most recent call last):
    ...
    TypeError: Typo: check_level is bound to levle, which is not one of its fields (size, ...
    """
    def bind(fn):
        target = fn.__func__ if isinstance(fn, staticmethod) else fn
        target.__option_check__ = tuple(names)
        return fn
    return bind


def _option_fields(cls) -> list[str]:
    """The dataclass field names ``cls`` will have (annotations along the MRO, no ClassVars);
    known before ``@dataclass`` runs, so bindings are checked as the class is made."""
    out: list[str] = []
    for klass in reversed(cls.__mro__):
        for name, ann in vars(klass).get("__annotations__", {}).items():
            if "ClassVar" in str(ann) or name.startswith("_"):
                continue
            if name not in out:
                out.append(name)
    return out


def _flag_check(name: str) -> Callable:
    def check(value, model=None) -> bool:
        return check_bool(value, name)
    return check


def _choice_check(name: str, choices: tuple, nullable: bool = False) -> Callable:
    def check(value, model=None):
        if value is None and nullable:
            return None
        return check_choice(value, choices, name)
    return check


def bind_checks(cls, base: bool = False, shorthands=()) -> dict[str, Callable]:
    """field -> check of options class ``cls``; ``TypeError`` for a binding to no field, a
    ``check_*`` bound to nothing, or a field without a check (``base``: the shared class, whose
    checks of fields the parts add, such as ``color``, are kept for them)."""
    fields = _option_fields(cls)
    out: dict[str, Callable] = {}
    own = vars(cls)
    fields = [*fields]
    for name in cls.FLAGS:
        out[name] = _flag_check(name)
    nullable = getattr(cls, "_NULLABLE", ())
    for name, words in cls.CHOICES.items():
        out[name] = _choice_check(name, tuple(words), name in nullable)
    for klass in reversed(cls.__mro__):
        for attr, obj in vars(klass).items():
            fn = obj.__func__ if isinstance(obj, staticmethod | classmethod) else obj
            bound = getattr(fn, "__option_check__", None)
            if bound is None:
                if attr.startswith("check_") and callable(fn) and klass is cls:
                    raise TypeError(f"{cls.__name__}: {attr} is bound to no field; decorate it "
                                    f"with @checks('<field>')")
                continue
            for name in bound:
                if name not in fields and base:
                    continue
                if name not in fields and klass is cls:
                    raise TypeError(f"{cls.__name__}: {attr} is bound to {name}, which is not "
                                    f"one of its fields ({', '.join(fields)})")
                out[name] = obj.__func__ if isinstance(obj, staticmethod) else getattr(cls, attr)
    shorthands = set(shorthands)
    for name in [*own.get("FLAGS", ()), *own.get("CHOICES", ())]:
        if name not in fields and name not in shorthands:
            raise TypeError(f"{cls.__name__}: {name} in FLAGS/CHOICES is not one of its fields")
    missing = [f for f in fields if f not in out]
    if missing:
        raise TypeError(f"{cls.__name__}: no check bound to {', '.join(missing)}; bind one "
                        f"with @checks(...) or list the field in FLAGS (true/false) or CHOICES")
    return out


__all__ = [
    "bind_checks",
    "check_bool",
    "check_choice",
    "check_exaggeration",
    "check_number",
    "check_range",
    "checks",
    "parse_bytes",
]
