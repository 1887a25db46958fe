"""Annotations drawn over a rendered picture: title and time, colour bar, categorical legend,
axes triad, scale bar and labels at points such as well heads (matplotlib's text and layout,
composited on the CPU; no GL).

Sizes follow the picture: text is :data:`FONT_FRACTION` of the image height (at least
:data:`MIN_FONT_PX` pixels), so 1024×768 and 3840×2160 read alike. Only the pixels the
annotations cover change: the overlay is transparent elsewhere, and the 3D picture under it is
kept bit for bit.

:func:`annotate` returns the picture and its *layout* (positions in pixels, row 0 at the top,
tick values and texts), which the Views put in ``stats["annotations"]`` so tests and tools can
check what is where.

>>> import numpy as np
>>> from geoshade.styles.palette import palette
>>> bar = ColorBar("PORO", lo=0.05, hi=0.35, palette=palette("viridis"))
>>> img, layout = annotate(np.full((240, 320, 4), 255, np.uint8), Annotations("case", colorbar=bar))
>>> layout["colorbar"]["ticks"][0]["value"] >= 0.05, layout["font_px"]
(True, 11)
"""

from __future__ import annotations

import dataclasses
import functools
import math
import sys
import threading
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geoshade.errors import terminal_safe

#: text height as a fraction of the picture's height, and its smallest size in pixels
FONT_FRACTION = 0.018
MIN_FONT_PX = 11
#: the overlay is drawn at this many dots per inch (points = pixels * 72 / DPI)
DPI = 100


def picture_text(text) -> str:
    r"""``text`` (a name or unit read from a file) as a picture shows it: control characters
    escaped as on a terminal (:func:`geoshade.errors.terminal_safe`; newlines kept), so an
    escape sequence is drawn as ``\x1b`` instead of a missing glyph.

    >>> picture_text("W\x1b]0;x\x07")
    'W\\x1b]0;x\\x07'
    """
    return terminal_safe(text)


def _text(fig, *args, **kw):
    """``fig.text`` drawing its string as it is: never as matplotlib's mathtext (a name such
    as ``W$\\foo$`` from a file is no formula, and a bad one raised at the draw)."""
    return fig.text(*args, parse_math=False, **kw)


def _safe(obj, *names: str) -> None:
    """Escape the text fields ``names`` of a frozen dataclass (see :func:`picture_text`)."""
    for name in names:
        value = getattr(obj, name)
        if isinstance(value, str):
            object.__setattr__(obj, name, picture_text(value))


@dataclass(frozen=True)
class ColorBar:
    """A continuous colouring: ``lo``..``hi`` of ``label`` [``unit``] over ``palette``.

    log: the palette spans ``log10(lo)..log10(hi)``; auto: log was chosen automatically (said
    on the bar); nan_color: RGBA 0..1 of the values without a colour (shown as a swatch).
    """

    label: str
    lo: float
    hi: float
    palette: np.ndarray = field(repr=False, compare=False)
    unit: str = ""
    log: bool = False
    auto: bool = False
    nan_color: tuple | None = None

    def __post_init__(self):
        _safe(self, "label", "unit")


@dataclass(frozen=True)
class Legend:
    """A categorical colouring: ``entries`` of (text, RGBA 0..255); ``nan_color`` (RGBA
    0..255): the colour of the values without a class (a "no value" swatch after the entries,
    in the layout as ``nan``, not among the entries)."""

    title: str
    entries: tuple = ()
    nan_color: tuple | None = None

    def __post_init__(self):
        _safe(self, "title")
        object.__setattr__(self, "entries", tuple(
            (picture_text(text) if isinstance(text, str) else text, rgba)
            for text, rgba in self.entries))


@dataclass(frozen=True)
class Triad:
    """Axes directions on the screen: ``axes`` of (label, (dx, dy), colour) with (dx, dy) the
    projected unit vector (x right, y up), its length < 1 when the axis points into the screen."""

    axes: tuple = ()


@dataclass(frozen=True)
class ScaleBar:
    """A map view's scale: ``units_per_pixel`` of the model's length ``unit``."""

    units_per_pixel: float
    unit: str = ""

    def __post_init__(self):
        _safe(self, "unit")


