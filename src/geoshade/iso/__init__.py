"""The saturation-isosurface part: tessellation marching cubes over the time steps of a field.

>>> import geoshade.iso
>>> from geoshade.compute.mesh.displacement import displacement_field
>>> field = displacement_field((32, 24, 24), steps=4)
>>> img, stats = geoshade.iso.render(field, 0.5, step=2, size="96x64", frames=1)
>>> stats["triangles"] > 0
True
"""

from __future__ import annotations

from geoshade.iso.api import OutsideValuesWarning, field_of
from geoshade.iso.options import (
    DEFAULT_KEYWORD,
    DEFAULT_PATCH_LEVEL,
    METHOD,
    PAPER_PATCH_LEVEL,
    IsoOptions,
    check_level,
)
from geoshade.iso.pick import pick_iso  # registers the View's picker
from geoshade.iso.tasks import animate, export_mesh, render
from geoshade.iso.view import IsoView

__all__ = [
    "DEFAULT_KEYWORD",
    "DEFAULT_PATCH_LEVEL",
    "METHOD",
    "PAPER_PATCH_LEVEL",
    "IsoOptions",
    "IsoView",
    "OutsideValuesWarning",
    "animate",
    "check_level",
    "export_mesh",
    "field_of",
    "pick_iso",
    "render",
]
