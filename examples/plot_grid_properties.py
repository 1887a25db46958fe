"""
Reservoir grid: a property, cell edges, filters and a cutting plane
===================================================================

A corner-point grid (COORD pillars, ZCORN depths, ACTNUM) as ECLIPSE and OPM write it.
``geoshade.compute.grid.synthetic.synthetic_grid`` builds a faulted one with porosity,
permeability and a water saturation over four report steps. ``geoshade.view`` picks the grid
part; ``update`` changes the property, step, filter or plane without rebuilding the geometry.
"""

import matplotlib.pyplot as plt

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid

grid = synthetic_grid(30, 20, 8, faults=True, seed=3)
nx, ny, nz = grid.dims
print(f"{nx} x {ny} x {nz} cells, properties {grid.property_names()}, "
      f"{len(grid.steps)} report steps, faults {[f.name for f in grid.faults]}")

settings = {
    "PORO, cell edges": {"property": "PORO", "edges": True},
    "SWAT of step 3 where PORO > 0.2": {"property": "SWAT", "step": 3, "filter": "PORO > 0.2",
                                        "edges": False},
    "log10(PERMX), cut by a plane": {"property": "log10(PERMX)", "step": -1, "filter": None,
                                     "plane": (1.0, 0.0, 0.0)},
    "layers k = 2..3 (slice)": {"property": "PORO", "plane": None, "slice": "k=2:4"},
}
pictures = {}
with geoshade.view(grid, exaggeration=5.0, size=(400, 300)) as view:
    for title, changes in settings.items():
        view.update(**changes)
        pictures[title], stats = view.draw()
        print(f"{title:34s} {stats['shown_cells']:6,d} cells shown, "
              f"{stats['faces_drawn']:6,d} faces drawn")

fig, axes = plt.subplots(2, 2, figsize=(10, 7.8), layout="constrained")
for ax, (title, img) in zip(axes.flat, pictures.items(), strict=True):
    ax.imshow(img)
    ax.set_title(title, fontsize=10)
    ax.axis("off")
plt.show()