@dataclass(frozen=True)
class Label:
    """A name at a point of the picture (a well head): ``x, y`` in pixels (row 0 at the top),
    the text centred just above the point, in ``color`` (RGB 0..1) with a white halo."""

    text: str
    x: float
    y: float
    color: tuple = (0.07, 0.07, 0.07)

    def __post_init__(self):
        _safe(self, "text")


@dataclass(frozen=True)
class Annotations:
    """What to draw over a picture (anything None is left out).

    labels: :class:`Label` s that follow the camera (drawn with the triad, never cached)
    """

    title: str = ""
    subtitle: str = ""
    colorbar: ColorBar | None = None
    legend: Legend | None = None
    triad: Triad | None = None
    scalebar: ScaleBar | None = None
    labels: tuple = ()

    def __post_init__(self):
        _safe(self, "title", "subtitle")


def font_px(height: int) -> int:
    """The text height in pixels for a picture ``height`` pixels high.

    >>> font_px(768), font_px(2160), font_px(100)
    (14, 39, 11)
    """
    return max(MIN_FONT_PX, round(FONT_FRACTION * height))


def exaggeration_text(factor) -> str:
    """What a picture says of its vertical exaggeration: '' at 1 (or unknown), else
    ``vertical exaggeration ×5`` (every part puts it in its subtitle).

    >>> exaggeration_text(1.0), exaggeration_text(5), exaggeration_text(None)
    ('', 'vertical exaggeration ×5', '')
    """
    try:
        f = float(factor)
    except (TypeError, ValueError):
        return ""
    return "" if f == 1.0 or not math.isfinite(f) else f"vertical exaggeration ×{f:g}"


def join_subtitle(*parts: str) -> str:
    """The non-empty ``parts`` joined with `` · `` (a subtitle's items).

    >>> join_subtitle("step 2 of 3", "", "vertical exaggeration ×5")
    'step 2 of 3 · vertical exaggeration ×5'
    """
    return " · ".join(p for p in parts if p)


def nice_length(target: float) -> float:
    """1, 2 or 5 times a power of ten, at most ``target`` (a scale bar's length).

    >>> nice_length(730), nice_length(0.031), nice_length(1999)
    (500.0, 0.02, 1000.0)
    """
    if not target > 0:
        return 0.0
    e = 10.0 ** math.floor(math.log10(target))
    for m in (5, 2, 1):
        if m * e <= target:
            return float(m * e) if m * e >= 1 else float(f"{m * e:.12g}")
    return float(e)


def _fmt(v: float) -> str:
    """A tick label: short, no float noise (``0.15``, ``10000``, ``1e+06``, ``2e-05``)."""
    if v == 0:
        return "0"
    a = abs(v)
    if a >= 1e6 or a < 1e-3:
        return f"{v:.2g}"
    return f"{v:.6g}"


def warm_up() -> None:
    """Import the matplotlib modules :func:`annotate` draws with on a daemon thread, once a
    process (~0.5 s: a View's first picture does not wait for them; a View starts it while it
    opens its data). An import that fails there fails again, said, where it is used.

    >>> warm_up()
    """
    if "matplotlib.backends.backend_agg" in sys.modules or _WARMING:
        return
    _WARMING.append(threading.Thread(target=_import_matplotlib, daemon=True,
                                     name="geoshade-annotation-imports"))
    _WARMING[0].start()


_WARMING: list = []


def _import_matplotlib() -> None:
    try:
        from matplotlib import lines, patches, patheffects, ticker  # noqa: F401
        from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: F401
        from matplotlib.figure import Figure  # noqa: F401
    except Exception:  # said where annotate imports them
        pass


