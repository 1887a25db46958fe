"""The core's small plots beside the picture, as SVG text: the volume's histogram with the
selected values shaded (and Otsu's thresholds), and the porosity profile.

What the desktop viewer's core panel draws (a log-count histogram, the selection over it, the
Otsu line in red and the multi-Otsu lines in grey; the profile against the slice position with
the total as a dashed line), from the same data: :meth:`CoreView.histogram`,
:meth:`CoreView.thresholds` and :attr:`CoreView.porosity`. No plotting library: a few
hundred bytes of SVG the page shows as it is.

>>> import numpy as np
>>> from geoshade.core.values import Histogram
>>> h = Histogram(np.array([4, 0, 9]), np.array([0.0, 1, 2, 3]), 0.0, 3.0)
>>> svg = histogram_svg(h, select=(0.0, 1.0))
>>> svg.count('class="bar"')
2
"""

from __future__ import annotations

import math
from html import escape

import numpy as np

from geoshade.core.plots import axis_label
from geoshade.errors import GeoshadeError

#: the plots' size in CSS pixels (the side panel's width)
WIDTH = 250
HISTOGRAM_HEIGHT = 70
#: pixels of the row of text under the histogram (the data's limits, Otsu's threshold)
LABEL_ROW = 12
POROSITY_HEIGHT = 190


def _n(v: float) -> str:
    return f"{v:.2f}".rstrip("0").rstrip(".")


def histogram_bars(counts, width: float = WIDTH, height: float = HISTOGRAM_HEIGHT
                   ) -> list[tuple[int, float, float, float]]:
    """``(bin, x, bar width, bar height)`` of each non-empty bin: heights ∝ log(1 + count),
    the fullest bin ``height - 4`` pixels (as the desktop viewer's histogram).

    Parameters
    ----------
    counts : (bins,) array of int
    width, height : float
        Pixels of the plot.

    Returns
    -------
    list of (int, float, float, float)

    Examples
    --------
    >>> [b[0] for b in histogram_bars([3, 0, 1])]
    [0, 2]
    """
    c = np.log1p(np.asarray(counts, np.float64))
    top = float(c.max()) if c.size and c.max() > 0 else 1.0
    bw = width / max(len(c), 1)
    return [(int(k), k * bw, max(bw, 1.0), float(c[k]) / top * (height - 4))
            for k in np.flatnonzero(c)]


def histogram_svg(hist, select=None, otsu: float | None = None, multi=(),
                  width: int = WIDTH, height: int = HISTOGRAM_HEIGHT) -> str:
    """The histogram as SVG.

    Parameters
    ----------
    hist : geoshade.core.values.Histogram
        ``counts`` over equal bins between ``edges[0]`` and ``edges[-1]``.
    select : (lo, hi), optional
        The selected values (shaded).
    otsu : float, optional
        Otsu's threshold (a red line); ``multi``: the multi-Otsu thresholds (grey lines).
    width, height : int
        Pixels.

    Returns
    -------
    str
        ``<svg ...>``: one ``rect.bar`` per non-empty bin, ``rect.select``, ``line.otsu``,
        ``line.multi`` over ``height`` pixels, the data's limits in a row of text below.
    """
    e0, e1 = float(hist.edges[0]), float(hist.edges[-1])

    def x(v: float) -> float:
        return (float(v) - e0) / max(e1 - e0, 1e-300) * width

    full = height + LABEL_ROW
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" class="histogram" width="{width}" '
           f'height="{full}" viewBox="0 0 {width} {full}">',
           f'<rect width="{width}" height="{height}" fill="#fafafa"/>']
    if select is not None:
        x0, x1 = x(select[0]), x(select[1])
        out.append(f'<rect class="select" x="{_n(x0)}" y="0" width="{_n(max(x1 - x0, 1.0))}" '
                   f'height="{height}" fill="#ffdc78"/>')
    for k, bx, bw, bh in histogram_bars(hist.counts, width, height):
        out.append(f'<rect class="bar" data-bin="{k}" x="{_n(bx)}" y="{_n(height - bh)}" '
                   f'width="{_n(bw)}" height="{_n(bh)}" fill="#3c5aa0"/>')
    for v in multi:
        out.append(f'<line class="multi" x1="{_n(x(v))}" x2="{_n(x(v))}" y1="0" '
                   f'y2="{height}" stroke="#787878"/>')
    if otsu is not None:
        out.append(f'<line class="otsu" x1="{_n(x(otsu))}" x2="{_n(x(otsu))}" y1="0" '
                   f'y2="{height}" stroke="#d22828"><title>Otsu {otsu:g}</title></line>')
    out.append(f'<text x="1" y="{full - 2}" font-size="9" fill="#555">{hist.vmin:g}</text>')
    if otsu is not None:
        out.append(f'<text x="{_n(x(otsu))}" y="{full - 2}" font-size="9" fill="#d22828" '
                   f'text-anchor="middle">Otsu {otsu:g}</text>')
    out.append(f'<text x="{width - 1}" y="{full - 2}" font-size="9" fill="#555" '
               f'text-anchor="end">{hist.vmax:g}</text>')
    out.append("</svg>")
    return "".join(out)


