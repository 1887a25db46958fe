"""Label placement without overlap: names at points (well heads) moved a little or hidden so
that no two drawn labels cover each other.

A label is drawn by :func:`geoshade.styles.annotate.annotate` centred just above its point;
:func:`place_labels` measures each text exactly as it will be drawn (the same matplotlib font,
size and weight, so the boxes are those of the annotation layout), then takes the labels in
order (the first ones win) and tries a few nearby spots for each: above its point, below it,
right, left, then a second ring around those. The first spot that lies inside the picture and
clear of the labels already placed is kept; a label with no such spot is hidden and counted, so the
picture can say how many names it left out.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence

import numpy as np

from geoshade.styles.annotate import DPI, font_px, picture_text

#: pixels kept free between two labels
GAP = 2.0


@dataclasses.dataclass(frozen=True)
class Placement:
    """The labels to draw (moved where they had to be) and what was hidden.

    labels: tuple of :class:`~geoshade.styles.annotate.Label`, the drawn ones in their order
    boxes:  (n, 4) float  their boxes x, y, width, height in pixels (row 0 at the top)
    moved:  int           labels drawn away from the spot right above their point
    hidden: tuple of str  the texts of the labels left out (no free spot near their point)
    """

    labels: tuple
    boxes: np.ndarray
    moved: int
    hidden: tuple

    def note(self, what: str = "labels") -> str:
        """One line for the picture and the stats ("" when nothing is hidden).

        >>> Placement((), np.zeros((0, 4)), 0, ("A", "B")).note("well labels")
        '2 overlapping well labels hidden'
        """
        if not self.hidden:
            return ""
        return f"{len(self.hidden)} overlapping {what} hidden"


@functools.lru_cache(maxsize=4096)
def _text_size(text: str, font: int) -> tuple[float, float]:
    """Width and height in pixels of one label at annotate's font of ``font`` pixels
    (remembered: a viewer places the same names every frame)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4, 4), dpi=DPI)
    t = fig.text(0.5, 0.5, text, fontsize=font * 72.0 / DPI * 0.9, ha="center", va="bottom",
                 weight="bold", parse_math=False)
    e = t.get_window_extent(FigureCanvasAgg(fig).get_renderer())
    return float(e.width), float(e.height)


def text_sizes(texts: Sequence[str], height: int) -> np.ndarray:
    """(n, 2) width and height in pixels of each label text as :mod:`~geoshade.styles.annotate`
    draws it in a picture ``height`` pixels high (bold, 0.9 of the annotation font)."""
    font = font_px(height)
    return np.array([_text_size(picture_text(str(t))[:40], font) for t in texts],
                    float).reshape(-1, 2)


def first_inside(points, rect) -> tuple[float, float] | None:
    """The first point of a polyline (pixels, (n, 2); rows of NaN break it: points behind the
    camera) that lies inside ``rect`` (x0, y0, x1, y1): its first vertex inside, or where a
    segment enters the rectangle (Liang–Barsky clipping); None when it never does. A well whose
    head is out of the picture is named where its pipe comes in.

    >>> first_inside(np.array([[50.0, -40], [50, 60], [50, 90]]), (0, 10, 100, 100))
    (50.0, 10.0)
    >>> first_inside(np.array([[500.0, 5], [600, 5]]), (0, 10, 100, 100)) is None
    True
    """
    p = np.asarray(points, float).reshape(-1, 2)
    x0, y0, x1, y1 = rect
    for n in range(len(p)):   # the vertices of one well's pipe
        a = p[n]
        if np.all(np.isfinite(a)) and x0 <= a[0] <= x1 and y0 <= a[1] <= y1:
            return float(a[0]), float(a[1])
        if n + 1 == len(p) or not (np.all(np.isfinite(a)) and np.all(np.isfinite(p[n + 1]))):
            continue
        d = p[n + 1] - a
        lo, hi = 0.0, 1.0
        for q, r in ((-d[0], a[0] - x0), (d[0], x1 - a[0]), (-d[1], a[1] - y0),
                     (d[1], y1 - a[1])):
            if q == 0:
                if r < 0:
                    lo, hi = 1.0, 0.0
                continue
            t = r / q
            if q < 0:
                lo = max(lo, t)
            else:
                hi = min(hi, t)
        if lo <= hi:
            e = a + lo * d
            return float(e[0]), float(e[1])
    return None


