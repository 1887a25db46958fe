"""The runnable examples in the docstrings of compute/, styles/ and core/plots.py."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "geoshade.compute.selection",
    "geoshade.compute.bitmaps",
    "geoshade.compute.visibility",
    "geoshade.compute.porosity",
    "geoshade.compute.synthetic",
    "geoshade.styles.palette",
    "geoshade.styles.light",
    "geoshade.core.plots",
]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0, f"{name} has no examples"
    assert result.failed == 0
