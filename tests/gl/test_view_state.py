"""Issue 33 item 4: a View's state as plain JSON reopens the same picture: ``geoshade.view(
model, **json.loads(json.dumps(view.state(cam))))`` draws what ``view.draw(cam)`` draws, pixel
for pixel, for every part, after changes and with a turned camera."""

from __future__ import annotations

import json

import numpy as np
import pytest

import geoshade
from geoshade.api import view_class

pytestmark = pytest.mark.gl
SIZE = (240, 180)

CHANGES = {
    "core": {"select": (0, 9000), "colormap": "magma", "box": [4, 4, 4, 40, 40, 40],
             "method": "cubes", "exaggeration": 2.0},
    "grid": {"property": "SWAT", "step": 1, "filter": "PORO > 0.15", "slice": "k=1:6",
             "edges": "quad", "color_range": (0.2, 0.7), "plane": "1,0,0", "faults": "hide"},
    "iso": {"level": 0.4, "step": 2, "color_by": "PRESSURE", "colormap": "plasma",
            "caps": True},
    "stacks": {"hide": None, "walk": "paper", "top": "flat", "smooth": 0.0},
}


@pytest.mark.parametrize("kind", sorted(CHANGES))
def test_state_reopens_the_picture(ctx, kind):
    cls = view_class(kind)
    model, options = cls.demo()
    options = {**options, "size": SIZE, "annotations": True}
    changes = {k: v for k, v in CHANGES[kind].items() if v is not None}
    if kind == "stacks":
        changes["hide"] = [int(model.legend.codes[0])]
    with cls(model, ctx=ctx, **options) as v:
        v.update(**changes)
        cam = v.camera(azimuth=70, elevation=40, zoom=1.3)
        want, _ = v.draw(cam)
        state = json.loads(json.dumps(v.state(cam)))   # plain JSON, as an address carries it
        left = geoshade.render.state.left_out(v)
    assert "camera" in state and all(k in state for k in changes if k not in ("color_range",
                                                                           "colormap"))
    reopened = {k: v for k, v in options.items() if k in left}   # arrays: given again
    with cls(model, ctx=ctx, **reopened, **state) as w:
        got, _ = w.draw()
    assert np.array_equal(got, want), f"{int(np.any(got != want, -1).sum())} pixels differ"


def test_state_without_a_camera_keeps_the_named_view(ctx):
    model, options = view_class("grid").demo()
    with geoshade.view(model, ctx=ctx, size=SIZE, view="top", ortho=True, **options) as v:
        state = v.state()
        want, _ = v.draw()
    assert state["view"] == "top" and state["ortho"] is True and "camera" not in state
    with geoshade.view(model, ctx=ctx, **{**state, "wells": options["wells"]}) as w:
        got, _ = w.draw()
    assert np.array_equal(got, want)
