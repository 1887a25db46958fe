"""
xarray: fields and volumes with coordinates and units
=====================================================

:func:`geoshade.to_xarray <geoshade.api.to_xarray>` gives a volume or a field over time as an
``xarray.DataArray`` with coordinates and units (and a corner-point grid as a ``Dataset``), without
copying; :func:`geoshade.from_xarray <geoshade.api.from_xarray>` reads one back -- also one made
elsewhere, such as a GeoTOP netCDF opened with xarray. Both need the ``netcdf`` extra.
"""

import matplotlib.pyplot as plt
import numpy as np

import geoshade
from geoshade.compute.mesh.displacement import displacement_field

field = displacement_field((48, 32, 32), steps=6, spacing=(5.0, 5.0, 2.0), seed=0)
da = geoshade.to_xarray(field)
print(da.dims, dict(da.sizes), "units:", da.attrs.get("units", "(none)"))

# %%
# xarray's labelled operations: the mean saturation across each x slice, for every step, is
# the front moving along the flow direction.
profile = da.mean(dim=("z", "y"))
fig, ax = plt.subplots(figsize=(6, 3.5), layout="constrained")
for t in range(da.sizes["time"]):
    profile.isel(time=t).plot(ax=ax, label=f"step {t}")
ax.set_ylabel("mean SWAT across the section")
ax.set_title("the water front along x")
ax.legend(fontsize=8)
plt.show()

# %%
# Back to geoshade: the field is the same (values, spacing, steps) and draws as before.
back = geoshade.from_xarray(da)
print("field -> xarray -> field equal:",
      np.array_equal(np.asarray(back.step(5)), np.asarray(field.step(5)))
      and tuple(back.spacing) == tuple(field.spacing) and back.nsteps == field.nsteps)

vol = geoshade.synthetic_core(48, seed=3)
vda = geoshade.to_xarray(vol)
print(f"volume: dims {vda.dims}, x from {float(vda.x[0])} to {float(vda.x[-1])} "
      f"{vda.x.attrs.get('units', '')} (voxel centres)")

img, stats = geoshade.iso.render(back, 0.5, step=5, size=(400, 300), frames=1)
fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(10, 4.3), layout="constrained")
ax0.imshow(img)
ax0.set_title("the field back from xarray, step 5")
ax0.axis("off")
vda.isel(z=24).plot(ax=ax1, cmap="gray", add_colorbar=False)  # a slice with its coordinates
ax1.set_aspect("equal")
ax1.set_title("core volume: slice z = 24 (xarray plot)")
plt.show()

# sphinx_gallery_thumbnail_number = 2
