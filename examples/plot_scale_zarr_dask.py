"""
Scale: a chunked zarr store, read lazily with dask
==================================================

Volumes larger than memory are ingested once into a chunked, multiscale zarr store (``geoshade
core ingest`` on the command line, :func:`geoshade.io.stores.ingest.ingest` in Python);
:func:`geoshade.load <geoshade.api.load>` then opens the store lazily (a dask array), the
porosity and the selection maps are computed chunk by chunk, and a volume beyond the GPU's
memory or texture limits is drawn in bricks (``bricks=48``, the largest brick side, forces that
here on a small volume).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import geoshade
from geoshade.io.stores.ingest import ingest

work = Path(tempfile.mkdtemp())
source = geoshade.synthetic_core(96, porosity=0.2, seed=5)
np.save(work / "core.npy", source.data)

report = ingest(work / "core.npy", work / "core.zarr", chunks=(32, 32, 32), levels=2,
                spacing=source.spacing, unit=source.unit)
print(f"{report.path.name}: {report.shape_xyz} {report.dtype}, levels {report.levels}, "
      f"chunks {report.chunks}")

# %%
# Open the store: nothing is read until a computation needs it.
vol = geoshade.load(work / "core.zarr")
print(type(vol.data).__name__, vol.data.shape, "chunks", vol.data.chunksize)
pores = (int(source.data.min()), int(source.meta["threshold"]))
res = geoshade.core.porosity(vol, pores, axis="z")
print(f"porosity {res.porosity:.4f}, the in-memory volume gives "
      f"{geoshade.core.porosity(source, pores).porosity:.4f}")

# %%
# Draw it whole and in bricks: the same picture.
pictures, titles = [], []
for bricks in (False, 48):
    img, stats = geoshade.core.render(vol, select=pores, color_range=pores, bricks=bricks,
                                      size=(400, 300), frames=1)
    pictures.append(img)
    titles.append(f"{stats.get('bricks', 1)} brick(s)")
    print(f"bricks={bricks}: {stats.get('bricks', 1)} brick(s), method {stats['method']}, "
          f"{stats['gpu_bytes'] / 2**10:.0f} KiB GPU")
print("pixels that differ:", int(np.any(pictures[0] != pictures[1], axis=-1).sum()))

fig, axes = plt.subplots(1, 2, figsize=(10, 4.3), layout="constrained")
for ax, title, img in zip(axes, titles, pictures, strict=True):
    ax.imshow(img)
    ax.set_title(title)
    ax.axis("off")
plt.show()
