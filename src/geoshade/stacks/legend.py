"""The legend drawn onto a rendered picture (Pillow, CPU side)."""

from __future__ import annotations

import numpy as np

from geoshade.models.stacks import Legend

#: most legend rows drawn; the rest are summarised in one line
MAX_ROWS = 24


def draw_legend(rgba: np.ndarray, legend: Legend, codes, title: str = "") -> np.ndarray:
    """A copy of ``rgba`` with a legend of ``codes`` (colour swatch + name) at the top left.

    Examples
    --------
    >>> lg = Legend.from_codes([1, 2])
    >>> out = draw_legend(np.full((60, 120, 4), 255, np.uint8), lg, [1, 2], title="lithok")
    >>> out.shape, bool((out != 255).any())
    ((60, 120, 4), True)
    """
    from PIL import Image, ImageDraw, ImageFont

    img = Image.fromarray(np.ascontiguousarray(rgba, np.uint8), "RGBA")
    draw = ImageDraw.Draw(img, "RGBA")
    font = ImageFont.load_default()
    codes = [int(c) for c in codes]
    rows = codes[:MAX_ROWS]
    extra = len(codes) - len(rows)
    line = 12
    idx = legend.index_of(np.array(rows, np.int64)) - 1 if rows else np.zeros(0, int)
    names = [f"{c}  {legend.names[i]}" for c, i in zip(rows, idx, strict=True)]
    if extra:
        names.append(f"… {extra} more")
    lines = ([title] if title else []) + names
    width = max((int(draw.textlength(s, font=font)) for s in lines), default=0) + 26
    height = line * len(lines) + 6
    draw.rectangle([2, 2, 2 + width, 2 + height], fill=(255, 255, 255, 215),
                   outline=(80, 80, 80, 255))
    y = 5
    if title:
        draw.text((6, y), title, fill=(0, 0, 0, 255), font=font)
        y += line
    for k, name in enumerate(names):
        if k < len(rows):
            r, g, b, _ = (int(v) for v in legend.rgba[idx[k]])
            draw.rectangle([6, y + 1, 16, y + 10], fill=(r, g, b, 255), outline=(0, 0, 0, 255))
        draw.text((20, y), name, fill=(0, 0, 0, 255), font=font)
        y += line
    return np.asarray(img).copy()
