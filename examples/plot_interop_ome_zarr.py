"""
OME-Zarr: a multiscale store other tools read
=============================================

``geoshade core ingest`` (:func:`geoshade.io.stores.ingest.ingest`) writes an OME-Zarr image (NGFF
0.5,
zarr v3): every pyramid level, with the voxel size and unit in the ``multiscales`` metadata, so
napari, Fiji/BigDataViewer, neuroglancer or ome-zarr-py open it with the right scale; geoshade
reads OME-Zarr images written by other tools the same way (NGFF 0.4 and 0.5).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import zarr

import geoshade
from geoshade.io.stores.ingest import ingest
from geoshade.io.stores.ome_zarr import parse_multiscales
from geoshade.io.stores.zarr_io import read_level

work = Path(tempfile.mkdtemp())
core = geoshade.synthetic_core(128, porosity=0.25, seed=11)
np.save(work / "core.npy", core.data)
ingest(work / "core.npy", work / "core.zarr", chunks=(64, 64, 64), levels=3,
       spacing=core.spacing, unit=core.unit)

# %%
# The NGFF metadata: one dataset per level, each with its scale (z, y, x) and the unit.
attrs = dict(zarr.open_group(str(work / "core.zarr"), mode="r").attrs)
ms = parse_multiscales(attrs, work / "core.zarr")
print(f"NGFF {ms.version}, axes {ms.axes}, unit {ms.unit!r}")
for level, path in enumerate(ms.paths):
    print(f"  level {level}: array {path!r}, voxel size (x, y, z) {ms.spacing(level)}")

# %%
# Every level is a lazy volume occupying the same world box: the same selection draws the
# same rock at a half and a quarter of the resolution.
pores = (int(core.data.min()), int(core.meta["threshold"]))
pictures = []
for level in range(len(ms.paths)):
    vol = read_level(work / "core.zarr", level)
    img, stats = geoshade.core.render(vol, select=pores, color_range=pores, size=(400, 300),
                                      frames=1)
    pictures.append((f"level {level}: {vol.shape_xyz[0]}³ voxels of {vol.spacing[0]:g} "
                     f"{vol.unit}", img))

fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
for ax, (title, img) in zip(axes, pictures, strict=True):
    ax.imshow(img)
    ax.set_title(title, fontsize=10)
    ax.axis("off")
plt.show()