def annotate(rgba: np.ndarray, ann: Annotations, cache: dict | None = None
             ) -> tuple[np.ndarray, dict]:
    """``rgba`` with ``ann`` drawn over it, and the layout of what was drawn.

    The result is a new array; pixels no annotation covers are ``rgba``'s, unchanged.
    ``cache`` (a dict the caller keeps; a viewer draws many frames): three layers, each drawn
    again only when its own content changes — the colour bar and legend; the title and
    subtitle (a step or date change redraws only their strip, in a figure kept for it); the
    triad, scale bar and labels, which follow the camera.
    """
    h, w = rgba.shape[:2]
    cache = {} if cache is None else cache
    layout: dict = {"width": w, "height": h, "font_px": font_px(h)}
    keys = dataclasses.replace(ann, title="", subtitle="", triad=None, scalebar=None, labels=())
    over, part, where = _cached(cache, "keys", _static_key(keys, w, h),
                                lambda: _static_overlay(keys, w, h))
    layout.update(part)
    out = _composite(rgba, over, where)
    if ann.colorbar is not None and "colorbar" in layout:
        _draw_ticks(out, ann.colorbar, layout["colorbar"], h)
    if ann.title or ann.subtitle:
        strip, texts, where = _title_layer(cache, ann, w, h)
        layout["title"] = texts
        _composite(out, strip, where, inplace=True)
    if ann.triad is not None or ann.scalebar is not None or ann.labels:
        over, part, where = _cached(cache, "camera", (w, h, ann.triad, ann.scalebar, ann.labels),
                                    lambda: _camera_overlay(ann, w, h))
        layout.update(part)
        _composite(out, over, where, inplace=True)
    return out, layout


def _cached(cache: dict, name: str, key, make) -> tuple[np.ndarray, dict, tuple]:
    """``(overlay, its layout, covered pixels)`` of layer ``name``, made by ``make()`` only when
    ``key`` changed."""
    entry = cache.get(name)
    if entry is None or entry["key"] != key:
        over, part = make()
        entry = cache[name] = {"key": key, "over": over, "layout": part, "where": _source(over)}
    return entry["over"], _copy_layout(entry["layout"]), entry["where"]


def _copy_layout(part: dict) -> dict:
    return {k: (list(v) if isinstance(v, list) else dict(v) if isinstance(v, dict) else v)
            for k, v in part.items()}


def _camera_overlay(ann: Annotations, w: int, h: int) -> tuple[np.ndarray, dict]:
    """The triad, scale bar and labels as a transparent RGBA overlay, and their layout."""
    fig, canvas, fpx, pt, margin, halo = _figure(w, h)
    layout: dict = {}
    if ann.triad is not None:
        layout["triad"] = _triad(fig, ann.triad, w, h, fpx, pt, margin, halo)
    if ann.scalebar is not None:
        sb = _scalebar(fig, ann.scalebar, w, h, fpx, pt, margin, halo)
        if sb:
            layout["scalebar"] = sb
    texts = _labels(fig, ann.labels, w, h, fpx, pt, halo) if ann.labels else []
    canvas.draw()
    if ann.labels:
        layout["labels"] = _label_boxes(texts, canvas, h)
    return np.asarray(canvas.buffer_rgba()).copy(), layout


