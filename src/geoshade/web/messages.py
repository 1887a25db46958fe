"""What a page may send to ``geoshade serve``, checked before anything is queued for it.

A page holds the token, but it is still input: every websocket message is parsed and checked
here, on the event loop, and anything else is refused with one line back to that page (and
nothing queued):

- a message is one JSON object of at most :data:`MAX_MESSAGE` bytes with a known type ``t``
  and exactly the fields :data:`MESSAGES` declares for it, each of its kind;
- a picture is at most :data:`MAX_SIDE` pixels a side (``resize``), a drape picture chosen from
  the server's list at most :data:`~geoshade.io.layers.dem.MAX_DRAPE_SIDE` a side;
- a panel change (``set``) names only options the tab's panel has a control for
  (:func:`geoshade.viewer.controls.settable`) and each value is one that control can send
  (:func:`check_control`: a select's choices, a number within its declared limits, a step
  within the steps ...); the View's options then check it as any change;
- a tab sends at most :data:`RATE` messages a second (bursts of :data:`BURST`); the rest are
  dropped and counted (:class:`Bucket`).

>>> parse('{"t": "resize", "w": 640, "h": 480}')
{'t': 'resize', 'w': 640, 'h': 480}
>>> parse('{"t": "resize", "w": 8000, "h": 8000}')
Traceback (most recent call last):
...
geoshade.errors.InputError: resize: 8000×8000 pixels is larger than this server draws ...
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from typing import Any

from geoshade.api import KINDS
from geoshade.errors import InputError
from geoshade.io.layers.dem import MAX_DRAPE_SIDE

#: the largest message a page may send, in bytes (a camera file is about 1 KB)
MAX_MESSAGE = 64 * 1024
#: the longest text a control may send (a filter, an expression, a ROI)
MAX_TEXT = 1000
#: the largest picture a tab is drawn at, pixels a side (4096×4096 RGBA is 64 MiB)
MAX_SIDE = 4096
#: the smallest
MIN_SIDE = 16
#: messages a tab may send a second, and in one burst
RATE = 200.0
BURST = 400
#: options a view's state (the page's address) names at most
MAX_STATE = 128
#: the sides of a plot beside the picture, pixels
MIN_PLOT, MAX_PLOT = 120, 2048
#: summary vectors a page may choose at once
MAX_VECTORS = 16
#: pointer coordinates and wheel notches taken (anything beyond is no pointer)
MAX_COORD = 1e5
MAX_NOTCHES = 100.0


def _number(lo: float | None = None, hi: float | None = None, integer: bool = False
            ) -> Callable[[str, Any], Any]:
    def check(what: str, v: Any) -> Any:
        ok = isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
        if ok and integer:
            ok = float(v).is_integer()
        if not ok or (lo is not None and v < lo) or (hi is not None and v > hi):
            rng = (f" {lo:g}..{hi:g}" if lo is not None and hi is not None else
                   f" >= {lo:g}" if lo is not None else f" <= {hi:g}" if hi is not None else "")
            raise InputError(f"{what}: expected {'an integer' if integer else 'a number'}"
                             f"{rng}, got {_show(v)}")
        return int(v) if integer else v
    return check


def _word(*words: str) -> Callable[[str, Any], Any]:
    def check(what: str, v: Any) -> Any:
        if v not in words:
            raise InputError(f"{what}: expected one of {', '.join(words)}, got {_show(v)}")
        return v
    return check


def _text(limit: int = MAX_TEXT, none: bool = False) -> Callable[[str, Any], Any]:
    def check(what: str, v: Any) -> Any:
        if v is None and none:
            return v
        if not isinstance(v, str):
            raise InputError(f"{what}: expected text, got {_show(v)}")
        if len(v) > limit:
            raise InputError(f"{what}: {len(v):,} characters; at most {limit:,}")
        return v
    return check


def _kind(what: str, v: Any) -> Any:
    if v is not None and v not in KINDS:
        raise InputError(f"{what}: expected one of {', '.join(KINDS)}, got {_show(v)}")
    return v


def _values(what: str, v: Any) -> Any:
    if not isinstance(v, dict) or not v or len(v) > 64:
        raise InputError(f"{what}: expected {{option: value}} (1 to 64 options), got "
                         f"{_show(v)}")
    return v


def _state(what: str, v: Any) -> Any:
    """A view's state from the page's address (:mod:`geoshade.web.address` checks its
    fields against the View)."""
    if v is None:
        return v
    if not isinstance(v, dict) or len(v) > MAX_STATE or any(
            not isinstance(k, str) or len(k) > 64 for k in v):
        raise InputError(f"{what}: expected {{option: value}} (at most {MAX_STATE} options, "
                         f"each named in at most 64 characters), got {_show(v)}")
    return v


def _cell(what: str, v: Any) -> Any:
    if not (isinstance(v, list) and len(v) == 3 and all(
            isinstance(x, int) and not isinstance(x, bool) and 0 <= x < 2**31 for x in v)):
        raise InputError(f"{what}: expected a cell [i, j, k] (0-based), got {_show(v)}")
    return v


def _cell_or_none(what: str, v: Any) -> Any:
    return v if v is None else _cell(what, v)


_COORD = _number(-MAX_COORD, MAX_COORD)
_PLOT = _number(MIN_PLOT, MAX_PLOT, integer=True)
_PLOT_XY = _number(0, MAX_PLOT)

#: every message a page sends: its type -> {field: (check, required)}
MESSAGES: dict[str, dict[str, tuple[Callable[[str, Any], Any], bool]]] = {
    "ack": {},
    "pointer": {"kind": (_word("down", "move", "up"), True), "x": (_COORD, True),
                "y": (_COORD, True),
                "button": (_word("left", "middle", "right", "other"), False)},
    "wheel": {"notches": (_number(-MAX_NOTCHES, MAX_NOTCHES), True)},
    "key": {"key": (_text(16), True)},
    "resize": {"w": (_number(MIN_SIDE, None, integer=True), True),
               "h": (_number(MIN_SIDE, None, integer=True), True)},
    "set": {"values": (_values, True)},
    "open": {"name": (_text(4096), True), "as": (_kind, False), "state": (_state, False)},
    "screenshot": {},
    "save_camera": {},
    "load_camera": {"text": (_text(MAX_MESSAGE), True)},
    "unpick": {"cell": (_cell, True)},
    "history": {"cell": (_cell_or_none, True), "name": (_text(64, none=True), True)},
    "plot_size": {"w": (_PLOT, True), "h": (_PLOT, True)},
    "timeline": {"x": (_PLOT_XY, True), "y": (_PLOT_XY, True)},
}


def _show(v: Any, limit: int = 60) -> str:
    text = repr(v)
    return text if len(text) <= limit else text[:limit] + "…"


def parse(text: str | bytes) -> dict:
    """One message of a page, checked (see the module); InputError in one line otherwise.

    >>> parse('{"t": "banana"}')
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: message: unknown type 'banana'; expected one of ack, pointer, ...
    """
    if len(text) > MAX_MESSAGE:
        raise InputError(f"message: {len(text):,} bytes; at most {MAX_MESSAGE:,}")
    try:
        m = json.loads(text)
    except (ValueError, RecursionError):
        raise InputError("message: not JSON") from None
    if not isinstance(m, dict):
        raise InputError(f"message: expected a JSON object, got {type(m).__name__}")
    t = m.get("t")
    if t not in MESSAGES:
        raise InputError(f"message: unknown type {_show(t)}; expected one of "
                         f"{', '.join(MESSAGES)}")
    fields = MESSAGES[t]
    extra = sorted(set(m) - set(fields) - {"t"})
    if extra:
        raise InputError(f"{t}: unknown field {_show(extra[0])}; it takes "
                         f"{', '.join(fields) or 'no field'}")
    for name, (check, required) in fields.items():
        if name in m:
            m[name] = check(f"{t}: {name}", m[name])
        elif required:
            raise InputError(f"{t}: {name} is missing")
    if t == "resize" and (m["w"] > MAX_SIDE or m["h"] > MAX_SIDE):
        raise InputError(f"resize: {m['w']}×{m['h']} pixels is larger than this server draws "
                         f"(at most {MAX_SIDE}×{MAX_SIDE})")
    return m


# --- panel changes ----------------------------------------------------------------------------
def _controls_of(panel: list[dict]) -> dict[str, list[dict]]:
    """option name -> the controls of ``panel`` that set it."""
    out: dict[str, list[dict]] = {}
    for g in panel:
        for c in g["controls"]:
            sets = c.get("sets", c["name"])
            for name in [sets] if isinstance(sets, str) else sets:
                out.setdefault(name, []).append(c)
    return out


def _same(a: Any, b: Any) -> bool:
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def check_control(spec: dict, name: str, value: Any, current: Any = None) -> Any:
    """``value`` if the control ``spec`` (:func:`geoshade.viewer.controls.controls`) can send it
    for option ``name``; InputError in one line otherwise. ``current``: the option's value now
    (a select shows it even where it is no choice, so it may be sent back).

    >>> check_control({"name": "faults", "type": "select", "choices": ["show", "hide"]},
    ...               "faults", "hide")
    'hide'
    >>> check_control({"name": "smooth", "type": "number", "min": 0, "max": 10}, "smooth", 1e9)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: smooth: expected a number 0..10, got 1000000000.0
    """
    t = spec["type"]
    what = name
    if t == "select":
        if any(_same(value, c) for c in spec["choices"]) or _same(value, current):
            return value
        if spec.get("editable") and isinstance(value, str) and 0 < len(value) <= 64:
            return value
        raise InputError(f"{what}: expected one of {', '.join(map(str, spec['choices'][:12]))}"
                         f"{' …' if len(spec['choices']) > 12 else ''}, got {_show(value)}")
    if t == "check":
        if not isinstance(value, bool):
            raise InputError(f"{what}: expected true or false, got {_show(value)}")
        return value
    if t == "number":
        return _number(spec.get("min"), spec.get("max"))(what, value)
    if t in ("pair", "ints"):
        if value is None:
            return value
        n = 2 if t == "pair" else int(spec["n"])
        if not isinstance(value, list) or len(value) != n:
            raise InputError(f"{what}: expected {n} {'numbers' if t == 'pair' else 'integers'}"
                             f" (or none), got {_show(value)}")
        check = _number(integer=t == "ints")
        return [check(what, v) for v in value]
    if t == "text":
        return _text(none=True)(what, value)
    if t == "step":
        return _number(spec["min"], spec["max"], integer=True)(what, value)
    if t == "button":
        if not _same(value, spec.get("value")):
            raise InputError(f"{what}: the {spec['name']} button sends {spec.get('value')!r}, "
                             f"got {_show(value)}")
        return value
    if t == "materials":
        codes = {int(item[0]) for item in spec["items"]}
        if name == "hide":
            if not isinstance(value, list) or any(not isinstance(c, int) or c not in codes
                                                  for c in value):
                raise InputError(f"hide: expected material codes of {sorted(codes)}, got "
                                 f"{_show(value)}")
            return value
        if not isinstance(value, dict) or len(value) > len(codes):
            raise InputError(f"opacity: expected {{code: 0..1}}, got {_show(value)}")
        for k, v in value.items():
            if not str(k).lstrip("-").isdigit() or int(k) not in codes:
                raise InputError(f"opacity: {_show(k)} is no material code of "
                                 f"{sorted(codes)}")
            _number(0, 1)(f"opacity of {k}", v)
        return value
    if t == "section":
        if value is None:
            return value
        if not (isinstance(value, list) and len(value) == 3 and value[0] in spec["axes"]
                and isinstance(value[2], bool)):
            raise InputError(f"section: expected [axis ({', '.join(spec['axes'])}), fraction "
                             f"0..1, flip], got {_show(value)}")
        _number(0, 1)("section: fraction", value[1])
        return value
    if t in _CHECKS:
        return _CHECKS[t](spec, what, value)
    raise InputError(f"{what}: the {t} control sends nothing here")


def _ijk(spec: dict, what: str, value: Any) -> Any:
    """The I/J/K sliders' ``[[i0, i1], [j0, j1], [k0, k1]]`` within the grid (or None)."""
    if value is None:
        return value
    dims = [int(n) for n in spec["dims"]]
    if not (isinstance(value, list) and len(value) == 3 and all(
            isinstance(p, list) and len(p) == 2 for p in value)):
        raise InputError(f"{what}: expected [[i0, i1], [j0, j1], [k0, k1]], got "
                         f"{_show(value)}")
    for axis, (lo, hi), n in zip("IJK", value, dims, strict=True):
        lo = _number(0, n - 1, integer=True)(f"{what}: {axis} from", lo)
        _number(lo + 1, n, integer=True)(f"{what}: {axis} to", hi)
    return value


