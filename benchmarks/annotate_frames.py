"""What the annotations cost a viewer per frame (issue 26, target 5): a grid's title, colour bar
and triad over a 1024×768 picture, with the View's cache, when only the step/date changes, when
a core's selection changes (the colour bar's range, its ticks and the title's numbers), and
when nothing changes (medians of 9, 9 and 5 frames; the step changes are timed on a second pass
through the steps, the first pass, which makes each new character's glyph once, beside)::

    python benchmarks/annotate_frames.py [WxH]

Session 6 on the 2-core box (llvmpipe, load ~1 from a test run beside it): step change 9.1–10.2
ms, unchanged frame 1.9–2.1 ms; the same loop over the code before (one overlay for title, bar
and legend, the triad drawn every frame) 43.3–45.8 and 8.0–9.4 ms. Session 7 (glyph-composed
numbers and titles, see benchmarks/RESULTS.md, section billion): step change ~2 ms, selection
change ~3–4 ms at 1024×768.
"""

from __future__ import annotations

import sys
import time

import numpy as np


def main(size="1024x768") -> dict:
    from geoshade.styles import annotate as ann_mod
    from geoshade.styles.palette import palette

    w, h = (int(v) for v in size.lower().split("x"))
    img = np.zeros((h, w, 4), np.uint8)
    bar = ann_mod.ColorBar("SWAT", 0.1, 0.9, palette("viridis"), unit="fraction")
    tri = ann_mod.triad_axes(np.eye(4))

    def ann(i):
        return ann_mod.Annotations(title="case.EGRID — SWAT",
                                   subtitle=f"step {i} of 37 · 2001-0{i % 9 + 1}-01",
                                   colorbar=bar, triad=tri)

    cache: dict = {}
    ann_mod.annotate(img, ann(0), cache)
    first, change, same = [], [], []
    for times in (first, change):   # the first pass makes each new character's glyph once
        for i in range(1, 10):
            t0 = time.perf_counter()
            ann_mod.annotate(img, ann(i), cache)
            times.append((time.perf_counter() - t0) * 1000)
    for _ in range(5):
        t0 = time.perf_counter()
        ann_mod.annotate(img, ann(9), cache)
        same.append((time.perf_counter() - t0) * 1000)

    def selection(i, shift=0):   # a core: a slider moves the upper grey value
        hi = 10632 - 397 * i - shift
        return ann_mod.Annotations(
            title=f"core.tif — values 1889..{hi} selected",
            subtitle=f"{4567969 - 100003 * i:,} voxels",
            colorbar=ann_mod.ColorBar("grey value", 1889.0, float(hi), palette("gray")),
            triad=tri)

    ann_mod.annotate(img, selection(0), cache)
    sel_first, sel = [], []
    for times, shift in ((sel_first, 0), (sel, 13)):  # new numbers on both passes
        for i in range(1, 10):
            t0 = time.perf_counter()
            ann_mod.annotate(img, selection(i, shift), cache)
            times.append((time.perf_counter() - t0) * 1000)
    res = {"size": [w, h], "step_change_ms": float(np.median(change)),
           "step_change_first_pass_ms": float(np.median(first)),
           "selection_change_ms": float(np.median(sel)),
           "selection_change_first_pass_ms": float(np.median(sel_first)),
           "unchanged_frame_ms": float(np.median(same))}
    print(f"{w}x{h}: step change {res['step_change_ms']:.1f} ms (first pass, glyphs made: "
          f"{res['step_change_first_pass_ms']:.1f} ms), selection change "
          f"{res['selection_change_ms']:.1f} ms (first pass "
          f"{res['selection_change_first_pass_ms']:.1f} ms), unchanged frame "
          f"{res['unchanged_frame_ms']:.1f} ms (medians)")
    return res


if __name__ == "__main__":
    main(*sys.argv[1:2])
