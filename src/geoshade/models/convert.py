"""The converters behind the models' ``to_pyvista()`` and ``to_xarray()`` methods.

``models`` imports nothing above it (the layers contract of ``lint-imports``; a forbidden
contract keeps ``importlib`` out of ``geoshade.models``), so the converters are *registered
downward*: ``geoshade.io`` registers the plain ones of ``io/interop`` at its import
(:func:`geoshade.io.interop.register_conversions`) and ``geoshade.api`` registers its own (a
grid's ``to_xarray`` with the ECLIPSE keyword units) at its import. A method looks the name up
here when it is called; PyVista or xarray load only then.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from geoshade.errors import InputError

#: converter name (``to_pyvista``, ``to_xarray``) -> ``function(model, **options)``
CONVERTERS: dict[str, Callable[..., Any]] = {}


def register_converter(name: str, function: Callable[..., Any]) -> None:
    """Make ``function(model, **options)`` the converter ``name`` of the models' methods (a
    later registration replaces an earlier one: ``geoshade.api`` refines ``geoshade.io``'s).

    >>> register_converter("to_text", lambda model, **o: repr(model))
    >>> convert("to_text", 3)
    '3'
    >>> del CONVERTERS["to_text"]
    """
    CONVERTERS[name] = function


def convert(function: str, model, **options) -> Any:
    """The registered converter ``function`` applied to ``model``.

    >>> import numpy as np
    >>> import geoshade.io   # registers the converters of io/interop
    >>> from geoshade.models import VoxelVolume
    >>> convert("to_xarray", VoxelVolume(np.zeros((1, 1, 2), np.uint8))).dims
    ('z', 'y', 'x')
    """
    try:
        fn = CONVERTERS[function]
    except KeyError:
        raise InputError(f"{type(model).__name__}.{function}: no converter is registered; "
                         "import geoshade.io (or use geoshade." + function + ")") from None
    return fn(model, **options)


__all__ = ["CONVERTERS", "convert", "register_converter"]