def _ranges(spec: dict, what: str, value: Any) -> Any:
    """The range sliders' ``{NAME: [lo, hi]}``: names of the spec's items, lo <= hi."""
    names = {str(item[0]) for item in spec["items"]}
    if value is None:
        return value
    if not isinstance(value, dict) or len(value) > len(names):
        raise InputError(f"{what}: expected {{NAME: [LO, HI]}}, got {_show(value)}")
    for name, pair in value.items():
        if name not in names:
            raise InputError(f"{what}: {_show(name)} is no property with a range here")
        if not (isinstance(pair, list) and len(pair) == 2):
            raise InputError(f"{what}: {name}: expected [LO, HI], got {_show(pair)}")
        lo = _number()(f"{what}: {name} low", pair[0])
        _number(lo, None)(f"{what}: {name} high", pair[1])
    return value


def _vectors(spec: dict, what: str, value: Any) -> Any:
    """Summary vector names or wildcards (the option checks them against the case)."""
    if value is None:
        return value
    if not isinstance(value, list) or len(value) > MAX_VECTORS or any(
            not isinstance(v, str) or not 0 < len(v) <= 64 for v in value):
        raise InputError(f"{what}: expected at most {MAX_VECTORS} vector names (FOPR, "
                         f"WOPR:*), got {_show(value)}")
    return value


