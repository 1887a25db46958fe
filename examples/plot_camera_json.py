"""
Reproduce a view: the camera as JSON
====================================

A picture's camera -- after framing, with every value exact -- can be saved as JSON
(``Camera.save``, ``--save-camera cam.json`` on every ``render`` command, "Save camera…" in the
viewer) and given back (``camera="cam.json"``, ``--camera cam.json``, "Load camera…"): the same
model at the same size is drawn pixel for pixel the same, on the command line, in Python or in
the viewer.
"""

import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid

grid = synthetic_grid(30, 20, 8, faults=True, seed=3)
work = Path(tempfile.mkdtemp())

with geoshade.view(grid, property="PERMX", edges=True, exaggeration=5.0, azimuth=200,
                   elevation=35, zoom=1.25, size=(400, 300)) as view:
    first, _ = view.draw()
    view.camera().save(work / "cam.json")  # the camera this picture was drawn with

saved = json.loads((work / "cam.json").read_text())
print({k: saved[k] for k in ("azimuth", "elevation", "distance", "ortho")})

# %%
# Later, elsewhere: the same view from the file, here with another property.
with geoshade.view(grid, property="PERMX", edges=True, exaggeration=5.0,
                   camera=str(work / "cam.json"), size=(400, 300)) as view:
    again, _ = view.draw()
    view.update(property="SWAT")
    swat, _ = view.draw()
print("pixel-identical:", np.array_equal(first, again))

fig, axes = plt.subplots(1, 2, figsize=(10, 4.3), layout="constrained")
for ax, title, img in zip(axes, ("saved with cam.json", "cam.json, SWAT"), (again, swat),
                          strict=True):
    ax.imshow(img)
    ax.set_title(title)
    ax.axis("off")
plt.show()
