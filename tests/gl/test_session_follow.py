"""Issue 30: a status line belongs to the state it describes: after an options change drawn
through the same camera, the last pick is made again (the pick line follows the property and
the step); a camera moved since leaves it."""

from __future__ import annotations

import pytest

from geoshade.api import view_class
from geoshade.viewer.session import Session
from geoshade.viewer.views import open_view

pytestmark = pytest.mark.gl


def test_the_pick_line_follows_the_property(ctx):
    grid, options = view_class("grid").demo()
    view = open_view(grid, size=(240, 180), ctx=ctx, **{**options, "property": "PORO"})
    try:
        s = Session(view, size=(240, 180))
        s.draw()
        hit = next(h for xy in ((120, 90), (100, 100), (90, 110), (130, 80), (80, 90))
                   if (h := s.pick(*xy)) is not None)
        assert hit.name == "PORO"
        first = s.pick_text
        view.update(property="PERMX")
        s.draw()
        assert s.picked.name == "PERMX" and s.picked.index == hit.index
        assert s.pick_text != first and "PERMX" in s.pick_text
        s.orbit(40, 0)        # the camera moved: that pixel shows another cell now
        view.update(property="NTG")
        s.draw()
        assert s.picked.name == "PERMX"
    finally:
        view.release()
