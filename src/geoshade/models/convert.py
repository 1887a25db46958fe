"""The models' conversion methods (``to_pyvista()``, ``to_xarray()``) call the public functions
of :mod:`geoshade.api` (:func:`geoshade.to_pyvista`, :func:`geoshade.to_xarray`), looked up by
name when a method is called.

So ``models`` imports nothing above it (the layers contract of ``lint-imports``: the
conversions live in ``io/interop/pyvista_io.py`` and ``io/interop/xarray_io.py``), and PyVista or
xarray load
only when a conversion is asked for.
"""

from __future__ import annotations

import importlib
from typing import Any


def convert(function: str, model, **options) -> Any:
    """``geoshade.api.<function>(model, **options)``, imported now.

    >>> import numpy as np
    >>> from geoshade.models import VoxelVolume
    >>> convert("to_xarray", VoxelVolume(np.zeros((1, 1, 2), np.uint8))).dims
    ('z', 'y', 'x')
    """
    return getattr(importlib.import_module("geoshade.api"), function)(model, **options)


__all__ = ["convert"]
