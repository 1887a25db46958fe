"""
Digital core: a cylindrical sample, its ROI and Otsu's threshold
================================================================

A micro-CT scan of a core plug is a cylinder of rock in a box of air. The air is dark, like the
pores: counted as pore space it inflates the porosity and drags an automatic threshold down.
``roi="cylinder"`` fits the sample's cylinder (slice by slice) and keeps only the voxels inside
it for the picture, the histogram, Otsu's threshold (``select="auto"``) and the porosity.
"""

import dataclasses

import matplotlib.pyplot as plt
import numpy as np

import geoshade

rock = geoshade.synthetic_core(96, porosity=0.2, seed=8)
z, y, x = np.ogrid[0:96, 0:96, 0:96]
outside = (x + 0.5 - 48) ** 2 + (y + 0.5 - 48) ** 2 > 40.0**2
data = rock.data.copy()
data[np.broadcast_to(outside, data.shape)] = 1500  # air around the plug: darker than the pores
plug = dataclasses.replace(rock, data=data, name="core plug")

# %%
# Otsu's threshold of the whole box and of the fitted cylinder, and the porosity each gives.
whole = geoshade.core.thresholds(plug)
inside = geoshade.core.thresholds(plug, roi="cylinder")
for name, t, roi in (("whole box", whole, None), ("cylinder ROI", inside, "cylinder")):
    res = geoshade.core.porosity(plug, t.pore_select(), roi=roi)
    print(f"{name:13s} Otsu {t.otsu:7.0f}   porosity {res.porosity:.3f}")
print(f"the rock was made with porosity {rock.meta['porosity']:.3f}")

hist = geoshade.core.histogram(plug)
fig, ax = plt.subplots(figsize=(7, 3), layout="constrained")
ax.stairs(hist.counts, hist.edges, fill=True, alpha=0.6)
ax.axvline(whole.otsu, color="C3", label=f"Otsu, whole box ({whole.otsu:.0f})")
ax.axvline(inside.otsu, color="C2", label=f"Otsu, cylinder ROI ({inside.otsu:.0f})")
ax.set_yscale("log")
ax.set_xlabel("grey value")
ax.set_ylabel("voxels")
ax.legend(fontsize=8)
plt.show()

# %%
# The pore space selected automatically, without and with the ROI.
pictures = []
for roi in (None, "cylinder"):
    img, stats = geoshade.core.render(plug, select="auto", roi=roi, size=(400, 300), frames=1)
    pictures.append((f"roi={roi!r}: {stats['voxels_selected']:,} voxels", img))
fig, axes = plt.subplots(1, 2, figsize=(10, 4.3), layout="constrained")
for ax, (title, img) in zip(axes, pictures, strict=True):
    ax.imshow(img)
    ax.set_title(title)
    ax.axis("off")
plt.show()

# sphinx_gallery_thumbnail_number = 2
