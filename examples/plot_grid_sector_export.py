"""
Reservoir grid: export a sector model
=====================================

A *sector model* is the part of a grid a simulation engineer wants to run on its own: the cells
picked by a filter, an IJK slice or a plane, in the smallest IJK box that holds them, with the
unselected cells of the box made inactive. :func:`geoshade.grid.export_sector` (``geoshade grid
export CASE --filter ... -o SECTOR.grdecl``) writes it as GRDECL, or as EGRID + INIT (through
resfo, with the pore volumes); any reader -- geoshade, xtgeo, OPM -- opens it.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid

grid = synthetic_grid(30, 20, 8, faults=True, seed=3)
work = Path(tempfile.mkdtemp())
selection = {"filter": "PORO > 0.18", "slice": "i=4:22,j=2:14"}

sector = geoshade.grid.export_sector(grid, work / "sector.grdecl", **selection)
print(f"{sector.cells:,} cells selected, box {sector.box_text()}, "
      f"files {[f.name for f in sector.files]}")

# %%
# Read back, the sector's active cells are the selected cells, with their properties.
back = geoshade.load(work / "sector.grdecl")
mask = geoshade.grid.selected_cells(grid, **selection)
i, j, k = sector.box
print(f"sector grid {back.dims}, {back.nactive:,} active cells; equal to the selection:",
      np.array_equal(back.active, mask[i, j, k]))
print("PORO of the active cells equal:",
      np.array_equal(back.properties["PORO"][back.active], grid.properties["PORO"][i, j, k][
          mask[i, j, k]]))

# %%
# The selection in the whole grid, and the exported sector drawn from its file (one colour
# range for the three pictures).
poro = (float(grid.properties["PORO"].min()), float(grid.properties["PORO"].max()))
pictures = []
with geoshade.view(grid, property="PORO", color_range=poro, exaggeration=5.0,
                   size=(400, 300)) as view:
    img, _ = view.draw()
    pictures.append(("the whole grid", img))
    view.update(**selection)
    img, _ = view.draw()
    pictures.append(("filter and slice", img))
img, _ = geoshade.grid.render(back, property="PORO", color_range=poro, exaggeration=5.0,
                              size=(400, 300), frames=1)
pictures.append(("sector.grdecl, read back", img))

fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
for ax, (title, img) in zip(axes, pictures, strict=True):
    ax.imshow(img)
    ax.set_title(title)
    ax.axis("off")
plt.show()
