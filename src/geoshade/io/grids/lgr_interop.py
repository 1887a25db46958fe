"""Local grid refinements in PyVista: the global grid's dataset and each LGR's, as one
``MultiBlock`` in which the host cells are hidden (ResInsight draws refined cells inside their
hosts the same way).  Nothing here imports PyVista or resfo: the converter and the
``MultiBlock`` class are passed in by :mod:`geoshade.io.interop.pyvista_io`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from geoshade.models import CornerPointGrid

__all__ = ["refined_to_pyvista"]

#: vtkDataSetAttributes.HIDDENCELL: the ghost-array bit of a blanked cell
HIDDEN_CELL = 32


def refined_to_pyvista(grid: CornerPointGrid, dataset, convert: Callable,
                       multiblock: Callable, **options):
    """A ``pyvista.MultiBlock`` (made by ``multiblock()``): the global grid's ``dataset`` (its
    host cells hidden, ghost type HIDDENCELL, as a viewer hides the cells it draws refined)
    under ``"GLOBAL"``, then each LGR's cells converted by ``convert(refinement.grid,
    **options)`` under its name; the global grid's dataset itself when there is no refinement.

    ``dataset`` must carry the cell array ``vtkGhostType`` (one value per cell, i fastest).
    """
    if not getattr(grid, "refinements", None):
        return dataset
    ghost = np.asarray(dataset.cell_data["vtkGhostType"]).copy()
    host = grid.host_cells().reshape(-1, order="F")
    ghost[host] |= HIDDEN_CELL
    dataset.cell_data["vtkGhostType"] = ghost
    blocks = multiblock()
    blocks["GLOBAL"] = dataset
    for r in grid.refinements:
        sub = convert(r.grid, **options)
        sub.field_data["geoshade_lgr"] = np.array([r.name])
        sub.field_data["geoshade_host_box"] = np.asarray(r.host_box, np.int64).ravel() + 1
        blocks[r.name] = sub
    return blocks