def _title_layer(cache: dict, ann: Annotations, w: int, h: int
                 ) -> tuple[np.ndarray, list, tuple]:
    """The title and subtitle drawn into a strip as wide as the picture at its top (a figure
    kept in ``cache`` and only its texts changed: a step or date change costs a few ms): the
    strip (its flat pixel indices are the picture's), the layout's text entries and the covered
    pixels' flat indices."""
    from matplotlib import patheffects

    fpx = font_px(h)
    pt = fpx * 72.0 / DPI
    margin = max(4, round(0.8 * fpx))
    step_t = round(1.35 * pt * DPI / 72)
    n_sub = ann.subtitle.count("\n") + 1 if ann.subtitle else 0
    th = min(h, margin + step_t * (1 + n_sub) + 2 * fpx)
    key = (w, h, th, ann.title, ann.subtitle)
    entry = cache.get("title")
    if entry is not None and entry["key"] == key:
        return entry["over"], [dict(t) for t in entry["texts"]], entry["where"]
    fonts = (_glyph_font(pt, max(2.0, pt / 4)), _glyph_font(pt * 0.9, max(2.0, pt / 4)))
    if all(f.has(t) for f, t in zip(fonts, (ann.title, ann.subtitle), strict=True)):
        # from cached glyphs and words: a new range or date costs about a millisecond
        strip = np.zeros((th, w, 4), np.uint8)
        texts, y = [], margin
        for font, text in zip(fonts, (ann.title, ann.subtitle), strict=True):
            if not text:
                continue
            text = font.fit(text, w - 2 * margin)
            for i, line in enumerate(text.split("\n")):
                font.draw(strip, line, margin, y + i * font.line_step, va="top")
            texts.append({"text": text, "x": margin, "y": y})
            y += round(1.35 * font.size_pt * DPI / 72)
        cache["title"] = {"key": key, "over": strip, "texts": texts, "where": _source(strip),
                          "size": None}
        return strip, [dict(t) for t in texts], cache["title"]["where"]
    # a character outside the font (matplotlib falls back to another): a kept figure
    if entry is None or entry.get("size") != (w, th, fpx):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=(w / DPI, th / DPI), dpi=DPI)
        fig.patch.set_alpha(0.0)
        canvas = FigureCanvasAgg(fig)
        halo = [patheffects.withStroke(linewidth=max(2.0, pt / 4), foreground="white")]
        arts = [_text(fig, margin / w, 1.0, "", fontsize=size, va="top", ha="left",
                         color="#111111", path_effects=halo) for _, size in
                [(None, pt), (None, pt * 0.9)]]
        entry = cache["title"] = {"size": (w, th, fpx), "canvas": canvas, "arts": arts}
    canvas, arts = entry["canvas"], entry["arts"]
    texts, y = [], margin
    for art, (text, _size) in zip(arts, [(ann.title, pt), (ann.subtitle, pt * 0.9)],
                                  strict=True):
        art.set_visible(bool(text))
        if not text:
            continue
        art.set_y(1.0 - y / th)
        text = _fit_lines(art, text, w - 2 * margin, canvas)
        texts.append({"text": text, "x": margin, "y": y})
        y += round(1.35 * art.get_fontsize() * DPI / 72)
    canvas.draw()
    # the strip's rows are the picture's first rows, as wide: its flat pixel indices are the
    # picture's (the composite reads only those)
    over = np.asarray(canvas.buffer_rgba())[:th].copy()
    entry.update(key=key, over=over, texts=texts, where=_source(over))
    return over, [dict(t) for t in texts], entry["where"]


def _range(cb: ColorBar) -> tuple[float, float]:
    lo, hi = float(cb.lo), float(cb.hi)
    if hi <= lo:
        hi = lo + (abs(lo) if lo else 1.0) * 1e-6
    return lo, hi


def _ticks(cb: ColorBar) -> tuple[list[float], bool]:
    """The major tick values of a colour bar within its range, and whether the range is
    narrower than the labels (then one tick, at the middle: "one value")."""
    values, single = _tick_values(*_range(cb), bool(cb.log))
    return list(values), single


@functools.lru_cache(maxsize=512)
def _tick_values(lo: float, hi: float, log: bool) -> tuple[tuple[float, ...], bool]:
    from matplotlib.ticker import LogLocator, MaxNLocator

    locator = LogLocator(base=10, numticks=8) if log else MaxNLocator(nbins=6)
    values = tuple(float(v) for v in locator.tick_values(lo, hi) if lo <= v <= hi)
    shown = [_fmt(v) for v in values]
    if len(set(shown)) < len(shown):
        return (0.5 * (lo + hi),), True
    return values, False


def _minor_ticks(lo: float, hi: float) -> list[float]:
    """2…9 × each decade inside ``lo..hi`` (a log bar's unlabelled marks)."""
    out = []
    for e in range(math.floor(math.log10(lo)), math.ceil(math.log10(hi)) + 1):
        out += [m * 10.0 ** e for m in range(2, 10) if lo <= m * 10.0 ** e <= hi]
    return out


_FONTS: dict = {}


def _glyph_font(size_pt: float, halo: float):
    from geoshade.styles.glyphs import GlyphFont

    key = (round(size_pt, 4), round(halo, 4))
    if key not in _FONTS:
        _FONTS[key] = GlyphFont(size_pt, "#111111", halo)
    return _FONTS[key]


