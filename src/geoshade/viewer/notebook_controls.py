"""The notebook's widget of each control type (:data:`geoshade.viewer.controls.TYPES`), made
once with ipywidgets, as the desktop viewer's :mod:`geoshade.viewer.panels.widgets` and the
browser's ``makeControl`` make them: every control exists in the three.

:func:`make_controls` turns a View's control specs into one accordion page per declared group;
a widget sends the option values it stands for to ``send({option: value})`` when the user
changes it and shows a value with ``put(value)`` (:func:`geoshade.viewer.values.control_values`)
without sending. ``ijk`` is three double-ended sliders (I, J, K, 1-based as ECLIPSE counts),
``ranges`` a double-ended slider of the chosen property's values, ``vectors`` a box of
comma-separated summary vectors with a completing box to add one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from geoshade.viewer.values import slider_value

#: a control's value -> the options it sends ({option: value})
Send = Callable[[dict], None]
#: positions of a range slider between a property's min and max
RANGE_STEPS = 1000



def _label(value: Any) -> str:
    return "(none)" if value is None else "yes" if value is True else "no" \
        if value is False else str(value)


def _fmt(v: Any) -> str:
    if isinstance(v, bool) or not isinstance(v, int | float):
        return "" if v is None else str(v)
    return str(v) if isinstance(v, int) else f"{v:.6g}"


def _number(text: str, what: str, whole: bool = False) -> float | int:
    try:
        v = float(text)
    except ValueError:
        raise ValueError(f"{what}: expected a number, got {text!r}") from None
    if whole and not v.is_integer():
        raise ValueError(f"{what}: expected a whole number, got {text!r}")
    return int(v) if whole else v


class NotebookControl:
    """One control: ``widget`` (what is shown), ``put(value)`` (shows without sending)."""

    def __init__(self, spec: dict, send: Send, error: Callable[[str], None]):
        self.spec, self._send, self.error = spec, send, error
        sets = spec.get("sets", spec["name"])
        self.target = sets if isinstance(sets, str) else spec["name"]
        self.quiet = False   # True while showing a value: nothing is sent
        self.widget: Any = None

    def send(self, value: Any) -> None:
        if not self.quiet:
            self._send({self.target: value})

    def showing(self, fn) -> None:
        """Run ``fn`` (which sets the widgets) without sending."""
        self.quiet = True
        try:
            fn()
        finally:
            self.quiet = False

    def put(self, value: Any) -> None: ...

    def watch(self, w, fn) -> None:
        """``fn(new value)`` when ``w`` 's value changes (not while showing)."""
        w.observe(lambda ch: None if self.quiet else fn(ch["new"]), names="value")


