"""
napari: the reader plugin, used from code
=========================================

geoshade's npe2 plugin (the ``napari`` extra) makes ``napari`` open the volumes and multiscale
stores geoshade reads, with their voxel size as the layer's ``scale``, and save a labels layer
as a geoshade zarr store. In napari that is ``viewer.open("core.zarr", plugin="geoshade")``;
here the same hooks are called directly, and the layers are built without opening a window.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from napari.layers import Layer

import geoshade
from geoshade.io.stores.ingest import ingest
from geoshade.napari import get_reader, selection_labels, write_labels

work = Path(tempfile.mkdtemp())
core = geoshade.synthetic_core(96, porosity=0.25, seed=5)
np.save(work / "core.npy", core.data)
ingest(work / "core.npy", work / "core.zarr", chunks=(48, 48, 48), levels=2,
       spacing=core.spacing, unit=core.unit)

# %%
# What napari does with a path: ask the plugin for a reader, call it, make the layers.
reader = get_reader(str(work / "core.zarr"))
[(data, kwargs, kind)] = reader(str(work / "core.zarr"))
image = Layer.create(data, kwargs, kind)
scale = tuple(float(s) for s in image.scale)
print(f"{type(image).__name__} {image.name!r}: multiscale {image.multiscale}, "
      f"levels {[tuple(d.shape) for d in image.data]}, scale (z, y, x) {scale}")

# %%
# The core selection as a labels layer (the plugin's "Selection as labels" widget), saved by
# the plugin's writer and read back by geoshade with the same spacing.
pores = (int(core.data.min()), int(core.meta["threshold"]))
labels = Layer.create(*selection_labels(core, *pores))
print(f"{type(labels).__name__} {labels.name!r}: {int(np.count_nonzero(labels.data)):,} "
      f"pore voxels of {labels.data.size:,}")
[written] = write_labels(str(work / "pores.zarr"), labels.data, labels.as_layer_data_tuple()[1])
back = geoshade.load(written)
same = np.array_equal(np.asarray(back.data), np.asarray(labels.data))
print(f"read back: {back.shape_xyz}, spacing {back.spacing} {back.unit}, labels "
      f"{bool(back.meta.get('labels'))}, equal {same}")

# %%
# A slice of each layer, as napari would show them, and the saved labels drawn by geoshade.
z = core.data.shape[0] // 2
img, _ = geoshade.core.render(back, select=(1, 1), size=(400, 300), frames=1)
fig, axes = plt.subplots(1, 3, figsize=(12, 4), layout="constrained")
axes[0].imshow(np.asarray(image.data[0][z]), cmap="gray")
axes[0].set_title(f"image layer, level 0, z = {z}")
axes[1].imshow(np.asarray(image.data[0][z]), cmap="gray")
axes[1].imshow(np.ma.masked_equal(np.asarray(labels.data[z]), 0), cmap="autumn", alpha=0.6)
axes[1].set_title("with the pore labels")
axes[2].imshow(img)
axes[2].set_title("pores.zarr drawn by geoshade")
for ax in axes:
    ax.axis("off")
plt.show()
