"""The browser's panels, generated from the part's options class and its View.

A panel is a list of controls (plain dicts, sent as JSON): the words of a choice come from the
options class's ``CHOICES``, the check boxes from its ``FLAGS``, the defaults from
``default()``; what depends on the data (a grid's properties and report steps, a core's values)
from the View. The browser turns each control into a widget and sends ``{name: value}`` back,
which :meth:`geoshade.render.view.View.jobs` checks like any other change.

>>> from geoshade.grid.options import GridOptions
>>> [c["name"] for c in option_controls(GridOptions)][:3]
['faults', 'edges', 'triad']
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.models.steps import step_label
from geoshade.stacks import section_plane
from geoshade.styles.options import ColorStyle
from geoshade.styles.palette import SUGGESTED

#: option words and flags a browser does not change (they fix how a View is opened, where it
#: draws, or what a picture file needs): the panels leave them to the command line
OPEN_ONLY = frozenset({"view", "transparent", "distributed", "approach", "zcorn_bits",
                       "zcorn_store", "wells_coords", "prefetch", "mesh_cache", "skip_patches",
                       "brick_skip", "trefoil_mode", "walk", "walk_from", "cull", "porosity",
                       "layout", "top_normals"})


def jsonable(value: Any) -> Any:
    """``value`` as plain JSON values (numpy scalars and arrays, tuples, slices, paths)."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, str | int | float | bool) or value is None:
        return value
    if isinstance(value, slice):
        return [value.start, value.stop]
    if isinstance(value, np.ndarray):
        return value.tolist() if value.size <= 64 else f"array {value.shape}"
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [jsonable(v) for v in value]
    if isinstance(value, Path):
        return value.name
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return str(value)
    return str(value)


def _label(name: str) -> str:
    return name.replace("_", " ")


def option_controls(options_cls) -> list[dict]:
    """A select for each of the class's ``CHOICES`` and a check box for each of its ``FLAGS``
    (those in :data:`OPEN_ONLY` left out), with the class's defaults."""
    out = []
    for name, words in options_cls.CHOICES.items():
        if name in OPEN_ONLY:
            continue
        out.append({"name": name, "label": _label(name), "type": "select",
                    "choices": [jsonable(w) for w in words],
                    "default": jsonable(options_cls.default(name))})
    for name in options_cls.FLAGS:
        if name in OPEN_ONLY:
            continue
        out.append({"name": name, "label": _label(name), "type": "check",
                    "default": jsonable(options_cls.default(name))})
    return out


def camera_controls(view) -> list[dict]:
    """The named view, orthographic projection and (where the part has one) the vertical
    exaggeration."""
    cls = view.Options
    out = [{"name": "view", "label": "view", "type": "select",
            "choices": list(cls.choices("view")), "default": "iso"},
           {"name": "ortho", "label": "orthographic", "type": "check", "default": False}]
    if view.has_exaggeration:
        out.append({"name": "exaggeration", "label": "exaggeration", "type": "number",
                    "min": 0.01, "step": "any", "default": cls.default("exaggeration")})
    return out


def color_controls(view) -> list[dict]:
    """Colour map, range, log scale, reversed, categorical (parts whose options have a
    :class:`ColorStyle`)."""
    if "color" not in {f.name for f in dataclasses.fields(view.Options)}:
        return []
    style = ColorStyle()
    return [
        {"name": "colormap", "label": "colour map", "type": "select",
         "choices": list(SUGGESTED), "default": style.colormap},
        {"name": "color_range", "label": "colour range", "type": "pair",
         "default": None, "placeholder": "auto"},
        {"name": "log", "label": "log scale", "type": "select",
         "choices": ["auto", True, False], "default": "auto"},
        {"name": "reverse", "label": "reversed", "type": "check", "default": style.reverse},
        {"name": "categorical", "label": "categorical", "type": "select",
         "choices": ["auto", True, False], "default": "auto"},
    ]


def _steps(view, dates=()) -> dict | None:

    n = int(getattr(view, "nsteps", 0) or 0)
    if n <= 1:
        return None
    return {"name": "step", "label": "step", "type": "step", "min": 0, "max": n - 1,
            "labels": [step_label(k, dates) for k in range(n)]}


def _hex(rgba) -> str:
    return "#{:02x}{:02x}{:02x}".format(*(int(c) for c in rgba[:3]))