def _draw_ticks(out: np.ndarray, cb: ColorBar, entry: dict, h: int) -> None:
    """The colour bar's tick marks and numbers drawn into ``out`` (in place) from cached
    glyphs, and ``entry`` (the layout's colour bar) given the range and the ticks."""
    x0, top, _bar_w, bar_h = entry["bbox"]
    fpx = font_px(h)
    pt = fpx * 72.0 / DPI
    lo, hi = _range(cb)
    values, _single = _ticks(cb)

    def row(v: float) -> float:
        frac = (math.log10(v) - math.log10(lo)) / (math.log10(hi) - math.log10(lo)) \
            if cb.log else (v - lo) / (hi - lo)
        return top + bar_h * (1 - frac)

    ink = np.array([17, 17, 17, 255], np.uint8)
    lw = max(1, round(max(0.5, pt / 14) * DPI / 72))
    major = max(2, round(fpx * 0.35 * DPI / 72))
    minor = max(1, round(2.0 * DPI / 72))
    for v, length in [(v, major) for v in values] + \
                     [(v, minor) for v in (_minor_ticks(lo, hi) if cb.log else [])]:
        y = round(row(v)) - (lw - 1) // 2
        out[max(0, y):max(0, y + lw), max(0, x0 - length):x0] = ink
    font = _glyph_font(pt * 0.85, max(2.0, pt / 4))
    right = x0 - major - 3.5 * DPI / 72
    ticks = []
    for v in values:
        text = _fmt(v)
        font.draw(out, text, right, row(v), ha="right", va="center")
        ticks.append({"value": v, "text": text, "y": round(row(v))})
    entry.update(lo=lo, hi=hi, ticks=ticks)


def _static_key(ann: Annotations, w: int, h: int) -> tuple:
    cb = ann.colorbar
    cbk = None if cb is None else (cb.label, cb.unit, cb.log, cb.auto, _ticks(cb)[1],
                                   cb.nan_color, np.asarray(cb.palette, np.uint8).tobytes())
    return (w, h, cbk, ann.legend)


def _figure(w: int, h: int):
    from matplotlib import patheffects
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fpx = font_px(h)
    pt = fpx * 72.0 / DPI
    margin = max(4, round(0.8 * fpx))
    fig = Figure(figsize=(w / DPI, h / DPI), dpi=DPI)
    fig.patch.set_alpha(0.0)
    canvas = FigureCanvasAgg(fig)
    halo = [patheffects.withStroke(linewidth=max(2.0, pt / 4), foreground="white")]
    return fig, canvas, fpx, pt, margin, halo


def _fit_lines(art, text: str, width: float, canvas) -> str:
    r"""Shorten each line of the text artist ``art`` that is wider than ``width`` pixels to what
    fits, ending in "…" (a title is never cut at the picture's edge); returns the text drawn.

    >>> fig, canvas, *_ = _figure(200, 100)
    >>> art = fig.text(0, 1, "x")
    >>> s = _fit_lines(art, "short\n" + "a very long line " * 20, 150, canvas)
    >>> s.split("\n")[0], s.endswith("…"), len(s) < 60
    ('short', True, True)
    """
    renderer = canvas.get_renderer()

    def wide(s: str) -> float:
        art.set_text(s)
        return art.get_window_extent(renderer).width

    lines = text.split("\n")
    out = []
    for line in lines:
        if not line or wide(line) <= width:
            out.append(line)
            continue
        lo, hi = 0, len(line)   # the longest prefix that fits with the ellipsis
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if wide(line[:mid].rstrip() + "…") <= width:
                lo = mid
            else:
                hi = mid - 1
        out.append(line[:lo].rstrip() + "…")
    fitted = "\n".join(out)
    art.set_text(fitted)
    return fitted


