"""Text composed from cached glyphs: numbers that change every frame, drawn in well under a
millisecond each.

A colour bar whose range follows a selection slider gets new tick labels on every change, and a
title says the new range; laying them out and rasterising them through a matplotlib figure
costs tens of milliseconds (issue 26, target 5). A :class:`GlyphFont` renders each character
once, through matplotlib's own text path with the annotations' white halo (so it looks like the
rest of the overlay), and keeps the sprite; a word is its glyphs composed at the font's
advances and kerning (FreeType's, as matplotlib lays text out) and is kept too (the words of a
title repeat; its numbers change); a line is its words pasted at their pen positions, rounded to
whole pixels.

>>> import numpy as np
>>> f = GlyphFont(9.0)
>>> img = np.zeros((40, 80, 4), np.uint8)
>>> box = f.draw(img, "4500", x=70, y=20, ha="right")
>>> bool(box[0] + box[2] <= 72 and img[..., 3].any())
True
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any

import numpy as np
from matplotlib import patheffects
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties, findfont
from matplotlib.ft2font import FT2Font, Kerning, LoadFlags

#: the overlay's dots per inch (as :data:`geoshade.styles.annotate.DPI`)
DPI = 100
#: words kept per font (least recently used dropped first)
WORDS_KEPT = 2048


class GlyphFont:
    """One font size, colour and halo; glyph sprites made on first use and kept.

    Parameters
    ----------
    size_pt : float
        Font size in points (at :data:`DPI`).
    color : str
        Text colour.
    halo : float
        Width in points of the white stroke around the glyphs (0: none).
    """

    def __init__(self, size_pt: float, color: str = "#111111", halo: float = 2.0):
        self.size_pt, self.color, self.halo = float(size_pt), color, float(halo)
        self.prop = FontProperties(size=self.size_pt)
        # an FT2Font of our own: matplotlib's get_font() object is shared, and its renderer
        # re-sizes it (with a hinting factor) while it draws
        self.font = FT2Font(findfont(self.prop))
        self.font.set_size(self.size_pt, DPI)
        px = self.size_pt * DPI / 72.0
        self.pad = int(np.ceil(self.halo * DPI / 72.0)) + 2
        self.box = int(np.ceil(2.0 * px)) + 2 * self.pad   # a square cell holds any glyph
        self.baseline = self.pad + int(np.ceil(0.5 * px))  # from the cell's bottom
        self._sprites: dict[str, tuple[list, int, int, tuple[int, int]]] = {}
        self._words: OrderedDict[str, tuple[np.ndarray, np.ndarray, int, int]] = OrderedDict()
        self._metrics: dict[str, tuple[Any, float]] = {}    # char -> (glyph index, advance)
        self._kerning: dict[tuple[Any, Any], float] = {}
        self._digit_h = self._height("0")
        # a line's ascent and height as matplotlib measures text ("lp"), for va="top"
        self.font.set_text("lp", 0.0, flags=LoadFlags.NO_HINTING)
        lp_h = self.font.get_width_height()[1] / 64.0
        lp_d = self.font.get_descent() / 64.0
        self.ascent = lp_h - lp_d
        #: baseline to baseline of a text's lines (matplotlib's linespacing 1.2)
        self.line_step = 1.2 * lp_h

    def _height(self, ch: str) -> float:
        g = self.font.load_char(ord(ch), flags=LoadFlags.NO_HINTING)
        return g.height / 64.0

    def has(self, text: str) -> bool:
        """Whether every character of ``text`` is in this font (no fallback needed)."""
        return all(ch == " " or self.font.get_char_index(ord(ch)) != 0 for ch in text)

    def _render(self, ch: str, effects) -> np.ndarray:
        """``ch`` drawn by matplotlib into a transparent cell, its pen at (pad, baseline)."""
        b = self.box
        fig = Figure(figsize=(b / DPI, b / DPI), dpi=DPI)
        fig.patch.set_alpha(0.0)
        canvas = FigureCanvasAgg(fig)
        fig.text(self.pad / b, self.baseline / b, ch, fontproperties=self.prop,
                 va="baseline", ha="left", color=self.color, path_effects=effects)
        canvas.draw()
        return np.asarray(canvas.buffer_rgba()).copy()

    def _sprite(self, ch: str) -> tuple[list, int, int, tuple[int, int]]:
        """``(layers, left, top, (height, width))`` of ``ch``: the halo and the ink as separate
        layers ``(pixels, covered flat indices)`` (a word lays every halo before any ink, as
        matplotlib strokes a whole text before filling it, so a glyph's halo never covers its
        neighbour's ink); ``left``/``top`` place the sprites' corner relative to the pen on the
        baseline."""
        got: tuple[list, int, int, tuple[int, int]] | None = self._sprites.get(ch)
        if got is None:
            b = self.box
            ink = self._render(ch, None)
            layers = [ink]
            if self.halo > 0:
                layers.insert(0, self._render(ch, [patheffects.Stroke(linewidth=self.halo,
                                                                      foreground="white")]))
            alpha = np.maximum.reduce([lay[..., 3] for lay in layers])
            rows = np.flatnonzero(alpha.any(axis=1))
            cols = np.flatnonzero(alpha.any(axis=0))
            if rows.size == 0:
                got = ([], 0, 0, (0, 0))
            else:
                crops = [np.ascontiguousarray(lay[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1])
                         for lay in layers]
                got = ([(c, np.flatnonzero(c[..., 3].reshape(-1))) for c in crops],
                       int(cols[0]) - self.pad, int(rows[0]) - (b - self.baseline),
                       (int(crops[0].shape[0]), int(crops[0].shape[1])))
            self._sprites[ch] = got
        return got

    def advances(self, text: str) -> list[float]:
        """The pen's x (pixels) before each character: FreeType's unhinted advances and
        kerning, as matplotlib lays text out."""
        xs, x, prev = [], 0.0, None
        for ch in text:
            got = self._metrics.get(ch)
            if got is None:
                idx = self.font.get_char_index(ord(ch))
                g = self.font.load_char(ord(ch), flags=LoadFlags.NO_HINTING)
                got = self._metrics[ch] = (idx, g.linearHoriAdvance / 65536.0)
            idx, advance = got
            if prev is not None:
                pair = (prev, idx)
                kern = self._kerning.get(pair)
                if kern is None:
                    kern = self._kerning[pair] = self.font.get_kerning(
                        prev, idx, Kerning.DEFAULT) / 64.0
                x += kern
            xs.append(x)
            x += advance
            prev = idx
        xs.append(x)
        return xs

    def width(self, text: str) -> float:
        """The advance width of ``text`` in pixels."""
        return self.advances(text)[-1]

    def _word(self, word: str) -> tuple[np.ndarray, np.ndarray, int, int]:
        """``(pixels, covered flat indices, left, top)`` of ``word``'s glyphs composed with the
        pen at (0, 0) on the baseline (kept)."""
        got = self._words.get(word)
        if got is not None:
            self._words.move_to_end(word)
            return got
        xs = self.advances(word)
        parts = [(self._sprite(ch), round(px)) for ch, px in zip(word, xs, strict=False)]
        parts = [(sp, px) for sp, px in parts if sp[0]]
        if not parts:
            got = (np.zeros((0, 0, 4), np.uint8), np.zeros(0, np.intp), 0, 0)
        else:
            x0 = min(px + sp[1] for sp, px in parts)
            y0 = min(sp[2] for sp, _ in parts)
            x1 = max(px + sp[1] + sp[3][1] for sp, px in parts)
            y1 = max(sp[2] + sp[3][0] for sp, _ in parts)
            canvas = np.zeros((y1 - y0, x1 - x0, 4), np.uint8)
            for layer in range(len(parts[0][0][0])):   # every halo, then every glyph's ink
                for (layers, left, top, (ch_h, ch_w)), px in parts:
                    crop, where = layers[layer]
                    cx, cy = px + left - x0, top - y0
                    _blend(canvas[cy:cy + ch_h, cx:cx + ch_w], crop, where)
            got = (canvas, np.flatnonzero(canvas[..., 3].reshape(-1)), x0, y0)
        self._words[word] = got
        if len(self._words) > WORDS_KEPT:
            self._words.popitem(last=False)
        return got

    def fit(self, text: str, width: float) -> str:
        r"""Each line of ``text`` wider than ``width`` pixels shortened to the longest prefix
        that fits with "…" after it.

        >>> f = GlyphFont(9.0)
        >>> s = f.fit("short\n" + "a very long line " * 20, 150)
        >>> s.split("\n")[0], s.endswith("…"), f.width(s.split("\n")[1]) <= 150
        ('short', True, True)
        """
        out = []
        for line in text.split("\n"):
            if not line or self.width(line) <= width:
                out.append(line)
                continue
            lo, hi = 0, len(line)
            while lo < hi:
                mid = (lo + hi + 1) // 2
                if self.width(line[:mid].rstrip() + "…") <= width:
                    lo = mid
                else:
                    hi = mid - 1
            out.append(line[:lo].rstrip() + "…")
        return "\n".join(out)

    def draw(self, rgba: np.ndarray, text: str, x: float, y: float, ha: str = "left",
             va: str = "baseline") -> list[int]:
        """Draw ``text`` into ``rgba`` (H, W, 4 uint8, C-contiguous; straight alpha, blended
        as the annotations are) with its anchor at pixel (``x``, ``y``), row 0 at the top.
        ``ha``: left, right or center; ``va``: baseline, center (the middle of a digit's
        height on ``y``) or top (a line's top on ``y``, as matplotlib's). Returns the drawn box
        ``[x, y, width, height]`` (empty: ``[W, H, 0, 0]``-like, width 0)."""
        xs = self.advances(text)
        x0 = x - {"left": 0.0, "right": xs[-1], "center": xs[-1] / 2}[ha]
        base = y + {"baseline": 0.0, "center": self._digit_h / 2, "top": self.ascent}[va]
        h, w = rgba.shape[:2]
        box = [w, h, 0, 0]
        start = 0
        for word in text.split(" "):
            px, start = xs[start], start + len(word) + 1
            if not word:
                continue
            crop, where, left, top = self._word(word)
            if where.size == 0:
                continue
            cx, cy = round(x0 + px) + left, round(base) + top
            ch_h, ch_w = crop.shape[:2]
            if cx < 0 or cy < 0 or cx + ch_w > w or cy + ch_h > h:
                continue   # off the picture: never wraps
            region = rgba[cy:cy + ch_h, cx:cx + ch_w]
            _blend(region, crop, where)
            box = [min(box[0], cx), min(box[1], cy), max(box[2], cx + ch_w),
                   max(box[3], cy + ch_h)]
        return [box[0], box[1], max(0, box[2] - box[0]), max(0, box[3] - box[1])]


def _blend(region: np.ndarray, sprite: np.ndarray, where: np.ndarray) -> None:
    """``sprite`` (straight RGBA) over ``region`` (a view), at the sprite's covered pixels."""
    cols = sprite.shape[1]
    r, c = np.divmod(where, cols)
    src = sprite.reshape(-1, 4)[where].astype(np.float32)
    dst = region[r, c].astype(np.float32)
    sa = src[:, 3:4] / 255.0
    da = dst[:, 3:4] / 255.0
    oa = sa + da * (1 - sa)
    rgb = (src[:, :3] * sa + dst[:, :3] * da * (1 - sa)) / np.maximum(oa, 1e-6)
    region[r, c, :3] = np.clip(np.rint(rgb), 0, 255).astype(np.uint8)
    region[r, c, 3] = np.clip(np.rint(oa[:, 0] * 255), 0, 255).astype(np.uint8)


__all__ = ["DPI", "GlyphFont"]
