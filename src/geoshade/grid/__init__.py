"""The reservoir-grid part: render corner-point grids coloured by a property, with cell edges,
slices, filters, a clipping plane, faults and wells (the paper's three GPU approaches).

>>> import geoshade.grid
>>> from geoshade.compute.synthetic_grid import synthetic_grid
>>> img, stats = geoshade.grid.render(synthetic_grid(6, 5, 3), property="PORO", size=(64, 48))
>>> stats["faces_drawn"] == stats["faces"]
True
"""

from __future__ import annotations

from geoshade.grid.api import (
    DEFAULT_APPROACH,
    FAULT_MODES,
    EmptyGridWarning,
    GridView,
    parse_clip,
    parse_slice,
    render,
)

__all__ = ["DEFAULT_APPROACH", "FAULT_MODES", "EmptyGridWarning", "GridView", "parse_clip",
           "parse_slice", "render"]
