"""What the test suites of geoshade (and of code that extends it) share: synthetic models of
every part, and the conformance checks every part's View must pass.

- the synthetic models: :func:`synthetic_core` (a porous micro-CT volume),
  :func:`synthetic_grid` (a faulted corner-point grid with properties and report steps),
  :func:`displacement_field` (a saturation front over time), :func:`synthetic_layers` (a
  layered stack model) — the data of every part's ``demo()``;
- :mod:`geoshade.testing.views` -- the View contract (framing fixed by the model, stats keys,
  the one empty-scene warning, every GPU object released);
- :mod:`geoshade.testing.parity` -- live-change parity: for every option of every part,
  ``update(x)`` then ``draw()`` gives the picture a View opened with ``x`` gives, pixel for
  pixel; an option fixed at opening is refused by ``update`` in one line.

>>> import geoshade.testing as t
>>> t.synthetic_grid(4, 3, 2).dims
(4, 3, 2)
"""

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.compute.mesh.displacement import displacement_field
from geoshade.compute.stacks import synthetic_layers
from geoshade.compute.voxels.synthetic import synthetic_core

__all__ = ["displacement_field", "synthetic_core", "synthetic_grid", "synthetic_layers"]
