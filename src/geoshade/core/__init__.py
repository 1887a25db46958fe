"""The digital-core part: render a box of a micro-CT volume and compute its porosity.

>>> import geoshade
>>> vol = geoshade.synthetic_core(24, seed=1)
>>> img, stats = geoshade.core.render(vol, select=(0, 12000), size=(64, 48), frames=1)
>>> img.shape, stats["method"]
((48, 64, 4), 'raycast')
"""

from __future__ import annotations

from geoshade.core.api import render
from geoshade.core.options import METHODS, CoreOptions, resolve_method
from geoshade.core.overview import overview_level, render_overview
from geoshade.core.pick import pick_core  # registers the View's picker
from geoshade.core.values import (
    Histogram,
    auto_select,
    default_box,
    default_range,
    detect_sample,
    display_color_range,
    histogram,
    porosity,
    porosity_line,
    region,
    resolve_select,
    thresholds,
)
from geoshade.core.view import CoreView, Prepared, model_matrix

__all__ = ["METHODS", "CoreOptions", "CoreView", "Histogram", "Prepared", "auto_select",
           "default_box", "default_range", "detect_sample", "display_color_range", "histogram",
           "model_matrix", "overview_level", "pick_core", "porosity", "porosity_line", "region",
           "render", "render_overview", "resolve_method", "resolve_select", "thresholds"]