def _overlaps(box: np.ndarray, boxes: np.ndarray) -> bool:
    if not len(boxes):
        return False
    x, y, w, h = box
    return bool(np.any((x < boxes[:, 0] + boxes[:, 2] + GAP) & (boxes[:, 0] < x + w + GAP)
                       & (y < boxes[:, 1] + boxes[:, 3] + GAP) & (boxes[:, 1] < y + h + GAP)))


def place_labels(labels: Sequence, size: tuple[int, int], sizes: np.ndarray | None = None
                 ) -> Placement:
    """Move or hide labels so that none covers another.

    Parameters
    ----------
    labels : sequence of :class:`~geoshade.styles.annotate.Label`
        In priority order (earlier labels keep their spot); ``x, y`` the point in pixels.
    size : (width, height)
        The picture's size; labels whose point lies outside are dropped (not counted hidden:
        annotate leaves them out too).
    sizes : (n, 2) array, optional
        Text widths and heights in pixels (default: :func:`text_sizes`).

    Returns
    -------
    Placement

    Examples
    --------
    >>> from geoshade.styles.annotate import Label
    >>> labs = [Label("OP_1", 100, 100), Label("OP_2", 102, 101), Label("OP_3", 104, 99),
    ...         Label("FAR", 300, 200)]
    >>> p = place_labels(labs, (400, 300), sizes=np.array([[40, 16]] * 4))
    >>> [lab.text for lab in p.labels], p.moved, p.hidden
    (['OP_1', 'OP_2', 'OP_3', 'FAR'], 2, ())
    >>> crowd = [Label(f"W{n}", 100, 100) for n in range(12)]
    >>> p = place_labels(crowd, (400, 300), sizes=np.array([[40, 16]] * 12))
    >>> len(p.labels), len(p.hidden), p.note("well labels")
    (4, 8, '8 overlapping well labels hidden')
    """
    w, h = size
    inside = [lab for lab in labels if 0 <= lab.x < w and 0 <= lab.y < h]
    if sizes is None:
        sizes = text_sizes([lab.text for lab in inside], h)
    else:
        keep = [n for n, lab in enumerate(labels) if 0 <= lab.x < w and 0 <= lab.y < h]
        sizes = np.asarray(sizes, float)[keep]
    lift = 0.5 * font_px(h)   # annotate draws the text's bottom this far above the point
    placed, boxes, hidden, moved = [], [], [], 0
    for lab, (bw, bh) in zip(inside, sizes, strict=True):
        # centres of the spots around the point: above (annotate's own), below, right, left,
        # then a second ring: above and below those, and beside them up and down
        ax, ay = 0.5 * bw + lift, lift + 0.5 * bh
        row = bh + GAP
        spots = [(0.0, -ay), (0.0, ay), (ax, 0.0), (-ax, 0.0), (0.0, -ay - row),
                 (0.0, ay + row), (ax, -row), (-ax, -row), (ax, row), (-ax, row)]
        arr = np.array(boxes).reshape(-1, 4)
        for n, (cx, cy) in enumerate(spots):
            box = np.array([lab.x + cx - 0.5 * bw, lab.y + cy - 0.5 * bh, bw, bh])
            x, y = lab.x + cx, lab.y + cy + 0.5 * bh + lift   # where annotate anchors it
            if (box[0] < 0 or box[1] < 0 or box[0] + bw > w or box[1] + bh > h
                    or not (0 <= x < w and 0 <= y < h)):   # annotate draws points inside
                continue
            if _overlaps(box, arr):
                continue
            placed.append(dataclasses.replace(lab, x=float(x), y=float(y)))
            boxes.append(box)
            moved += n > 0
            break
        else:
            hidden.append(str(lab.text))
    return Placement(tuple(placed), np.array(boxes).reshape(-1, 4), moved, tuple(hidden))


__all__ = ["GAP", "Placement", "first_inside", "place_labels", "text_sizes"]
