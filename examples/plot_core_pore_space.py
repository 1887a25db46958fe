"""
Digital core: pore space and mineral skeleton
=============================================

A micro-CT scan of a rock has two peaks in its histogram: pores (low grey values) and mineral
grains (high ones). :func:`geoshade.synthetic_core <geoshade.compute.synthetic_core>` makes such
a volume; selecting the values below the threshold between the peaks shows the pore space, the
values above it the mineral skeleton. ``geoshade.view`` picks the digital-core part for a
:class:`~geoshade.models.VoxelVolume`; ``update`` changes the selection and keeps the framing,
so the two pictures are pixel-aligned.
"""

import matplotlib.pyplot as plt

import geoshade

vol = geoshade.synthetic_core(64, porosity=0.25, seed=7)
lo, hi = int(vol.data.min()), int(vol.data.max())
threshold = int(vol.meta["threshold"])
print(f"{vol.shape_xyz} {vol.dtype.name} voxels, values {lo}..{hi}, threshold {threshold}")

# %%
# One View, two selections. ``color_range`` spreads the colour map over the selected values.
pictures = {}
with geoshade.view(vol, select=(lo, threshold), color_range=(lo, threshold),
                   size=(400, 300)) as view:
    pictures["pore space"], stats = view.draw()
    print(f"pore space: {stats['voxels_selected']:,} voxels selected, method {stats['method']}")
    view.update(select=(threshold + 1, hi), color_range=(threshold + 1, hi))
    pictures["mineral skeleton"], stats = view.draw()
    print(f"skeleton:   {stats['voxels_selected']:,} voxels selected")

fig, axes = plt.subplots(1, 2, figsize=(10, 4.3), layout="constrained")
for ax, (name, img) in zip(axes, pictures.items(), strict=True):
    ax.imshow(img)
    ax.set_title(name)
    ax.axis("off")
plt.show()

# %%
# Porosity
# --------
# :func:`geoshade.core.porosity` counts the selected voxels slice by slice: the porosity of the
# whole box and its profile along an axis (the plot the paper shows next to the picture).
res = geoshade.core.porosity(vol, (lo, threshold), axis="z")
print(f"porosity {res.porosity:.3f} (built with {vol.meta['porosity']:.3f})")

fig, ax = plt.subplots(figsize=(5, 3), layout="constrained")
ax.plot(res.profile, res.positions)
ax.set_xlabel("porosity of the slice")
ax.set_ylabel("z (voxel)")
ax.set_title("porosity profile along z")
plt.show()
