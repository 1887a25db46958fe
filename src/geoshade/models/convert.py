"""The converters behind the models' ``to_pyvista()`` and ``to_xarray()`` methods: one registry,
resolved by name.

``models`` imports nothing above it (the layers contract of ``lint-imports``), so a method does
not import its converter: :data:`CONVERTERS` names it (``"module:function"``, as zarr's codec
registry names its codecs) and :func:`convert` imports it the first time it is called. The
registry is filled once, here, so a conversion gives the same result whatever was imported
before it: a grid's ``to_xarray()`` carries its ECLIPSE keyword units
(:mod:`geoshade.models.units`) with or without ``geoshade.api``. PyVista or xarray load only when
a conversion runs. (The forbidden contract "Models look nothing up by name" lets this one module
use ``importlib``, for this.)
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

from geoshade.errors import InputError

#: converter name (``to_pyvista``, ``to_xarray``) -> ``"module:function"`` (imported when first
#: used) or ``function(model, **options)``
CONVERTERS: dict[str, str | Callable[..., Any]] = {
    "to_pyvista": "geoshade.io.interop.pyvista_io:to_pyvista",
    "to_xarray": "geoshade.io.interop.xarray_io:to_xarray",
}


def register_converter(name: str, function: str | Callable[..., Any]) -> None:
    """Make ``function(model, **options)`` (or the ``"module:function"`` it names) the
    converter ``name`` of the models' methods.

    >>> register_converter("to_text", lambda model, **o: repr(model))
    >>> convert("to_text", 3)
    '3'
    >>> del CONVERTERS["to_text"]
    """
    CONVERTERS[name] = function


def convert(function: str, model, **options) -> Any:
    """The converter ``function`` applied to ``model``.

    >>> import numpy as np
    >>> from geoshade.models import VoxelVolume
    >>> convert("to_xarray", VoxelVolume(np.zeros((1, 1, 2), np.uint8))).dims
    ('z', 'y', 'x')
    """
    try:
        fn = CONVERTERS[function]
    except KeyError:
        raise InputError(f"{type(model).__name__}.{function}: no such conversion; expected one "
                         f"of {', '.join(sorted(CONVERTERS))}") from None
    if isinstance(fn, str):
        module, _, attr = fn.partition(":")
        fn = CONVERTERS[function] = getattr(importlib.import_module(module), attr)
    return fn(model, **options)


__all__ = ["CONVERTERS", "convert", "register_converter"]
