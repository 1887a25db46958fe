"""
Geological stacks: layers, a section and an orthophoto
======================================================

A layered voxel model (such as GeoTOP) stores each column as a short list of intervals -- a
*stack* -- instead of one value per voxel, and ray-casts those stacks on the GPU.
``geoshade.compute.stacks.synthetic_layers`` builds a layer cake with pinch-outs and
relief directly as stacks; :func:`geoshade.stacks.convert` would build one from voxels.
"""

import matplotlib.pyplot as plt

import geoshade
from geoshade.compute.stacks import synthetic_layers

model = synthetic_layers(64, 48, 40, max_intervals=6, seed=3, spacing=(50.0, 50.0, 2.0))
mem = geoshade.stacks.memory_stats(model, octree=False)
print(f"{model.shape} columns, {model.nlevels} levels: voxels "
      f"{mem['bytes_voxels'] / 2**10:.0f} KiB, stacks {mem['bytes_stacks'] / 2**10:.0f} KiB")

# %%
# The model, a vertical section (the plane keeps ``-x + y >= -400``, the side its normal points
# to), one material hidden, and an orthophoto draped on the top surface.
settings = {
    "layers": {},
    "section": {"plane": (-1.0, 1.0, 0.0, -400.0)},
    "layers 5 and 6 hidden": {"plane": None, "hide": [5, 6]},
    "orthophoto drape": {"hide": [], "drape": geoshade.stacks.demo_drape(model)},
}
pictures = {}
with geoshade.view(model, exaggeration=4.0, legend=True, size=(400, 300)) as view:
    for title, changes in settings.items():
        view.update(**changes)
        pictures[title], stats = view.draw()
    print(f"{stats['columns']:,} columns, {stats['intervals']:,} intervals on the GPU "
          f"({stats['method']} layout)")

fig, axes = plt.subplots(2, 2, figsize=(10, 7.8), layout="constrained")
for ax, (title, img) in zip(axes.flat, pictures.items(), strict=True):
    ax.imshow(img)
    ax.set_title(title)
    ax.axis("off")
plt.show()
