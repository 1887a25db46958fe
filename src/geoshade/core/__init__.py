"""The digital-core part: render a box of a micro-CT volume and compute its porosity.

>>> import geoshade
>>> vol = geoshade.synthetic_core(24, seed=1)
>>> img, stats = geoshade.core.render(vol, range=(0, 12000), size=(64, 48))  # doctest: +SKIP
>>> img.shape, stats["method"]                                               # doctest: +SKIP
((48, 64, 4), 'raycast')
"""

from __future__ import annotations

from geoshade.core.api import METHODS, CoreView, Prepared, porosity, render, resolve_method

__all__ = ["METHODS", "CoreView", "Prepared", "porosity", "render", "resolve_method"]