def _static_overlay(ann: Annotations, w: int, h: int) -> tuple[np.ndarray, dict]:
    """The colour bar's frame and the legend as a transparent RGBA overlay, and their layout
    (the title is :func:`_title_layer`'s, the bar's ticks :func:`_draw_ticks`')."""
    fig, canvas, fpx, pt, margin, halo = _figure(w, h)
    layout: dict = {"width": w, "height": h, "font_px": fpx}

    def fx(px: float) -> float:  # pixels from the left -> figure fraction
        return px / w

    def fy(py: float) -> float:  # pixels from the top -> figure fraction (from the bottom)
        return 1.0 - py / h

    right = w - margin
    if ann.colorbar is not None:
        cb = ann.colorbar
        bar_w = max(10, round(0.022 * w))
        bar_h = round(0.45 * h)
        top = round(0.5 * h - 0.5 * bar_h)
        x0 = right - bar_w
        # the gradient: the palette sampled along the bar, pixel for pixel (row 0 = hi)
        pal = np.asarray(cb.palette, np.uint8)[:, :4]
        rows = np.minimum((np.arange(bar_h)[::-1] + 0.5) / bar_h * len(pal),
                          len(pal) - 1).astype(int)
        grad = np.repeat(pal[rows][:, None, :], bar_w, axis=1)
        fig.figimage(grad, xo=x0, yo=h - top - bar_h, origin="upper", zorder=1)
        # the frame only: the ticks and their numbers follow the range, drawn per picture from
        # cached glyphs (_draw_ticks), so a new range does not lay this layer out again
        ax = fig.add_axes((fx(x0), fy(top + bar_h), fx(bar_w), bar_h / h))
        ax.set_facecolor("none")
        ax.set_xticks([])
        ax.set_yticks([])
        for spine in ax.spines.values():
            spine.set_linewidth(max(0.5, pt / 14))
        single = _ticks(cb)[1]
        label = cb.label + (f" [{cb.unit}]" if cb.unit else "")
        scale = ("log scale (auto)" if cb.log and cb.auto else "log scale") if cb.log else ""
        if single:
            scale = "one value"
        _text(fig, fx(right), fy(top - 0.6 * fpx), label, fontsize=pt, ha="right", va="bottom",
                 color="#111111", path_effects=halo)
        if scale:
            _text(fig, fx(right), fy(top + bar_h + 0.5 * fpx), scale, fontsize=pt * 0.8,
                     ha="right", va="top", color="#111111", path_effects=halo)
        nan_box = None
        if cb.nan_color is not None:
            from matplotlib.patches import Rectangle

            sw = round(0.9 * fpx)
            ny = top + bar_h + round((2.0 if scale else 0.8) * fpx)
            fig.add_artist(Rectangle((fx(right - sw), fy(ny + sw)), sw / w, sw / h,
                                     transform=fig.transFigure, facecolor=cb.nan_color,
                                     edgecolor="#333333", linewidth=max(0.4, pt / 20)))
            _text(fig, fx(right - sw - 0.4 * fpx), fy(ny + sw / 2), "no value", fontsize=pt * 0.8,
                     ha="right", va="center", color="#111111", path_effects=halo)
            nan_box = [right - sw, ny, sw, sw]
        layout["colorbar"] = {"bbox": [x0, top, bar_w, bar_h], "label": label, "log": cb.log,
                              "auto": cb.auto, "lo": None, "hi": None, "ticks": [],
                              "scale": scale, "nan": nan_box}
        right = x0 - 6 * fpx
    if ann.legend is not None and ann.legend.entries:
        layout["legend"] = _legend(fig, ann.legend, w, h, fpx, pt, margin, halo)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).copy(), layout


