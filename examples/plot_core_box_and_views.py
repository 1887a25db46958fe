"""
Digital core: a sub-volume, named views and picking
===================================================

``box=[x0, y0, z0, nx, ny, nz]`` shows part of a volume (in voxels). The camera is framed on the
box only, so changing the selection never moves the picture; a named view (``iso top bottom
front back left right``), ``azimuth``/``elevation``, ``zoom`` and ``ortho`` place it.
``pick(x, y)`` says what a pixel of the last picture shows.
"""

import matplotlib.pyplot as plt

import geoshade

vol = geoshade.synthetic_core(64, porosity=0.3, seed=2)
pores = (int(vol.data.min()), int(vol.meta["threshold"]))

views = ["iso", "top", "front"]
pictures = []
with geoshade.view(vol, select=pores, box=[0, 0, 0, 32, 32, 32], color_range=pores,
                   size=(400, 300)) as view:
    for name in views:
        img, stats = view.draw(view.camera(name, ortho=name != "iso"))
        pictures.append(img)
    print(f"box {stats['box']}: {stats['voxels_selected']:,} voxels selected, "
          f"{stats['gpu_bytes'] / 2**10:.0f} KiB on the GPU")
    # what the centre pixel of the last picture (front, orthographic) shows
    hit = view.pick(200, 150)
    print(hit.text() if hit is not None else "the centre pixel shows nothing")

fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
for ax, name, img in zip(axes, views, pictures, strict=True):
    ax.imshow(img)
    ax.set_title(f"view={name!r}")
    ax.axis("off")
plt.show()