def _make(W, spec: dict, send: Send, error) -> NotebookControl:
    kind = spec["type"]
    c = NotebookControl(spec, send, error)
    desc = {"description": spec.get("label", spec["name"]), "tooltip":
            spec.get("help") or "", "style": {"description_width": "120px"}}
    if kind == "select":
        choices = list(spec.get("choices") or [])
        if spec.get("editable"):
            w = W.Combobox(options=[str(v) for v in choices], ensure_option=False,
                           continuous_update=False, **desc)
            c.watch(w, lambda v: v.strip() and c.send(v.strip()))
            c.put = lambda v: setattr(w, "value", "" if v is None else str(v))
        else:
            w = W.Dropdown(options=[(_label(v), k) for k, v in enumerate(choices)], **desc)
            c.watch(w, lambda k: c.send(choices[k]) if k is not None else None)

            def put_select(v):
                for k, ch in enumerate(choices):
                    if (ch == v and type(ch) is type(v)) or (ch is None and v is None):
                        w.value = k
                        return
                choices.append(v)
                w.options = [(_label(x), k) for k, x in enumerate(choices)]
                w.value = len(choices) - 1
            c.put = put_select
    elif kind == "check":
        w = W.Checkbox(value=bool(spec.get("default")), indent=False, **desc)
        c.watch(w, c.send)
        c.put = lambda v: setattr(w, "value", bool(v))
    elif kind in ("number", "text"):
        w = W.Text(placeholder=str(spec.get("placeholder") or (
            "auto" if kind == "number" else "")), continuous_update=False, **desc)

        def typed(text):
            text = text.strip()
            if kind == "text":
                c.send(text)
            elif text:
                try:
                    c.send(_number(text, spec.get("label", spec["name"])))
                except ValueError as err:
                    error(str(err))
        c.watch(w, typed)
        c.put = lambda v: setattr(w, "value", _fmt(v) if kind == "number" else str(v or ""))
    elif kind in ("pair", "ints"):
        whole = kind == "ints"
        n = int(spec.get("n", 2)) if whole else 2
        names = list(spec.get("fields") or [])
        boxes = [W.Text(placeholder=str(names[k] if k < len(names) else
                                        spec.get("placeholder") or ""),
                        continuous_update=False, layout={"width": "80px"}) for k in range(n)]
        w = W.HBox([W.Label(desc["description"], layout={"width": "120px"}), *boxes])

        def typed_all(_):
            texts = [b.value.strip() for b in boxes]
            if all(t == "" for t in texts):
                c.send(None)
            elif all(texts):
                try:
                    c.send([_number(t, spec.get("label", spec["name"]), whole) for t in texts])
                except ValueError as err:
                    error(str(err))
        for b in boxes:
            c.watch(b, typed_all)

        def put_numbers(v):
            vals = list(v) if isinstance(v, list | tuple) else [None] * n
            for b, x in zip(boxes, vals, strict=False):
                b.value = _fmt(x) if isinstance(x, int | float) and math.isfinite(x) else ""
        c.put = put_numbers
        c.boxes = boxes
    elif kind == "step":
        labels = list(spec.get("labels") or [])
        w = W.SelectionSlider(options=[(lab, k) for k, lab in enumerate(labels)],
                              continuous_update=False, **desc,
                              layout={"width": "100%"})
        c.watch(w, c.send)
        c.put = lambda v: setattr(w, "value", int(v)) if isinstance(v, int) else None
    elif kind == "button":
        w = W.Button(description=spec.get("label", spec["name"]),
                     tooltip=spec.get("help") or "")
        w.on_click(lambda _b: c.send(spec.get("value")))
    elif kind == "materials":
        rows, vis, op = [], {}, {}
        for code, name, colour in spec.get("items") or ():
            cb = W.Checkbox(value=True, description=f"{code} {name}", indent=False,
                            style={"background": colour})
            sl = W.FloatSlider(value=1.0, min=0, max=1, step=0.01, continuous_update=False,
                               description="opacity", readout_format=".0%")
            vis[int(code)], op[int(code)] = cb, sl
            rows.append(W.HBox([cb, sl]))
        w = W.VBox(rows)

        def changed(_):
            c.quiet or send({"hide": [k for k, cb in vis.items() if not cb.value],
                             "opacity": {k: s.value for k, s in op.items() if s.value < 1}})
        for x in (*vis.values(), *op.values()):
            x.observe(changed, names="value")

        def put_materials(v):
            hidden = set((v or {}).get("hide") or ())
            ops = (v or {}).get("opacity") or {}
            for k, cb in vis.items():
                cb.value = k not in hidden
                op[k].value = float(ops.get(k, 1.0))
        c.put = put_materials
    elif kind == "section":
        on = W.Checkbox(value=False, description="cut", indent=False, layout={"width": "60px"})
        axis = W.Dropdown(options=list(spec.get("axes") or ("x", "y", "z")),
                          layout={"width": "60px"})
        pos = W.FloatSlider(value=0.5, min=0.01, max=0.99, step=0.01, readout_format=".0%",
                            continuous_update=False)
        flip = W.Checkbox(value=False, description="flip", indent=False)
        w = W.HBox([W.Label(desc["description"], layout={"width": "120px"}), on, axis, pos,
                    flip])

        def cut(_):
            c.send([axis.value, pos.value, flip.value] if on.value else None)
        for x in (on, axis, pos, flip):
            c.watch(x, cut)

        def put_section(v):
            on.value = isinstance(v, list | tuple)
            if isinstance(v, list | tuple):
                axis.value, pos.value, flip.value = str(v[0]), float(v[1]), bool(v[2])
        c.put = put_section
    elif kind == "ijk":
        dims = [int(n) for n in spec.get("dims") or (1, 1, 1)]
        sliders = [W.IntRangeSlider(value=(1, n), min=1, max=max(n, 1), description=ax,
                                    continuous_update=False,
                                    tooltip=f"the {ax} shown, 1 to {n}")
                   for ax, n in zip("IJK", dims, strict=True)]
        w = W.VBox([W.Label(desc["description"]), *sliders])

        def cut_ijk(_):
            c.send([[int(s.value[0]) - 1, int(s.value[1])] for s in sliders])
        for s in sliders:
            c.watch(s, cut_ijk)

        def put_ijk(v):
            pairs = v if isinstance(v, list | tuple) and len(v) == 3 else \
                [[0, n] for n in dims]
            for s, (lo, hi), n in zip(sliders, pairs, dims, strict=True):
                s.value = (min(max(int(lo or 0) + 1, 1), n),
                           min(max(int(n if hi is None else hi), 1), n))
        c.put = put_ijk
        c.sliders = sliders
    elif kind == "ranges":
        extent = {str(n): (float(lo), float(hi)) for n, lo, hi in spec.get("items") or ()
                  if lo is not None and hi is not None}
        narrowed: dict[str, list] = {}
        name = W.Dropdown(options=list(extent), description="property")
        rng = W.FloatRangeSlider(min=0, max=RANGE_STEPS, step=1, value=(0, RANGE_STEPS),
                                 readout=False, continuous_update=False)
        ends = W.Label("")
        clear = W.Button(description="clear", tooltip="show the cells of every value again")
        summary = W.Label("every value shown")
        w = W.VBox([W.Label(desc["description"]), W.HBox([name, clear]),
                    W.HBox([rng, ends]), summary])

        def value_at(n, p):
            return slider_value(*extent[n], p, RANGE_STEPS)

        def show_chosen(*_):
            n = name.value
            if n not in extent:
                return
            lo, hi = extent[n]
            got = narrowed.get(n) or [None, None]
            a = lo if got[0] is None else float(got[0])
            b = hi if got[1] is None else float(got[1])
            span = (hi - lo) or 1.0

            def set_rng():
                rng.value = (round((a - lo) / span * RANGE_STEPS),
                             round((b - lo) / span * RANGE_STEPS))
            c.showing(set_rng)
            ends.value = f"{_fmt(a)} to {_fmt(b)}"
            summary.value = " · ".join(
                f"{k} {_fmt(v[0]) if v[0] is not None else '…'} to "
                f"{_fmt(v[1]) if v[1] is not None else '…'}" for k, v in narrowed.items()) \
                or "every value shown"

        def slid(ch):
            n = name.value
            if c.quiet or n not in extent:
                return
            lo_p, hi_p = ch["new"]
            pair = [None if lo_p <= 0 else value_at(n, lo_p),
                    None if hi_p >= RANGE_STEPS else value_at(n, hi_p)]
            kept = narrowed.get(n)
            for end in (0, 1):   # the end not moved keeps its value (a typed 0.2 stays 0.2)
                if kept is not None and ch["new"][end] == ch["old"][end]:
                    pair[end] = kept[end]
            if pair == [None, None]:
                narrowed.pop(n, None)
            else:
                narrowed[n] = pair
            show_chosen()
            c.send({k: list(p) for k, p in narrowed.items()})

        def cleared(_b):
            narrowed.clear()
            show_chosen()
            c.send({})
        name.observe(show_chosen, names="value")
        rng.observe(slid, names="value")
        clear.on_click(cleared)

        def put_ranges(v):
            narrowed.clear()
            for n, pair in (v or {}).items():
                key = next((k for k in extent if k.upper() == str(n).upper()), None)
                if key is not None:
                    narrowed[key] = [None if x is None else float(x) for x in pair]
            show_chosen()

        def set_range(n, lo, hi):   # exact ends, as typed (scripts and tests)
            name.value = n
            if lo is None and hi is None:
                narrowed.pop(n, None)
            else:
                narrowed[n] = [lo, hi]
            show_chosen()
            c.send({k: list(p) for k, p in narrowed.items()})
        c.put, c.set_range, c.slider = put_ranges, set_range, rng
        show_chosen()
    elif kind == "vectors":
        choices = [str(x) for x in spec.get("choices") or ()]
        box = W.Text(placeholder="FOPR, WBHP:*", continuous_update=False, **desc)
        add = W.Combobox(options=choices, placeholder="add a vector", ensure_option=False,
                         continuous_update=False, layout={"width": "200px"})
        w = W.HBox([box, add])

        def typed_names(text):
            names = [n.strip() for n in text.split(",") if n.strip()]
            c.send(names or None)

        def added(name_):
            if name_.strip():
                box.value = ", ".join([*(n.strip() for n in box.value.split(",")
                                         if n.strip()), name_.strip()])
                c.showing(lambda: setattr(add, "value", ""))
        c.watch(box, typed_names)
        c.watch(add, added)
        c.put = lambda v: setattr(box, "value", ", ".join(
            [v] if isinstance(v, str) else [str(x) for x in v or ()]))
        c.box = box
    else:
        raise ValueError(f"no notebook widget for control type {kind!r}")
    c.widget = w
    return c


def make_controls(groups: list[dict], send: Send, error: Callable[[str], None]):
    """``(accordion, made)``: one accordion page per group of ``groups``
    (:func:`~geoshade.viewer.controls.controls`), ``made`` the controls by name."""
    import ipywidgets as W  # noqa: N812

    made: dict[str, NotebookControl] = {}
    pages = []
    for g in groups:
        items = []
        for spec in g["controls"]:
            c = _make(W, spec, send, error)
            made[spec["name"]] = c
            items.append(c.widget)
        pages.append(W.VBox(items))
    acc = W.Accordion(children=pages, titles=tuple(g["group"] for g in groups))
    acc.selected_index = 0 if pages else None
    return acc, made


def put_all(made: dict[str, NotebookControl], values: dict[str, Any]) -> None:
    """Show ``values`` in the controls, sending nothing."""
    for name, value in values.items():
        c = made.get(name)
        if c is not None:
            c.showing(lambda c=c, value=value: c.put(value))


__all__ = ["NotebookControl", "make_controls", "put_all"]
