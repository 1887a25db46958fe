"""How a change between two steps is coloured (``diff``): a diverging colour map centred on 0
over a symmetric range, never log, never categories.

>>> from geoshade.styles.options import ColorStyle
>>> diverging(ColorStyle()).colormap, symmetric_range(-0.2, 0.5)
('RdBu', (-0.5, 0.5))
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

#: the colour map a difference is drawn with where the user chose none (blue: less, red: more)
DIVERGING = "RdBu_r"


def diverging(style):
    """``style`` for a difference: linear, not categorical, the diverging colour map
    (:data:`DIVERGING`) unless the user chose one (the default viridis is replaced).

    >>> from geoshade.styles.options import ColorStyle
    >>> s = diverging(ColorStyle(colormap="magma", log=True))
    >>> s.colormap, s.log, s.categorical
    ('magma', False, False)
    """
    if style.colormap == "viridis" and not style.reverse and style.solid is None:
        style = style.with_(colormap=DIVERGING)
    return replace(style, log=False, categorical=False)


def symmetric_range(lo, hi) -> tuple[float, float]:
    """``(-m, m)`` with ``m`` the largest magnitude of ``lo`` and ``hi`` (1 where both are 0
    or neither is finite): the colour range of a change, centred on 0.

    >>> symmetric_range(-3.0, 1.0), symmetric_range(0.0, 0.0), symmetric_range(None, None)
    ((-3.0, 3.0), (-1.0, 1.0), (-1.0, 1.0))
    """
    ends = [abs(float(v)) for v in (lo, hi) if v is not None and np.isfinite(v)]
    m = max(ends, default=0.0) or 1.0
    return -m, m


def color_name(style) -> str:
    """The colour map's name as drawn (``_r`` where reversed).

    >>> from geoshade.styles.options import ColorStyle
    >>> color_name(diverging(ColorStyle()))
    'RdBu_r'
    """
    return str(style.colormap) + ("_r" if style.reverse else "")


__all__ = ["DIVERGING", "color_name", "diverging", "symmetric_range"]
