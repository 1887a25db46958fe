"""What each control shows for a View's current options (no GUI toolkit).

:func:`geoshade.viewer.controls.controls` says which controls a View has; this module says the
value each one shows, by control *type*: a tristate's None is ``"auto"``, a wells or drape check
box is on while the View shows some, a text box shows the option as it would be typed (a slice
``i=0:4,j=0:3,k=1:2``, a plane ``NX,NY,NZ,D``, a ROI ``cylinder:CX,CY,R``), a core's box its six
numbers, materials the hidden codes and opacities. A viewer sets its controls from these values
with their change signals ignored, so what it shows never sends a change back.

>>> spec = {"name": "log", "type": "select", "auto": True, "choices": ["auto", True, False]}
>>> control_values([{"group": "colours", "controls": [spec]}],
...                {"color": {"log": None}})
{'log': 'auto'}
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np

from geoshade.viewer.controls import AUTO, jsonable

#: a control whose option sits in the colour style under another name
COLOR_ALIAS = {"color_range": "range"}


def specs(groups: Iterable[dict]) -> list[dict]:
    """The controls of ``groups`` (:func:`~geoshade.viewer.controls.controls`), in order."""
    return [c for g in groups for c in g["controls"]]


def as_text(value: Any) -> str:
    """An option's value as it is typed into a text box (None: empty).

    >>> as_text((slice(0, 4), slice(0, 3), slice(1, 2)))
    'i=0:4,j=0:3,k=1:2'
    >>> as_text({"normal": (1.0, 0.0, 0.0), "offset": 2.5})
    '1,0,0,2.5'
    """
    if value is None:
        return ""
    if isinstance(value, tuple) and value and all(isinstance(s, slice) for s in value):
        return ",".join(f"{ax}={s.start}:{s.stop}" for ax, s in zip("ijk", value, strict=False))
    if isinstance(value, dict) and "normal" in value:
        nums = [*value["normal"], *([] if value.get("offset") is None else [value["offset"]])]
        return ",".join(f"{float(v):g}" for v in nums)
    if hasattr(value, "normal") and hasattr(value, "offset"):
        return as_text({"normal": value.normal, "offset": value.offset})
    if callable(getattr(value, "text", None)):
        return str(value.text())
    return str(value)


def is_on(value: Any) -> bool:
    """A check box's state: None, False and an empty list are off; anything else (a drape
    picture, the wells shown) is on."""
    if value is None or value is False:
        return False
    if isinstance(value, list | tuple | dict):
        return len(value) > 0
    if isinstance(value, np.ndarray):
        return True
    return bool(value)


def shown(spec: dict, value: Any) -> Any:
    """The value control ``spec`` shows for its option's ``value``."""
    kind = spec["type"]
    if kind == "check":
        return is_on(value)
    if kind == "text":
        return as_text(value)
    if kind == "select" and spec.get("auto") and value is None:
        return AUTO
    if kind == "ints" and hasattr(value, "offset") and hasattr(value, "size"):
        return [*value.offset, *value.size]   # a core's box
    if kind == "ijk":   # [[i0, i1], [j0, j1], [k0, k1]], the full range where not cut
        dims = spec.get("dims") or (0, 0, 0)
        cut = tuple(value) if isinstance(value, tuple | list) else (slice(None),) * 3
        return [[int(s.start or 0), int(dims[a] if s.stop is None else s.stop)]
                for a, s in enumerate(cut)]
    if kind == "ranges":   # {NAME: [LO, HI]} of the narrowed properties
        return {} if value is None else jsonable(value.as_dict() if hasattr(value, "as_dict")
                                                 else value)
    if kind == "vectors":
        return list(value or ())
    return jsonable(value)


def control_values(groups: Iterable[dict], settings: dict, section: list | None = None
                   ) -> dict[str, Any]:
    """``{control name: value}`` of every control of ``groups`` that shows an option.

    Parameters
    ----------
    groups : list of dict
        The View's controls (:func:`~geoshade.viewer.controls.controls`).
    settings : dict
        The View's :meth:`~geoshade.render.view.View.settings`, with the session's ``view``,
        ``ortho`` and ``exaggeration``.
    section : [axis, fraction, flip], optional
        The section the section control last set (a plane does not say it).

    A button and a control that only sets another option (a typed expression, Otsu) show
    nothing; a materials list shows ``{"hide": [...], "opacity": {...}}``.
    """
    color = settings.get("color") or {}
    out: dict[str, Any] = {}
    for spec in specs(groups):
        name, kind = spec["name"], spec["type"]
        if kind == "button" or (spec.get("sets") and kind not in ("materials", "section")):
            continue
        if kind == "materials":
            out[name] = {"hide": [int(c) for c in settings.get("hide") or ()],
                         "opacity": {int(k): float(v)
                                     for k, v in (settings.get("opacity") or {}).items()}}
        elif kind == "section":
            out[name] = section if settings.get("plane") is not None else None
        elif name in settings:
            out[name] = shown(spec, settings[name])
        elif COLOR_ALIAS.get(name, name) in color:
            out[name] = shown(spec, color[COLOR_ALIAS.get(name, name)])
    return out


def slider_value(lo: float, hi: float, pos: float, steps: int) -> float:
    """The value at position ``pos`` of ``steps`` of a slider from ``lo`` to ``hi``, to the
    slider's resolution (no 0.19999999999999998 from a position at 0.2): what the range
    sliders of the desktop viewer and the notebook send.

    >>> slider_value(0.0, 0.35, 200, 350), slider_value(1.84, 55204.4, 1000, 1000)
    (0.2, 55204.4)
    """
    if pos >= steps:
        return float(hi)
    v = lo + (hi - lo) * pos / steps
    span = abs(hi - lo) / steps
    digits = 0 if span <= 0 else max(0, 1 - math.floor(math.log10(span)))
    return float(round(v, digits))


__all__ = ["as_text", "control_values", "is_on", "shown", "slider_value", "specs"]
