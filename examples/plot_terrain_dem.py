"""
Terrain from a DEM, and layers between surfaces
===============================================

A digital elevation model -- a georeferenced one-band GeoTIFF of heights -- becomes a terrain
stack model: one column per DEM cell, from the height down to a base
(:func:`geoshade.stacks.convert`, ``geoshade stacks convert DEM.tif``; the ``geo`` extra reads
GeoTIFFs with rasterio). Several surfaces, top to bottom, give a layered model with one unit
between each pair. The top of such models is drawn smooth (interpolated between column
centres) instead of in whole levels.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import rasterio
from rasterio.transform import from_origin

import geoshade

# A synthetic DEM: two hills on a slope, 50 m cells, in the Dutch RD New grid (EPSG:28992).
ny, nx, cell = 30, 40, 50.0
y, x = np.mgrid[0:ny, 0:nx].astype(np.float64)
heights = (20 + 40 * np.exp(-((x - 12) ** 2 + (y - 10) ** 2) / 40)
           + 25 * np.exp(-((x - 30) ** 2 + (y - 20) ** 2) / 25) + 0.2 * x)
work = Path(tempfile.mkdtemp())


def write_dem(path, z):
    """A GeoTIFF of heights z (row 0 north), as a GIS exports one."""
    with rasterio.open(path, "w", driver="GTiff", width=nx, height=ny, count=1,
                       dtype="float32", crs="EPSG:28992",
                       transform=from_origin(155000.0, 463000.0, cell, cell)) as dst:
        dst.write(z.astype(np.float32), 1)
    return path


top = write_dem(work / "dem.tif", heights)
surfaces = [write_dem(work / f"base_{k}.tif", heights - d)
            for k, d in enumerate((6 + 0.1 * x, 16 + 5 * np.sin(x / 5), 28 + 0.3 * y))]

terrain = geoshade.stacks.convert(top, dz=0.5)
layered = geoshade.stacks.convert(top, surfaces=surfaces, dz=0.5)
print(f"terrain: {terrain.shape} columns, base {terrain.meta['base']:.1f} m")
print(f"layered: units {list(layered.legend.names)}")

# %%
# The terrain with its smooth top and with the paper's flat tops, and the layered model with
# a section cut into it.
views = [
    ("terrain, smooth top", terrain, {"top": "smooth"}),
    ("terrain, flat tops (the paper)", terrain, {"top": "flat"}),
    ("layers between four surfaces", layered, {}),
    ("layers, cut by a plane", layered, {"plane": (0.0, 1.0, 0.0)}),
]
fig, axes = plt.subplots(2, 2, figsize=(10, 7.8), layout="constrained")
for ax, (title, model, options) in zip(axes.flat, views, strict=True):
    img, stats = geoshade.stacks.render(model, exaggeration=6.0, size=(400, 300), frames=1,
                                        **options)
    ax.imshow(img)
    ax.set_title(title)
    ax.axis("off")
plt.show()
