"""The saturation-isosurface part: tessellation marching cubes over the time steps of a field.

>>> import geoshade.iso
>>> from geoshade.compute.displacement import displacement_field
>>> field = displacement_field((32, 24, 24), steps=4)
>>> img, stats = geoshade.iso.render(field, 0.5, step=2, size="96x64")   # doctest: +SKIP
>>> stats["triangles"] > 0                                               # doctest: +SKIP
True
"""

from __future__ import annotations

from geoshade.iso.api import (
    DEFAULT_PATCH_LEVEL,
    METHOD,
    PAPER_PATCH_LEVEL,
    EmptySurfaceWarning,
    OutsideValuesWarning,
)
from geoshade.iso.tasks import animate, export_mesh, render
from geoshade.iso.view import IsoView

__all__ = [
    "DEFAULT_PATCH_LEVEL",
    "METHOD",
    "PAPER_PATCH_LEVEL",
    "EmptySurfaceWarning",
    "IsoView",
    "OutsideValuesWarning",
    "animate",
    "export_mesh",
    "render",
]
