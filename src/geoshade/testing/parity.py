"""Live-change parity: ``view.update(name=x)`` draws what ``geoshade.view(model, name=x)``
draws, for every option the declarations say may change live (:mod:`geoshade.styles.declare`).

The values tried come from the declarations too: an option's ``example``, else a word of its
``choices`` other than the default, else the other state of a switch. A test suite runs
:func:`parity_cases` through :func:`check_parity`:

>>> from geoshade.testing.parity import parity_cases
>>> cases = parity_cases("grid")
>>> ("edges", "quad") in [(c.name, c.value) for c in cases]
True
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from geoshade.api import view_class
from geoshade.errors import InputError

#: the picture size the parity pictures are drawn at (annotations on: the keys change too)
SIZE = (240, 180)
#: more starting points for the colour options: part -> options (a grid coloured by integer
#: region codes, where ``categorical`` decides between a legend and a colour bar)
COLOUR_BASES = {"grid": ({"property": "FIPNUM"},), "iso": ({"color_by": None},)}
#: the options an option's case must start from to mean anything (a difference is of a
#: report-step property; an isosurface's change without a level assumes one, again on update)
CASE_BASES = {("grid", "diff"): {"property": "SWAT"}, ("iso", "diff"): {"level": None}}


@dataclass(frozen=True)
class Case:
    """One option of one part and the value it changes to."""

    kind: str
    name: str
    value: Any
    live: bool
    #: options the case opens with beyond the demo's (e.g. an integer property)
    base: tuple = ()

    @property
    def id(self) -> str:
        more = "".join(f"[{k}={v}]" for k, v in self.base)
        return f"{self.kind}-{self.name}{more}"


def example_value(opt, default, model=None):
    """A value of an option other than its default, from its declaration (None: none)."""
    if opt.example is not None:
        return opt.example(model) if callable(opt.example) else opt.example
    if opt.choices:
        return next((c for c in opt.choices if c != default), None)
    if opt.form == "switch":
        return (not default) if isinstance(default, bool) else True
    return None


def demo(kind: str) -> tuple[Any, dict]:
    """The part's demo model and the options a parity case starts from."""
    cls = view_class(kind)
    model, options = cls.demo()
    return model, {**options, "size": SIZE, "annotations": True}


def parity_cases(kind: str) -> list[Case]:
    """Every option of part ``kind`` with a value to change to (options without a flag or
    value, such as an explicit palette, are left out)."""
    cls = view_class(kind)
    model, _ = demo(kind)
    out = []
    for name, (opt, default) in cls.Options.declarations().items():
        if name in ("camera", "palette", "select_auto", "variable", "empty", "logs", "keyword"):
            continue
        value = example_value(opt, default, model)
        if value is None:
            continue
        out.append(Case(kind, name, value, opt.live,
                        tuple(CASE_BASES.get((kind, name), {}).items())))
        if opt.group == "colour":
            out += [Case(kind, name, v, opt.live, tuple(b.items())) for b in
                    COLOUR_BASES.get(kind, ())
                    for v in ([value, True] if name == "categorical" else [value])]
    return out


def check_parity(case: Case, ctx=None) -> None:
    """Assert ``update(name=value)`` ≡ open with ``name=value`` (pixel for pixel, and the
    stats' colour key), or, for an option fixed at opening, that ``update`` refuses it in one
    line."""
    cls = view_class(case.kind)
    model, base = demo(case.kind)
    base.update(case.base)
    with cls(model, ctx=ctx, **base) as a:
        a.draw()
        if not case.live:
            try:
                a.update(**{case.name: case.value})
            except InputError as err:
                assert "fixed when" in str(err), str(err)
                return
            raise AssertionError(f"{case.id}: update() took an option fixed at opening")
        a.update(**{case.name: case.value})
        img_a, st_a = a.draw()
    with cls(model, ctx=ctx, **{**base, case.name: case.value}) as b:
        img_b, st_b = b.draw()
    assert img_a.shape == img_b.shape, f"{case.id}: {img_a.shape} vs {img_b.shape}"
    differ = int(np.count_nonzero(np.any(img_a != img_b, axis=-1)))
    assert differ == 0, (f"{case.id}={case.value!r}: update() then draw differs from opening "
                         f"with it in {differ} of {img_a.shape[0] * img_a.shape[1]} pixels")
    for key in ("categories", "color_range", "property", "step"):
        assert st_a.get(key) == st_b.get(key), f"{case.id}: stats[{key!r}] differ"


__all__ = ["SIZE", "Case", "check_parity", "demo", "example_value", "parity_cases"]