def part_controls(view, images=()) -> list[dict]:
    """What depends on the data: a grid's properties (or a typed expression), steps, filter,
    slice and wells; an isosurface's level and steps; a core's selection (or Otsu's), box, ROI
    and occlusion; a stack model's materials (visible, opacity), section and drape.

    A control sets the option of its ``name``, or those of its ``sets`` (a typed expression
    sets ``property``; the materials set ``hide`` and ``opacity``; the drape picker, listing
    ``images`` (catalogue names), sets ``drape``)."""
    kind, out = view.kind, []
    if kind == "grid":
        g = view.grid
        out.append({"name": "property", "label": "property", "type": "select",
                    "choices": [None, *view.property_names()]})
        out.append({"name": "expression", "sets": "property", "label": "expression",
                    "type": "text", "placeholder": "log10(PERMX) or PORO * NTG"})
        st = _steps(view, g.step_dates)
        if st:
            out.append(st)
        out.append({"name": "filter", "label": "filter", "type": "text",
                    "placeholder": "PORO > 0.2 and PERMX > 100"})
        out.append({"name": "slice", "label": "IJK slice", "type": "text",
                    "placeholder": "i=0:10,j=0:5,k=2 (0-based, end exclusive)"})
        # the wells the View opened with (--wells files, or the deck's), else the deck's
        wells = list(view.options.wells or g.meta.get("wells") or [])
        if wells:
            out.append({"name": "wells", "label": f"{len(wells)} wells", "type": "check"})
        if view.has_sim_wells():
            out.append({"name": "sim_wells", "label": "simulation wells", "type": "check"})
    elif kind == "iso":
        f = view.field
        out.append({"name": "level", "label": "isosurface level", "type": "number",
                    "step": "any"})
        st = _steps(view, getattr(f, "times", ()) or ())
        if st:
            out.append(st)
        names = list(getattr(f, "properties", {}) or {})
        if names:
            out.append({"name": "color_by", "label": "colour by", "type": "select",
                        "choices": [None, *names]})
    elif kind == "core":
        out.append({"name": "select", "label": "selected values", "type": "pair"})
        out.append({"name": "otsu", "sets": "select", "label": "Otsu (pore space)",
                    "type": "button", "value": "auto"})
        out.append({"name": "box", "label": "box x0 y0 z0 nx ny nz", "type": "ints", "n": 6})
        out.append({"name": "roi", "label": "ROI", "type": "text",
                    "placeholder": "cylinder, or cylinder:CX,CY,R"})
        out.append({"name": "occlusion", "label": "occlusion", "type": "select",
                    "choices": ["auto", True, False]})
    elif kind == "stacks":
        out.append({"name": "materials", "sets": ["hide", "opacity"],
                    "label": "materials (visible, opacity)", "type": "materials",
                    "items": [[int(c), str(n), _hex(rgba)] for c, n, rgba in view.materials()]})
        out.append({"name": "section", "sets": "plane", "label": "section", "type": "section",
                    "axes": ["x", "y", "z"]})
        if images:   # the pictures the server shows, by name (never a path)
            out.append({"name": "drape_file", "sets": "drape", "label": "drape image file",
                        "type": "select", "choices": [None, *images]})
        if view.options.drape is not None or images:
            out.append({"name": "drape", "label": "drape image", "type": "check"})
            out.append({"name": "drape_mix", "label": "drape mix", "type": "number",
                        "min": 0, "max": 1, "step": 0.1})
    return out


def panel_spec(view, images=()) -> list[dict]:
    """Every control of ``view``'s panel, grouped: ``[{"group": ..., "controls": [...]}]``
    (``images``: the catalogue's pictures a stack model may be draped with)."""
    groups = [("model", part_controls(view, images)), ("colour", color_controls(view)),
              ("camera", camera_controls(view)), ("options", option_controls(view.Options))]
    return [{"group": g, "controls": c} for g, c in groups if c]


def settable(panel: list[dict]) -> set[str]:
    """The option names the controls of ``panel`` set: the only names a browser's change may
    carry (a file option such as ``mask`` or ``drape`` never comes as a path from the browser).

    Parameters
    ----------
    panel : list of dict
        :func:`panel_spec`.

    Returns
    -------
    set of str

    Examples
    --------
    >>> sorted(settable([{"group": "g", "controls": [{"name": "otsu", "sets": "select"},
    ...                                              {"name": "faults"}]}]))
    ['faults', 'select']
    """
    out: set[str] = set()
    for g in panel:
        for c in g["controls"]:
            sets = c.get("sets", c["name"])
            out.update([sets] if isinstance(sets, str) else sets)
    return out


#: controls whose "auto" word means None (the part decides)
_AUTO = ("log", "categorical", "occlusion")


def from_browser(name: str, value: Any, view, opened: dict | None = None) -> dict:
    """A control's value as the View's options ``{name: value}``: ``"auto"`` and empty text
    are None, a pair is a tuple, the wells check box the wells the View opened with
    (``opened["wells"]``: ``--wells`` files) or the deck's (or None), a section
    ``[axis, fraction, flip]`` is its plane (:func:`geoshade.stacks.section_plane`), the drape
    check box the image the View opened with (``opened["drape"]``), a drape picture's
    catalogue name its file (``opened["resolve"]``; it becomes the check box's image),
    opacities by material code.

    Parameters
    ----------
    name : str
        The option the control sets.
    value : JSON value
    view : geoshade.render.view.View
    opened : dict, optional
        What the View opened with that a check box turns on again (``drape``, ``wells``).

    Returns
    -------
    dict
        ``{option: value}`` for :meth:`View.jobs`.

    Examples
    --------
    >>> from_browser("log", "auto", None), from_browser("color_range", [0, 1], None)
    ({'log': None}, {'color_range': (0, 1)})
    """
    if name != "select" and isinstance(value, str) and (
            value.strip() == "" or (name in _AUTO and value == "auto")):
        return {name: None}
    if name == "wells":
        wells = (opened or {}).get("wells") or view.grid.meta.get("wells") or []
        return {name: list(wells) if value else False}
    if name == "plane":
        if value is None:
            return {"plane": None}
        if not (isinstance(value, list) and len(value) == 3):
            raise InputError(f"section: expected [axis, fraction, flip], got {value!r}")
        return {"plane": section_plane(view.model, str(value[0]), float(value[1]),
                                       bool(value[2]))}
    if name == "drape":
        if isinstance(value, str):   # a picture chosen by its catalogue name (never a path):
            resolve = (opened or {}).get("resolve")
            if resolve is None:
                raise InputError("drape: a picture is chosen by its name in the server's list")
            path = resolve(value)   # InputError unless the server shows it
            if opened is not None:
                opened["drape"] = path   # what the check box turns on from now on
            return {name: path}
        return {name: (opened or {}).get("drape") if value else None}
    if name == "opacity":
        if not isinstance(value, dict):
            raise InputError(f"opacity: expected {{code: 0..1}}, got {value!r}")
        return {name: {int(k): float(v) for k, v in value.items()}}
    if isinstance(value, list):
        return {name: tuple(value)}
    return {name: value}
