"""
One View for every model
========================

Every part has the same shape::

    geoshade.load(path) -> model -> geoshade.view(model, **options) -> View
    View.draw() -> (rgba, stats)

:func:`geoshade.view <geoshade.api.view>` picks the part from the model's type, checks every
option before any OpenGL context exists, and returns a View: ``draw()`` gives the picture (an
``(h, w, 4)`` uint8 array) and a dict of statistics; ``update()`` changes options; ``release()``
(or ``with``) frees the GPU memory. The same grid can also be shown by another part with ``as_``.
"""

import matplotlib.pyplot as plt

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.compute.mesh.displacement import displacement_field
from geoshade.compute.stacks import synthetic_layers

grid = synthetic_grid(24, 16, 6, seed=1)
models = {
    "digital core": (geoshade.synthetic_core(48, seed=1), {"select": (0, 19000)}),
    "corner-point grid": (grid, {"property": "PERMX", "log": True, "exaggeration": 5.0}),
    "the grid's SWAT = 0.4 (as_='iso')": (grid, {"as_": "iso", "level": 0.4,
                                                "exaggeration": 5.0}),
    "fields over time": (displacement_field((40, 24, 24), steps=4), {"level": 0.5}),
    "geological stacks": (synthetic_layers(48, 32, 30, max_intervals=5, seed=2,
                                           spacing=(50.0, 50.0, 2.0)), {"exaggeration": 4.0}),
}

pictures = {}
for title, (model, options) in models.items():
    with geoshade.view(model, size=(400, 300), **options) as view:
        img, stats = view.draw()
        print(f"{title:34s} {type(view).__name__:10s} {view.summary(stats)}")
    pictures[title] = img

# a picture without the title, colour bar and axes, with a transparent background
with geoshade.view(grid, property="PORO", exaggeration=5.0, annotations=False, transparent=True,
                   size=(400, 300)) as view:
    pictures["bare render, transparent"], _ = view.draw()

fig, axes = plt.subplots(2, 3, figsize=(12, 6.4), layout="constrained")
for ax, (title, img) in zip(axes.flat, pictures.items(), strict=True):
    ax.imshow(img)
    ax.set_title(title, fontsize=9)
    ax.axis("off")
plt.show()
