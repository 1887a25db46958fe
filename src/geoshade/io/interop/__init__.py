"""Models to and from other libraries: PyVista, xarray, mesh files."""

from __future__ import annotations

from geoshade.io.interop.pyvista_io import to_pyvista
from geoshade.io.interop.xarray_io import to_xarray
from geoshade.models.convert import CONVERTERS


def _to_pyvista(model, **options):

    return to_pyvista(model, **options)


def _to_xarray(model, name=None, units=None):

    return to_xarray(model, name=name, units=units)


def register_conversions() -> None:
    """Register the converters of this package for the models' ``to_pyvista()`` and
    ``to_xarray()`` methods (:mod:`geoshade.models.convert`); PyVista and xarray are imported
    only when a conversion runs. ``geoshade.io`` calls this at its import."""

    for name, fn in (("to_pyvista", _to_pyvista), ("to_xarray", _to_xarray)):
        CONVERTERS.setdefault(name, fn)   # geoshade.api's (with units) wins when registered


__all__ = ["register_conversions"]
