"""A View's state as plain JSON values: what reopens the same picture.

:func:`view_state` gives, by the names ``geoshade.view`` takes, every option whose value is not
its declared default (the resolved values: an automatic exaggeration or property as the number
or name it became) and the camera (a saved camera when one is given: the user's turned view),
each as the text or numbers a command line or a browser address would carry. ``geoshade.view(
model, **state)`` draws the same picture pixel for pixel (tested for every part). Values that
are no plain data (well trajectories read from files, a drape or palette array, a mask volume)
are left out and named by :func:`left_out`.

>>> state_value(slice(1, 3)), state_value((slice(0, 4), slice(None, 2), slice(3, 4)))
([1, 3], 'i=0:4,j=:2,k=3:4')
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from geoshade.styles.options import CAMERA_OPTIONS, COLOR_OPTIONS, CameraSpec


class _LeftOut:
    """The mark of a value a view's state cannot carry (it is left out of the state)."""

    def __repr__(self) -> str:
        return "LEFT_OUT"


#: what a value that cannot be carried becomes
LEFT_OUT = _LeftOut()
#: options a state never carries: where the work runs, and what resolving sets itself
NEVER = frozenset({"scheduler", "distributed", "worker_timeout", "parts", "gpu_memory",
                   "select_auto", "camera", "color", "progressive", "prefetch"})


def state_value(value: Any) -> Any:
    """``value`` as plain JSON (text, numbers, lists), or :data:`LEFT_OUT`."""
    if value is None or isinstance(value, bool | str):
        return value
    if isinstance(value, int | float | np.integer | np.floating):
        v = value.item() if isinstance(value, np.generic) else value
        return v if not isinstance(v, float) or math.isfinite(v) else LEFT_OUT
    if isinstance(value, slice):
        return [value.start, value.stop]
    if isinstance(value, tuple | list) and len(value) == 3 and \
            all(isinstance(v, slice) for v in value):   # an IJK box
        return ",".join(f"{a}={'' if s.start is None else s.start}:"
                        f"{'' if s.stop is None else s.stop}" for a, s in zip("ijk", value,
                                                                           strict=True))
    if isinstance(value, dict):
        out = {str(k): state_value(v) for k, v in value.items()}
        return LEFT_OUT if any(v is LEFT_OUT for v in out.values()) else out
    if isinstance(value, tuple | list):
        out = [state_value(v) for v in value]
        return LEFT_OUT if any(v is LEFT_OUT for v in out) else out
    if hasattr(value, "offset") and hasattr(value, "size") and not hasattr(value, "shape"):
        return [*map(int, value.offset), *map(int, value.size)]   # a Box
    if hasattr(value, "text") and callable(value.text):
        return value.text()   # a Plane, a Cylinder
    if hasattr(value, "expr"):
        return str(value.expr)   # a Filter or an Expression
    return LEFT_OUT


def _same(a, b) -> bool:
    try:
        return bool(a == b) if not isinstance(a, np.ndarray) else False
    except (TypeError, ValueError):
        return False


def view_state(view, camera=None) -> dict:
    """The state of ``view`` (see the module); ``camera``: the
    :class:`~geoshade.render.camera.Camera` the picture is drawn with (default: the options'
    framed camera)."""
    o, cls = view.options, view.Options
    out: dict[str, Any] = {}
    for f in dataclasses.fields(o):
        if f.name in NEVER:
            continue
        value = getattr(o, f.name)
        if _same(value, cls.default(f.name)) and f.name != "size":
            continue
        v = state_value(value)
        if v is not LEFT_OUT:
            out[f.name] = v
    if any(f.name == "color" for f in dataclasses.fields(o)):
        default = type(o.color)()
        for short, (fld, _) in COLOR_OPTIONS.items():
            if short in cls.NO_COLOR or short == "palette":
                continue
            value = getattr(o.color, fld)
            if not _same(value, getattr(default, fld)):
                v = state_value(value)
                if v is not LEFT_OUT:
                    out[short] = v
    if camera is not None:
        out["camera"] = camera.saved().as_dict()
    else:
        spec, default = o.camera, CameraSpec()
        for name in CAMERA_OPTIONS:
            if not _same(getattr(spec, name), getattr(default, name)):
                out[name] = state_value(getattr(spec, name))
        if spec.saved is not None:
            out["camera"] = spec.saved.as_dict()
    return out


def left_out(view) -> list[str]:
    """The options of ``view`` set to values its state cannot carry (see the module)."""
    o, cls = view.options, view.Options
    return [f.name for f in dataclasses.fields(o) if f.name not in NEVER
            and not _same(getattr(o, f.name), cls.default(f.name))
            and state_value(getattr(o, f.name)) is LEFT_OUT]


__all__ = ["LEFT_OUT", "left_out", "state_value", "view_state"]
