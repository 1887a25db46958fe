"""The runnable examples in the grid part's docstrings (some need the GL context)."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "geoshade.grid",
    "geoshade.grid.api",
    "geoshade.render.visuals.grid.layout",
    "geoshade.render.visuals.grid.prepare",
    "geoshade.render.visuals.grid.framing",
    "geoshade.render.visuals.wells.visual",
]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(ctx, name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0, f"{name} has no examples"
    assert result.failed == 0
