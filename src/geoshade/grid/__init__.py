"""The reservoir-grid part: render corner-point grids coloured by a property, with cell edges,
slices, filters, a cutting plane, faults and wells (the paper's three GPU approaches).

>>> import geoshade.grid
>>> from geoshade.compute.grid.synthetic import synthetic_grid
>>> img, stats = geoshade.grid.render(synthetic_grid(6, 5, 3), property="PORO", size=(64, 48),
...                                   frames=1)
>>> stats["faces_drawn"] == stats["faces"]
True
"""

from __future__ import annotations

from geoshade.grid.api import animate, render
from geoshade.grid.export import Sector, export_sector, selected_cells
from geoshade.grid.geometry import (
    demo_wells,
    display_bounds,
    frame_points,
    model_matrix,
    parse_slice,
    plane_from_clip,
    world_bounds,
    world_centre,
    world_points,
)
from geoshade.grid.options import (
    DEFAULT_APPROACH,
    FAULT_MODES,
    GridOptions,
    resolve_property,
    step_names,
)
from geoshade.grid.pick import pick_grid  # registers the View's picker
from geoshade.grid.view import GridView, PreparedFaces

__all__ = ["DEFAULT_APPROACH", "FAULT_MODES", "GridOptions", "GridView", "PreparedFaces",
           "Sector", "animate", "demo_wells", "display_bounds", "export_sector", "frame_points",
           "model_matrix", "parse_slice", "pick_grid", "plane_from_clip", "render",
           "resolve_property", "selected_cells", "step_names", "world_bounds", "world_centre",
           "world_points"]
