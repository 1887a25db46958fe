"""The controls of every viewer, made from the options' declarations (no GUI toolkit).

A View's controls are typed specs (plain dicts, sent as JSON to a browser, turned into widgets by
the Qt window): one per option its declaration gives a control (:func:`geoshade.styles.declare.
control_type`) and that can change on an open View (``live``), in the declaration's group, with
its words, default and help; what depends on the data comes from the View (a grid's properties
and report steps, an isosurface's colour-by quantities, a core's selection, a stack model's
materials). Qt and the browser each render a control *type* once, so every control exists in
both. A control's value goes back through :func:`to_options` and :meth:`View.jobs`, which
checks it like any other change.

>>> from geoshade.grid.options import GridOptions
>>> names = [c["name"] for c in option_controls(GridOptions)]
>>> "faults" in names, "scheduler" in names     # fixed when a View opens: no control
(True, False)
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.iso.keyword import keywords
from geoshade.models.steps import step_label
from geoshade.styles.declare import GROUPS, control_type
from geoshade.styles.palette import SUGGESTED

#: the control types a viewer renders (each once, in Qt and in the browser)
TYPES = ("select", "check", "number", "text", "pair", "ints", "step", "button", "materials",
         "section", "ijk", "ranges", "vectors")
#: controls whose "auto" word means None (the part decides)
AUTO = "auto"


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


def _spec(name: str, opt, default, ctype: str) -> dict | None:
    """The control of one option from its declaration alone (None: it needs the data)."""
    base = {"name": name, "label": _label(name), "help": opt.help, "group": opt.group}
    if ctype == "select":   # None first where it is the default (no porosity profile...)
        return {**base, "type": "select", "default": jsonable(default),
                "choices": [None] * (default is None) + [jsonable(w) for w in opt.choices]}
    if ctype == "check":
        return {**base, "type": "check", "default": bool(default)}
    if ctype == "tristate":
        return {**base, "type": "select", "choices": [AUTO, True, False], "default": AUTO,
                "auto": True}
    if ctype == "colormap":
        return {**base, "type": "select", "choices": list(SUGGESTED), "default": default,
                "editable": True}
    if ctype == "number":
        spec = {**base, "type": "number", "step": "any", "default": jsonable(default)}
        if opt.limits is not None:
            spec["min"], spec["max"] = opt.limits
        return spec
    if ctype == "pair":
        return {**base, "type": "pair", "default": jsonable(default), "placeholder": AUTO}
    if ctype == "ints":
        return {**base, "type": "ints", "n": int(opt.nargs), "default": jsonable(default)}
    if ctype == "text":
        return {**base, "type": "text", "default": jsonable(default),
                "placeholder": str(opt.example) if isinstance(opt.example, str) else ""}
    return None


def option_controls(options_cls) -> list[dict]:
    """The controls the declarations of ``options_cls`` give without any data: words,
    switches, numbers, text and colours of every option that can change on an open View."""
    out = []
    for name, (opt, default) in options_cls.declarations().items():
        ctype = control_type(opt, default)
        if not opt.live or not ctype:
            continue
        spec = _spec(name, opt, default, ctype)
        if spec is not None:
            out.append(spec)
    return out


def _steps(view, dates=()) -> dict | None:
    n = int(getattr(view, "nsteps", 0) or 0)
    if n <= 1:
        return None
    return {"name": "step", "type": "step", "min": 0, "max": n - 1,
            "labels": [step_label(k, dates) for k in range(n)]}


def _hex(rgba) -> str:
    return "#{:02x}{:02x}{:02x}".format(*(int(c) for c in rgba[:3]))


def data_controls(view, name: str, ctype: str, images=()) -> list[dict]:
    """The controls of an option whose choices come from the data (``ctype`` from its
    declaration): a grid's property (and a typed expression), report steps, wells; an
    isosurface's colour-by quantities; a core's selection (and Otsu's); a stack model's
    materials, section and drape (``images``: the pictures a server lists by name)."""
    kind = view.kind
    if ctype == "property":
        return [{"name": "property", "type": "select",
                 "choices": [None, *view.property_names()]},
                {"name": "expression", "sets": "property", "label": "expression",
                 "type": "text", "placeholder": "log10(PERMX) or PORO * NTG"}]
    if ctype == "step":
        model = view.model
        dates = (model.step_dates if kind == "grid" else getattr(model, "times", ())) or ()
        st = _steps(view, dates)
        return [st] if st else []
    if ctype == "steps":   # a step to compare with (None: none), by date where dates are known
        model = view.model
        n = int(getattr(view, "nsteps", 0) or 0)
        dates = [str(d) for d in ((model.step_dates if kind == "grid"
                                   else getattr(model, "times", ())) or ())]
        named = len(dates) == n and len(set(dates)) == n and not any(
            d.startswith("step ") for d in dates)
        return [{"name": name, "type": "select",
                 "choices": [None, *(dates if named else range(n))]}] if n > 1 else []
    if ctype == "color_by":   # what is read, and what the file can still give
        m = view.model
        names = list(dict.fromkeys([*(getattr(m, "properties", {}) or {}),
                                    *((getattr(m, "meta", None) or {}).get("quantities")
                                      or ())]))
        return [{"name": "color_by", "type": "select", "choices": [None, *names]}] \
            if names else []
    if ctype == "keyword":   # the quantities of the field's file the isosurface can show
        names = keywords(view.model)
        return [{"name": name, "type": "select", "choices": names}] if len(names) > 1 else []
    if ctype == "wells":
        g = view.model
        wells = list(view.options.wells or g.meta.get("wells") or [])
        return [{"name": "wells", "label": f"{len(wells)} wells", "type": "check"}] \
            if wells else []
    if ctype == "selection":
        return [{"name": "select", "label": "selected values", "type": "pair"},
                {"name": "otsu", "sets": "select", "label": "Otsu (pore space)",
                 "type": "button", "value": "auto"}]
    if ctype == "materials":
        if name != "hide":
            return []
        return [{"name": "materials", "sets": ["hide", "opacity"],
                 "label": "materials (visible, opacity)", "type": "materials",
                 "items": [[int(c), str(n), _hex(rgba)] for c, n, rgba in view.materials()]}]
    if ctype == "section":   # a plane across x, y or z of the model's box
        return [{"name": "section", "sets": "plane", "label": "section", "type": "section",
                 "axes": ["x", "y", "z"]}]
    if ctype == "ijk":   # I/J/K range sliders (0-based, end exclusive)
        return [{"name": name, "label": "I, J, K ranges", "type": "ijk",
                 "dims": [int(n) for n in view.model.dims], "default": None}]
    if ctype == "ranges":   # min/max sliders of each property with values
        # (a name a filter cannot spell, ECLIPSE's MULTZ-, has no slider: the ranges are a
        # filter's terms)
        items = [[n, lo, hi] for n, (lo, hi) in view.property_ranges().items()
                 if str(n).isidentifier()]
        return [{"name": name, "label": "value ranges", "type": "ranges",
                 "items": jsonable(items)}] if items else []
    if ctype == "vectors":   # the case's summary vectors, where it has some
        from geoshade.io.grids.summary import case_spec  # resfo

        try:
            keys = list(case_spec(view.model).keys)
        except InputError:
            return []
        return [{"name": name, "label": "summary vectors", "type": "vectors",
                 "choices": keys, "default": None}] if keys else []
    if ctype == "drape":
        out = []
        if images:   # the pictures the server shows, by name (never a path)
            out.append({"name": "drape_file", "sets": "drape", "label": "drape image file",
                        "type": "select", "choices": [None, *images]})
        if view.options.drape is not None or images:
            out.append({"name": "drape", "label": "drape image", "type": "check"})
        return out
    return []


#: controls shown only where the data has what they show
APPLIES = {"sim_wells": lambda view: view.has_sim_wells(),
           "exaggeration": lambda view: view.has_exaggeration}


def controls(view, images=()) -> list[dict]:
    """Every control of ``view``, grouped as the declarations group them:
    ``[{"group": title, "controls": [...]}]`` (``images``: the server's pictures a stack model
    may be draped with)."""
    groups: dict[str, list[dict]] = {g: [] for g in GROUPS}
    for name, (opt, default) in view.Options.declarations().items():
        ctype = control_type(opt, default)
        if not opt.live or not ctype:
            continue
        if name in APPLIES and not APPLIES[name](view):
            continue
        made = _spec(name, opt, default, ctype)
        specs = [made] if made is not None else data_controls(view, name, ctype, images)
        for spec in specs:
            spec.setdefault("label", _label(spec["name"]))
            spec.setdefault("help", opt.help)
            spec["group"] = opt.group
            groups[opt.group].append(spec)
    return [{"group": GROUPS[g], "controls": c} for g, c in groups.items() if c]


def settable(panel: list[dict]) -> set[str]:
    """The option names the controls of ``panel`` set: the only names a browser's change may
    carry (a file option such as ``mask`` or ``drape`` never comes as a path from the browser).

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


def _auto_names(view) -> set[str]:
    return {n for n, (opt, d) in view.Options.declarations().items()
            if control_type(opt, d) == "tristate"} if view is not None else \
        {"log", "categorical", "occlusion", "sim_wells", "smear_faults"}


def ijk_text(value, dims=None) -> str | None:
    """The I/J/K sliders' ``[[i0, i1], [j0, j1], [k0, k1]]`` (0-based, end exclusive) as a
    slice option; an axis at its full range (``dims``) is left out; None: nothing cut.

    >>> ijk_text([[0, 10], [2, 5], [0, 3]], (10, 8, 3)), ijk_text([[0, 4]] * 3, (4, 4, 4))
    ('j=2:5', None)
    """
    if not (isinstance(value, list | tuple) and len(value) == 3):
        raise InputError(f"slice: expected [[i0, i1], [j0, j1], [k0, k1]], got {value!r}")
    parts = []
    for a, pair in enumerate(value):
        try:
            lo, hi = (int(v) for v in pair)
        except (TypeError, ValueError):
            raise InputError(f"slice: expected [[i0, i1], [j0, j1], [k0, k1]] of whole "
                             f"numbers, got {value!r}") from None
        if dims is not None and lo <= 0 and hi >= int(dims[a]):
            continue
        parts.append(f"{'ijk'[a]}={lo}:{hi}")
    return ",".join(parts) or None


def to_options(name: str, value: Any, view, opened: dict | None = None) -> dict:
    """A control's value as the View's options ``{name: value}``: ``"auto"`` (of a tristate)
    and empty text are None, a pair is a tuple, the wells check box the wells the View opened
    with (``opened["wells"]``: ``--wells`` files) or the deck's (False: none), a section
    ``[axis, fraction, flip]`` is its plane (:func:`geoshade.stacks.section_plane`), the drape
    check box the image the View opened with (``opened["drape"]``), a drape picture's catalogue
    name its file (``opened["resolve"]``; it becomes the check box's image), opacities by
    material code.

    >>> to_options("log", "auto", None), to_options("color_range", [0, 1], None)
    ({'log': None}, {'color_range': (0, 1)})
    """
    if name != "select" and isinstance(value, str) and (
            value.strip() == "" or (name in _auto_names(view) and value == AUTO)):
        return {name: None}
    if name == "wells":
        wells = (opened or {}).get("wells") or view.model.meta.get("wells") or []
        return {name: list(wells) if value else False}
    if name == "plane" and view is not None and hasattr(view, "section_plane"):
        if value is None:
            return {"plane": None}
        if not (isinstance(value, list) and len(value) == 3):
            raise InputError(f"section: expected [axis, fraction, flip], got {value!r}")
        return {"plane": view.section_plane(str(value[0]), value[1], bool(value[2]))}
    if name == "slice" and isinstance(value, list):
        return {name: ijk_text(value, None if view is None else view.model.dims)}
    if name == "ranges":
        if value is not None and not isinstance(value, dict | str):
            raise InputError(f"ranges: expected {{NAME: [LO, HI]}}, got {value!r}")
        return {name: value or None}
    if name == "summary":
        return {name: value or None}
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


__all__ = ["APPLIES", "TYPES", "controls", "data_controls", "ijk_text", "jsonable",
           "option_controls", "settable", "to_options"]
