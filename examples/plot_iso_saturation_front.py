"""
Saturation isosurface: a water front over time
==============================================

A displacement simulation writes the water saturation ``SWAT`` of every cell at every report
step. The isosurface ``SWAT = 0.5`` is the water front; the isosurface part marches it on the
GPU (tessellation marching cubes) for any step. ``displacement_field``
(``geoshade.compute.mesh.displacement``) makes an unstable displacement whose fingers grow from step
to step; the surface is coloured by the pressure field that comes with it.
"""

import matplotlib.pyplot as plt

import geoshade
from geoshade.compute.mesh.displacement import displacement_field

field = displacement_field((48, 32, 32), steps=6, seed=0)
print(f"{field.nsteps} steps of {field.shape_xyz} nodes, properties {sorted(field.properties)}")

steps = [1, 3, 5]
pictures = []
with geoshade.view(field, level=0.5, color_by="PRESSURE", color_range=(200.0, 300.0),
                   size=(400, 300)) as view:
    for k in steps:
        view.update(step=k)  # the colour range stays, so colours compare across steps
        img, stats = view.draw()
        pictures.append(img)
        print(f"step {k}: {stats['triangles']:,} triangles")

fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
for ax, k, img in zip(axes, steps, pictures, strict=True):
    ax.imshow(img)
    ax.set_title(f"SWAT = 0.5, step {k}")
    ax.axis("off")
plt.show()

# %%
# The same surface as a triangle mesh
# -----------------------------------
# :func:`geoshade.iso.export_mesh` returns the triangles the GPU emits for one step (and writes
# PLY, OBJ or STL when given a path); the CPU marching cubes the GPU is tested against finds the
# same number.
from geoshade.compute.mesh.marching_cubes import marching_cubes  # noqa: E402

mesh = geoshade.iso.export_mesh(field, 0.5, step=5)
cpu = marching_cubes(field.step(5), 0.5)
print(f"step 5: GPU {mesh.n_faces:,} triangles ({mesh.n_vertices:,} welded vertices), "
      f"CPU reference {cpu.count:,} triangles")
