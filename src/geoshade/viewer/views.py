"""Opening models in the viewer (no GUI toolkit): the part's View, the CPU work done before it
on a worker thread, and the defaults a viewer opens with.

The viewer shows the parts' Views themselves (:class:`geoshade.render.view.View`): their
``settings()``, ``jobs(**changes)`` (CPU half on a worker, GL half on the window's thread),
``readout()`` and ``camera()``; the histogram, default selection and porosity of a core come
from :mod:`geoshade.core`. Nothing here re-implements a part.

>>> from geoshade.compute.synthetic import synthetic_core
>>> view_kind(synthetic_core(8))
'core'
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.api import KINDS, distributed_class, load, view_class, view_kind
from geoshade.errors import InputError
from geoshade.grid import display_bounds
from geoshade.render.view import Job, Progress, View

#: exaggerations :func:`auto_exaggeration` picks from
NICE_EXAGGERATIONS = (1, 2, 5, 10, 20, 50, 100, 200)


def auto_exaggeration(bounds, ratio: float = 0.2) -> float:
    """A round vertical exaggeration that makes a flat model about ``ratio`` as tall as wide.

    >>> auto_exaggeration([[0, 0, 0], [10000, 8000, 50]])
    20.0
    >>> auto_exaggeration([[0, 0, 0], [10, 10, 10]])
    1.0
    """
    b = np.asarray(bounds, float)
    width, height = float(max(b[1, 0] - b[0, 0], b[1, 1] - b[0, 1])), float(b[1, 2] - b[0, 2])
    if not (height > 0 and width > 0):
        return 1.0
    want = ratio * width / height
    return float(max([n for n in NICE_EXAGGERATIONS if n <= want], default=1))


def load_model(source, kind: str | None = None, hints: dict | None = None) -> Any:
    """A model from a path (:func:`geoshade.load`, read as ``kind``) or as is."""

    hints = {k: v for k, v in (hints or {}).items() if v is not None}
    if not isinstance(source, str | Path):
        if hints:
            raise InputError(f"{', '.join(sorted(hints))}: hints apply to files only")
        return source
    return load(source, as_=kind, **hints)


def open_settings(kind: str, model, settings: dict, progress: Progress | None = None
                  ) -> tuple[dict, dict]:
    """``(options, prepared)``: what the viewer opens ``model`` with (CPU work, any thread).

    The options are the user's, and for what they leave out only what a window needs beyond a
    picture file: its keys drawn (``annotations``), a core's porosity profile (the panel's
    plot) and centred box for volumes beyond :data:`geoshade.core.values.DEFAULT_BOX_SIDE`, a
    grid's first property and its wells, a flat model's vertical exaggeration, a stack model's
    legend. Every option given is passed as it is: the selection, Otsu's threshold, the ROI,
    the colour range are decided by the part's options (:meth:`ViewOptions.resolve`), as on
    every other path, so the same options draw what ``geoshade <part> render`` draws.
    ``prepared`` carries a core's histogram (the panel's)."""
    opts = dict(settings)
    opts.setdefault("annotations", True)  # a viewer shows every picture with its keys
    prepared: dict = {}
    if kind == "core":
        from geoshade import core

        prepared["histogram"] = core.histogram(model, progress=progress)
        if opts.get("box") is None:
            opts["box"] = core.default_box(model)
        opts.setdefault("porosity", "z")
    elif kind == "grid":

        names = model.property_names()
        if "property" not in opts and names:
            opts["property"] = "PORO" if "PORO" in names else names[0]
        if opts.get("exaggeration") is None:
            opts["exaggeration"] = auto_exaggeration(display_bounds(model))
        if opts.get("wells", True) is True and model.meta.get("wells"):
            opts["wells"] = list(model.meta["wells"])
        elif opts.get("wells") is True:
            opts.pop("wells")
    elif kind == "stacks":
        if opts.get("exaggeration") is None:
            zl, zh = model.occupied_levels()
            b = model.bounds()
            b[:, 2] = model.origin[2] + np.array([zl, zh]) * model.spacing[2]
            opts["exaggeration"] = auto_exaggeration(b)
        opts.setdefault("legend", True)
    return {k: v for k, v in opts.items() if v is not None or k in settings}, prepared


def resolved_settings(cls, model, options: dict, progress: Progress | None = None) -> dict:
    """``options`` with what the part's options resolve from the data (a core's Otsu
    selection, its fitted ROI: :meth:`ViewOptions.resolve`) put in, done once here on the
    worker thread so that the View made on the GUI thread does no data work again."""
    opts = cls.Options.parse(model, **options)
    res = opts.resolve(model, progress)
    if res is opts:
        return options
    changed = {f: getattr(res, f) for f in type(res).__dataclass_fields__
               if getattr(res, f) is not getattr(opts, f)}
    return {**options, **changed}


@dataclass
class Opening:
    """What :func:`prepare` made on a worker thread, ready for :func:`make_view`."""

    cls: type
    model: Any
    options: dict
    prepared: dict


def prepare(source, kind: str | None = None, hints: dict | None = None,
            progress: Progress | None = None, **settings) -> Opening:
    """CPU half of opening (any thread): read, pick the part, defaults, the part's own
    preparation (:meth:`View.prepare_open`)."""
    model = load_model(source, kind, hints)
    k = view_kind(model, kind)
    cls = distributed_class(k) if settings.get("distributed") else view_class(k)
    model = cls.coerce(model, settings, progress)  # e.g. labelled voxels -> stacks
    options, prepared = open_settings(k, model, settings, progress)
    options = resolved_settings(cls, model, options, progress)
    model, more = cls.prepare_open(model, progress, **options)
    return Opening(cls, model, options, {**prepared, **more})


def make_view(opening: Opening, size=(800, 600), ctx=None) -> View:
    """GL half of opening (the GL thread): the View, which only uploads what was prepared."""
    return opening.cls(opening.model, size=size, ctx=ctx, prepared=opening.prepared,
                       **opening.options)


def open_view(source, kind: str | None = None, size=(800, 600), hints: dict | None = None,
              progress: Progress | None = None, ctx=None, **settings) -> View:
    """Read ``source`` (path or model) and make the View that shows it, here and now.

    Examples
    --------
    >>> from geoshade.compute.synthetic import synthetic_core
    >>> with open_view(synthetic_core(16), size=(64, 48)) as view:
    ...     img, stats = view.draw()
    >>> stats["kind"], stats["porosity"] > 0
    ('core', True)
    """
    return make_view(prepare(source, kind, hints, progress, **settings), size=size, ctx=ctx)


def demo_views() -> dict[str, tuple[type, Any, dict]]:
    """kind -> (View class, synthetic model, options) for every part."""
    out = {}
    for k in KINDS:
        cls = view_class(k)
        model, options = cls.demo()
        out[k] = (cls, model, options)
    return out


def run_now(jobs) -> None:
    """Run ``jobs`` (a Job or a list) on this thread."""
    for job in [jobs] if isinstance(jobs, Job) else list(jobs or ()):
        job.run()


__all__ = ["Job", "Opening", "auto_exaggeration", "demo_views", "distributed_class", "load_model",
           "make_view",
           "open_settings", "open_view", "prepare", "resolved_settings", "run_now"]
