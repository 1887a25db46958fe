"""Part adapters: which part shows a model, and how to open one (toolkit-free).

A part plugs in by adding its adapter class to :data:`PART_CLASSES` (``kind -> "module:Class"``);
a part whose API package is missing is skipped (the viewer then shows the others).

>>> from geoshade.compute.synthetic import synthetic_core
>>> part_class(synthetic_core(8)).kind
'core'
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

from geoshade.errors import InputError
from geoshade.viewer.parts.base import Job, Part, Progress, run_now

#: kind -> "module:Class" of the adapter, in the order models are matched
PART_CLASSES = {
    "core": "geoshade.viewer.parts.core:CorePart",
    "grid": "geoshade.viewer.parts.grid:GridPart",
    "iso": "geoshade.viewer.parts.iso:IsoPart",
    "stacks": "geoshade.viewer.parts.stacks:StacksPart",
}


def adapter(kind: str) -> type[Part] | None:
    """The adapter class of ``kind``, or None when that part's API is not installed."""
    if kind not in PART_CLASSES:
        raise InputError(f"kind: unknown part {kind!r}; expected one of "
                         f"{', '.join(PART_CLASSES)}")
    mod, cls = PART_CLASSES[kind].split(":")
    try:
        return getattr(importlib.import_module(mod), cls)
    except ImportError:
        return None


def available_kinds() -> list[str]:
    return [k for k in PART_CLASSES if adapter(k) is not None]


def part_class(model, kind: str | None = None) -> type[Part]:
    """The adapter that shows ``model`` (``kind`` forces one)."""
    if kind is not None:
        cls = adapter(kind)
        if cls is None:
            raise InputError(f"kind: the {kind} part is not available in this installation")
        if not cls.accepts(model):
            raise InputError(f"kind: the {kind} view cannot show a {type(model).__name__}")
        return cls
    for k in PART_CLASSES:
        cls = adapter(k)
        if cls is not None and cls.accepts(model):
            return cls
    raise InputError(f"the viewer has no view for a {type(model).__name__}; it shows voxel "
                     "volumes, corner-point grids, fields over time and stack models")


def load_model(source, kind: str | None = None, hints: dict | None = None,
               settings: dict | None = None) -> Any:
    """A model from a path (``geoshade.load``; fields over time with ``kind='iso'``) or as is.

    A field's ``color_by`` setting is read with it (``load_field(..., color_by=...)``).
    """
    hints = {k: v for k, v in (hints or {}).items() if v is not None}
    if kind == "iso" and (settings or {}).get("color_by") and isinstance(source, (str, Path)):
        hints.setdefault("color_by", settings["color_by"])
    if not isinstance(source, (str, Path)):
        if hints:
            raise InputError(f"{', '.join(sorted(hints))}: hints apply to files only")
        return source
    if kind == "iso":
        import inspect

        from geoshade.io.fields import load_field

        takes = set(list(inspect.signature(load_field).parameters)[1:])
        if set(hints) - takes:
            raise InputError(f"{source}: {', '.join(sorted(set(hints) - takes))} does not apply "
                             f"to fields over time; they take {', '.join(sorted(takes))}")
        return load_field(source, **hints)
    from geoshade.io import load

    return load(source, **hints)


def precompute(cls: type[Part], model, settings: dict, progress: Progress | None = None) -> dict:
    """CPU work before the View is made (any thread): keyword arguments for ``cls``
    (``model`` among them replaces the model, e.g. a labelled volume converted to stacks)."""
    hook = getattr(cls, "precompute", None)
    return hook(model, settings, progress) if hook is not None else {}


def open_part(source, kind: str | None = None, size=(800, 600), hints: dict | None = None,
              progress: Progress | None = None, **settings) -> Part:
    """Load ``source`` (path or model) and make the part adapter that shows it, here and now.

    Parameters
    ----------
    source : path or model
    kind : {'core', 'grid', 'iso', 'stacks'}, optional
        Force a part (``iso`` reads the path with :func:`geoshade.io.load_field`).
    size : (w, h)
    hints : dict
        Reader hints (``shape``, ``dtype``, ``endian``, ``spacing``; ``keyword`` for fields).
    **settings
        The part's settings (see each adapter), e.g. ``range=(0, 9000)`` for a core.

    Examples
    --------
    >>> from geoshade.compute.synthetic import synthetic_core
    >>> part = open_part(synthetic_core(16), size=(64, 48))   # doctest: +SKIP
    >>> img, stats = part.draw(part.camera())                 # doctest: +SKIP
    """
    model = load_model(source, kind, hints, settings)
    cls = part_class(model, kind)
    init, later = split_settings(cls, settings)
    extra = precompute(cls, model, init, progress)
    part = cls(extra.pop("model", model), size=size, **init, **extra)
    for job in part.apply(**later):
        run_now(job)
    return part


def split_settings(cls: type[Part], settings: dict) -> tuple[dict, dict]:
    """(settings the constructor takes, the rest for :meth:`Part.apply`)."""
    import inspect

    params = inspect.signature(cls.__init__).parameters
    init = {k: v for k, v in settings.items() if k in params and not k.startswith("_")}
    return init, {k: v for k, v in settings.items() if k not in init}


def demo_parts() -> dict[str, tuple[type[Part], Any, dict]]:
    """kind -> (adapter, synthetic model, settings) for every available part."""
    out = {}
    for k in PART_CLASSES:
        cls = adapter(k)
        if cls is not None:
            model, settings = cls.demo()
            out[k] = (cls, model, settings)
    return out


__all__ = ["PART_CLASSES", "Job", "Part", "adapter", "available_kinds", "demo_parts",
           "load_model", "open_part", "part_class", "precompute", "run_now", "split_settings"]
