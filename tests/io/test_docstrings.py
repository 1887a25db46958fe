"""The examples in the io docstrings run and give what they show."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["__init__", "raw", "tiff", "npy", "zarr_io", "describe"]


@pytest.mark.parametrize("name", MODULES)
def test_examples(name):
    mod = importlib.import_module("geoshade.io" if name == "__init__" else f"geoshade.io.{name}")
    result = doctest.testmod(mod, optionflags=doctest.ELLIPSIS)
    assert result.failed == 0
    if name != "__init__":
        assert result.attempted > 0