def porosity_points(result, width: float = WIDTH, height: float = POROSITY_HEIGHT,
                    margin=(34, 8, 12, 28)) -> tuple[list[list[tuple[float, float]]], float]:
    """The profile as polylines in pixels (a NaN slice breaks the line) and the x range's end.

    Parameters
    ----------
    result : geoshade.compute.voxels.porosity.PorosityResult
    width, height : float
        Pixels of the plot.
    margin : (left, right, top, bottom)
        Pixels around the frame.

    Returns
    -------
    lines : list of list of (x, y)
        The profile's value runs along x from 0 to ``xmax``, the slice position along y (the
        first slice at the bottom).
    xmax : float
        At least 0.05, 15 % beyond the largest value, at most 1.
    """
    prof = np.asarray(result.profile, np.float64)
    _, pos = axis_label(result)
    left, right, top, bottom = margin
    xmax = max(0.05, min(1.0, float(np.nanmax(prof, initial=0)) * 1.15))
    p0, p1 = float(pos[0]), float(pos[-1])
    span = (p1 - p0) or 1.0
    lines: list[list[tuple[float, float]]] = [[]]
    for v, p in zip(prof, pos, strict=True):
        if not math.isfinite(v):
            if lines[-1]:
                lines.append([])
            continue
        px = left + v / xmax * (width - left - right)
        py = height - bottom - (float(p) - p0) / span * (height - top - bottom)
        lines[-1].append((px, py))
    return [ln for ln in lines if ln], xmax


def porosity_svg(result, width: int = WIDTH, height: int = POROSITY_HEIGHT) -> str:
    """The porosity (or selected-fraction) profile as SVG.

    Parameters
    ----------
    result : geoshade.compute.voxels.porosity.PorosityResult
    width, height : int
        Pixels.

    Returns
    -------
    str
        ``<svg ...>``: one ``polyline.profile`` per run of measured slices, the total as a
        dashed ``line.total``, the axes labelled as :func:`geoshade.core.plots.porosity_plot`
        labels them.
    """
    left, right, top, bottom = margin = (34, 8, 12, 28)
    lines, xmax = porosity_points(result, width, height, margin)
    label, pos = axis_label(result)
    quantity = getattr(result, "quantity", "porosity")
    total = float(result.porosity)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" class="porosity" width="{width}" '
           f'height="{height}" viewBox="0 0 {width} {height}" font-size="9">',
           f'<rect x="{left}" y="{top}" width="{width - left - right}" '
           f'height="{height - top - bottom}" fill="none" stroke="#999"/>']
    for ln in lines:
        pts = " ".join(f"{_n(x)},{_n(y)}" for x, y in ln)
        out.append(f'<polyline class="profile" points="{pts}" fill="none" stroke="#1f77b4" '
                   f'stroke-width="1.2"/>')
    if math.isfinite(total):
        tx = left + total / xmax * (width - left - right)
        out.append(f'<line class="total" x1="{_n(tx)}" x2="{_n(tx)}" y1="{top}" '
                   f'y2="{height - bottom}" stroke="#d62728" stroke-dasharray="4 3"/>')
        out.append(f'<text x="{width - right}" y="{top - 2}" text-anchor="end" '
                   f'fill="#d62728">total {total:.4f}</text>')
    out.append(f'<text x="{left}" y="{height - bottom + 10}">0</text>')
    out.append(f'<text x="{width - right}" y="{height - bottom + 10}" '
               f'text-anchor="end">{xmax:.2g}</text>')
    out.append(f'<text x="{(left + width - right) / 2:.0f}" y="{height - 4}" '
               f'text-anchor="middle">{escape(quantity)}</text>')
    out.append(f'<text x="{left - 3}" y="{height - bottom}" text-anchor="end">'
               f'{float(pos[0]):.4g}</text>')
    out.append(f'<text x="{left - 3}" y="{top + 8}" text-anchor="end">{float(pos[-1]):.4g}'
               "</text>")
    out.append(f'<text transform="translate(9 {(top + height - bottom) / 2:.0f}) rotate(-90)" '
               f'text-anchor="middle">{escape(label)}</text>')
    out.append("</svg>")
    return "".join(out)


def core_plots(view) -> dict[str, str]:
    """The plots of a core's panel now (CPU work: any thread).

    Parameters
    ----------
    view : geoshade.core.CoreView

    Returns
    -------
    dict
        ``{"histogram": svg, "porosity": svg}``: the porosity only when the View computes a
        profile, the thresholds only where scikit-image is installed.
    """
    o = view.options
    try:
        t = view.thresholds()
        otsu, multi = t.otsu, list(t.multiotsu)
    except GeoshadeError:
        otsu, multi = None, []
    out = {"histogram": histogram_svg(view.histogram(), select=o.select, otsu=otsu,
                                      multi=multi)}
    if view.porosity is not None:
        out["porosity"] = porosity_svg(view.porosity)
    return out