#: the checks of the workbench's control types
_CHECKS = {"ijk": _ijk, "ranges": _ranges, "vectors": _vectors}


def check_set(values: dict, panel: list[dict], current: dict, kind: str) -> dict:
    """A ``set`` message's ``{option: value}`` checked against the tab's panel: each option one
    a control of it sets, each value one such a control sends (:func:`check_control`; where
    several controls set one option, any of them).

    >>> panel = [{"group": "g", "controls": [{"name": "faults", "type": "select",
    ...           "choices": ["show", "hide"]}]}]
    >>> check_set({"mask": "/etc/passwd"}, panel, {}, "grid")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: set: 'mask' is not a control of this grid's panel
    """
    controls = _controls_of(panel)
    out = {}
    for name, value in values.items():
        specs = controls.get(name)
        if not specs:
            raise InputError(f"set: {_show(name)} is not a control of this {kind}'s panel")
        errors = []
        for spec in specs:
            try:
                out[name] = check_control(spec, name, value, current.get(name))
                break
            except InputError as err:
                errors.append(err)
        else:
            raise errors[0]
    return out


class Bucket:
    """A token bucket: :meth:`take` is True for at most ``burst`` messages at once and ``rate``
    a second after; the messages refused are counted (:attr:`dropped`).

    >>> b = Bucket(rate=1.0, burst=2)
    >>> [b.take() for _ in range(3)], b.dropped
    ([True, True, False], 1)
    """

    def __init__(self, rate: float = RATE, burst: int = BURST):
        self.rate, self.burst = float(rate), float(burst)
        self.tokens = float(burst)
        self.stamp = time.monotonic()
        self.dropped = 0

    def take(self) -> bool:
        now = time.monotonic()
        self.tokens = min(self.burst, self.tokens + (now - self.stamp) * self.rate)
        self.stamp = now
        if self.tokens >= 1.0:
            self.tokens -= 1.0
            return True
        self.dropped += 1
        return False


def limits() -> dict:
    """The limits a page is told in its ``hello`` (it keeps its requests within them).

    >>> limits()["max_side"]
    4096
    """
    return {"max_side": MAX_SIDE, "min_side": MIN_SIDE, "max_message": MAX_MESSAGE,
            "max_text": MAX_TEXT, "rate": RATE, "burst": BURST,
            "max_drape_side": MAX_DRAPE_SIDE, "min_plot": MIN_PLOT, "max_plot": MAX_PLOT}


__all__ = ["BURST", "MAX_MESSAGE", "MAX_SIDE", "MAX_TEXT", "MESSAGES", "RATE", "Bucket",
           "check_control", "check_set", "limits", "parse"]