def _legend(fig, legend: Legend, w, h, fpx, pt, margin, halo) -> dict:
    """Swatches and names at the top right, wrapped into columns that fit 80 % of the height;
    the columns are as wide as the widest name and the block as wide as its title (measured
    as drawn), so nothing runs past the picture's edge. An entry with a transparent colour
    (``… and 12 more codes``) has no swatch."""
    from matplotlib.patches import Rectangle

    row = round(1.45 * fpx)
    top = margin + round(2.2 * fpx)
    rows = max(1, int((0.8 * h - top) // row) - 1)
    entries = list(legend.entries)
    nan_at = None
    if legend.nan_color is not None:   # the no-value swatch: one more row, not an entry
        nan_at = len(entries)
        entries.append(("no value", tuple(legend.nan_color)))
    ncols = max(1, math.ceil(len(entries) / rows))
    rows = math.ceil(len(entries) / ncols)
    renderer = fig.canvas.get_renderer()
    texts = [_text(fig, 0, 0, str(text)[:40], fontsize=pt, va="center", ha="left",
                      color="#111111", path_effects=halo) for text, _ in entries]
    title = None
    if legend.title:
        title = _text(fig, 0, 0, legend.title, fontsize=pt, va="top", ha="left",
                         color="#111111", weight="bold", path_effects=halo)
    widest = max((t.get_window_extent(renderer).width for t in texts), default=0.0)
    col_w = math.ceil(1.4 * fpx + widest + 0.8 * fpx)
    title_w = math.ceil(title.get_window_extent(renderer).width) if title is not None else 0
    block_w = min(max(ncols * col_w, title_w), w - 2 * margin)
    x_left = w - margin - block_w
    out: dict[str, Any] = {"title": legend.title, "columns": ncols, "entries": [],
                           "bbox": [x_left, top - row, block_w, (rows + 1) * row]}
    if title is not None:
        title.set_position((x_left / w, 1 - (top - row) / h))
    for n, ((text, rgba), t) in enumerate(zip(entries, texts, strict=True)):
        c, r = divmod(n, rows)
        x = x_left + c * col_w
        y = top + r * row
        sw = round(0.9 * fpx)
        if int(rgba[3]) > 0:
            fig.add_artist(Rectangle((x / w, 1 - (y + sw) / h), sw / w, sw / h,
                                     transform=fig.transFigure,
                                     facecolor=np.asarray(rgba[:4], float) / 255.0,
                                     edgecolor="#333333", linewidth=max(0.4, pt / 20)))
        t.set_position(((x + 1.4 * fpx) / w, 1 - (y + sw / 2) / h))
        entry = {"text": str(text)[:40], "rgba": [int(v) for v in rgba[:4]], "x": x, "y": y,
                 "swatch": [x, y, sw, sw]}
        if n == nan_at:
            out["nan"] = entry
        else:
            out["entries"].append(entry)
    return out


def _triad(fig, triad: Triad, w, h, fpx, pt, margin, halo) -> dict:
    length = max(3 * fpx, round(0.07 * h))
    ox, oy = margin + 1.3 * length, h - margin - 1.3 * length  # pixels, row 0 at the top
    out: dict[str, Any] = {"origin": [ox, oy], "length": length, "axes": []}
    for label, (dx, dy), color in triad.axes:
        ex, ey = ox + dx * length, oy - dy * length
        fig.add_artist(_line(fig, (ox, oy), (ex, ey), w, h, color, max(1.0, pt / 7)))
        if math.hypot(dx, dy) > 0.15:
            tx, ty = ox + dx * length * 1.28, oy - dy * length * 1.28
            _text(fig, tx / w, 1 - ty / h, label, fontsize=pt * 0.9, ha="center", va="center",
                     color=color, weight="bold", path_effects=halo)
        out["axes"].append({"label": label, "end": [round(ex, 1), round(ey, 1)]})
    return out


def _line(fig, a, b, w, h, color, lw):
    from matplotlib.lines import Line2D

    return Line2D([a[0] / w, b[0] / w], [1 - a[1] / h, 1 - b[1] / h], transform=fig.transFigure,
                  color=color, linewidth=lw, solid_capstyle="round")


def _scalebar(fig, sb: ScaleBar, w, h, fpx, pt, margin, halo) -> dict | None:
    if not (sb.units_per_pixel > 0 and math.isfinite(sb.units_per_pixel)):
        return None
    value = nice_length(0.2 * w * sb.units_per_pixel)
    if value <= 0:
        return None
    px = value / sb.units_per_pixel
    x1 = w - margin
    x0 = x1 - px
    y = h - margin - 0.4 * fpx
    fig.add_artist(_line(fig, (x0, y), (x1, y), w, h, "#111111", max(1.5, pt / 5)))
    for x in (x0, x1):
        fig.add_artist(_line(fig, (x, y - 0.35 * fpx), (x, y + 0.35 * fpx), w, h, "#111111",
                             max(1.0, pt / 8)))
    text = f"{_fmt(value)} {sb.unit}".strip()
    _text(fig, x1 / w, 1 - (y - 0.5 * fpx) / h, text, fontsize=pt * 0.9,   # ends at the bar's
             ha="right", va="bottom", color="#111111", path_effects=halo)  # end: never cut
    return {"value": value, "text": text, "length_px": round(px, 2), "x": [x0, x1], "y": y}


def _labels(fig, labels, w, h, fpx, pt, halo) -> list:
    """The labels inside the picture as matplotlib texts, with their layout entries."""
    out = []
    lift = 0.5 * fpx
    for lab in labels:
        if not (0 <= lab.x < w and 0 <= lab.y < h):
            continue
        t = _text(fig, lab.x / w, 1 - (lab.y - lift) / h, str(lab.text)[:40], fontsize=pt * 0.9,
                     ha="center", va="bottom", color=tuple(lab.color), weight="bold",
                     path_effects=halo)
        out.append((t, {"text": str(lab.text)[:40], "x": round(float(lab.x), 1),
                        "y": round(float(lab.y), 1)}))
    return out


def _label_boxes(texts, canvas, h) -> list[dict]:
    """Layout entries of drawn labels with their ``bbox`` [x, y, width, height] in pixels."""
    renderer = canvas.get_renderer()
    out = []
    for t, entry in texts:
        e = t.get_window_extent(renderer)
        entry["bbox"] = [round(float(e.x0), 1), round(float(h - e.y1), 1),
                         round(float(e.width), 1), round(float(e.height), 1)]
        out.append(entry)
    return out


def _composite(rgba: np.ndarray, over: np.ndarray, where: np.ndarray | tuple | None = None,
               inplace: bool = False) -> np.ndarray:
    """``over`` (straight RGBA) over ``rgba``; pixels where ``over`` is transparent are kept.
    ``where``: the flat indices of ``over``'s covered pixels when known, or a cached layer's
    :func:`_source`;
    the blend touches those pixels only (a few per cent of a picture). ``over`` may be the
    picture's first rows only (a strip as wide). ``inplace``: into ``rgba`` (C-contiguous)."""
    out = rgba if inplace else np.array(rgba, copy=True, order="C")
    idx, srcp, sa, keep = where if isinstance(where, tuple) else _source(over, where)
    if idx.size == 0:
        return out
    flat = out.reshape(-1, 4)
    dst = flat[idx].astype(np.float32)
    da = dst[:, 3:4] * np.float32(1 / 255)
    dk = da * keep
    oa = sa + dk
    rgb = (srcp + dst[:, :3] * dk) / np.maximum(oa, np.float32(1e-6))
    flat[idx, :3] = np.clip(np.rint(rgb), 0, 255).astype(np.uint8)
    flat[idx, 3] = np.clip(np.rint(oa[:, 0] * 255), 0, 255).astype(np.uint8)
    return out


def _source(over: np.ndarray, where: np.ndarray | None = None) -> tuple:
    """What a composite needs of an overlay, computed once per cached layer: its covered
    pixels' flat indices, their premultiplied colour, alpha and 1 − alpha (float32)."""
    if where is None:
        where = covered(over)
    src = np.asarray(over).reshape(-1, 4)[where].astype(np.float32)
    sa = src[:, 3:4] * np.float32(1 / 255)
    return where, src[:, :3] * sa, sa, np.float32(1) - sa


def covered(over: np.ndarray) -> np.ndarray:
    """Flat indices of the pixels of an RGBA overlay that are not fully transparent."""
    return np.flatnonzero(np.ascontiguousarray(over[..., 3]).reshape(-1))


def triad_axes(view_matrix, labels=("E", "N", "Up"), model_axes=None) -> Triad:
    """The screen directions of the world axes (or of ``model_axes``, (3, 3) world vectors of
    e.g. a grid's I, J, K) under the camera's ``view_matrix``; x red, y green, z blue."""
    r = np.asarray(view_matrix, float)[:3, :3]
    axes = np.eye(3) if model_axes is None else np.asarray(model_axes, float)
    colors = ("#d62728", "#2ca02c", "#1f77b4")
    out = []
    for label, a, c in zip(labels, axes, colors, strict=True):
        n = np.linalg.norm(a)
        s = r @ (a / n if n > 0 else a)
        out.append((label, (float(s[0]), float(s[1])), c))
    return Triad(tuple(out))


__all__ = ["Annotations", "ColorBar", "Label", "Legend", "ScaleBar", "Triad", "annotate",
           "exaggeration_text", "font_px", "join_subtitle", "nice_length", "triad_axes"]
