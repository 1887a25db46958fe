"""Opening models in the viewer (no GUI toolkit): the part's View, the CPU work done before it
on a worker thread, and the defaults a viewer opens with.

The viewer shows the parts' Views themselves (:class:`geoshade.render.view.View`): their
``settings()``, ``jobs(**changes)`` (CPU half on a worker, GL half on the window's thread),
``readout()`` and ``camera()``; the histogram, default selection and porosity of a core come
from :mod:`geoshade.core`. Nothing here re-implements a part.

>>> from geoshade.compute.voxels.synthetic import synthetic_core
>>> view_kind(synthetic_core(8))
'core'
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from geoshade import core
from geoshade.api import KINDS, distributed_class, load, view_class, view_kind
from geoshade.errors import InputError
from geoshade.render.view import Job, Progress, View


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

    The options are the user's, nothing added: every default (a flat model's exaggeration, a
    grid's first property and its deck's wells, a big core's centred box, the porosity profile,
    the annotations) is the part's declared one, the same ``geoshade <part> render`` uses, so the
    same options draw the same picture everywhere. ``annotations`` is passed as its declared
    default (True) for the same reason the command line passes it. ``prepared`` carries what a
    panel shows beside the picture: a core's histogram."""
    opts = {"annotations": True, **settings}
    prepared: dict = {}
    if kind == "core":
        prepared["histogram"] = core.histogram(model, progress=progress)
    return opts, prepared


@dataclass
class Opening:
    """What :func:`prepare` made on a worker thread, ready for :func:`make_view`."""

    cls: type
    model: Any
    #: the part's options, checked and resolved once on the worker (Otsu's selection, the
    #: fitted ROI, the automatic exaggeration): the View made from them does no data work again
    options: Any
    prepared: dict


def prepare(source, kind: str | None = None, hints: dict | None = None,
            progress: Progress | None = None, **settings) -> Opening:
    """CPU half of opening (any thread): read, pick the part, defaults, the part's own
    preparation (:meth:`View.prepare_open`)."""
    model = load_model(source, kind, hints)
    k = view_kind(model, kind)
    cls = distributed_class(k) if settings.get("distributed") else view_class(k)
    model = cls.coerce(model, settings, progress)  # e.g. labelled voxels -> stacks
    settings, prepared = open_settings(k, model, settings, progress)
    options = cls.Options.parse(model, **settings).resolve(model, progress)
    model, more = cls.prepare_open(model, progress, options=options)
    return Opening(cls, model, options, {**prepared, **more})


def make_view(opening: Opening, size=(800, 600), ctx=None) -> View:
    """GL half of opening (the GL thread): the View, which only uploads what was prepared."""
    return opening.cls(opening.model, size=size, ctx=ctx, prepared=opening.prepared,
                       options=opening.options)


def open_view(source, kind: str | None = None, size=(800, 600), hints: dict | None = None,
              progress: Progress | None = None, ctx=None, **settings) -> View:
    """Read ``source`` (path or model) and make the View that shows it, here and now.

    Examples
    --------
    >>> from geoshade.compute.voxels.synthetic import synthetic_core
    >>> with open_view(synthetic_core(16), size=(64, 48), porosity="z") as view:
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


__all__ = ["Job", "Opening", "demo_views", "distributed_class", "load_model",
           "make_view",
           "open_settings", "open_view", "prepare", "run_now"]
