"""The annotation overlay (no GL): colour bar gradient = the palette, decade ticks, sizes that
follow the picture, legends that wrap, only covered pixels change."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.styles.annotate import (
    Annotations,
    ColorBar,
    Legend,
    ScaleBar,
    annotate,
    font_px,
    nice_length,
    triad_axes,
)
from geoshade.styles.palette import palette


def _bar(**kw):
    return ColorBar(kw.pop("label", "PERMX"), kw.pop("lo", 0.01), kw.pop("hi", 1e4),
                    palette(kw.pop("cmap", "viridis")), **kw)


@pytest.mark.parametrize("size", [(1024, 768), (3840, 2160), (320, 240)])
@pytest.mark.parametrize("cmap", ["viridis", "magma", "gray"])
def test_the_bar_is_the_palette_sampled_along_it(size, cmap):
    w, h = size
    img, lay = annotate(np.full((h, w, 4), 255, np.uint8), Annotations(colorbar=_bar(cmap=cmap)))
    x0, top, bw, bh = lay["colorbar"]["bbox"]
    column = img[top + 2: top + bh - 2, x0 + bw // 2, :3]          # inside the outline
    rows = np.minimum((np.arange(bh)[::-1] + 0.5) / bh * 256, 255).astype(int)[2: bh - 2]
    np.testing.assert_array_equal(column, palette(cmap)[rows, :3])


def test_log_ticks_are_decades_and_linear_ticks_are_round():
    _, lay = annotate(np.full((768, 1024, 4), 255, np.uint8),
                      Annotations(colorbar=_bar(lo=0.003, hi=1e4, log=True, auto=True)))
    cb = lay["colorbar"]
    values = [t["value"] for t in cb["ticks"]]
    assert values == [10.0 ** e for e in range(-2, 5)]
    assert [t["text"] for t in cb["ticks"]] == ["0.01", "0.1", "1", "10", "100", "1000", "10000"]
    ys = [t["y"] for t in cb["ticks"]]
    assert ys == sorted(ys, reverse=True)                  # higher values higher up
    steps = np.diff(ys)
    assert np.ptp(steps) <= 1                              # equal spacing per decade
    assert cb["scale"] == "log scale (auto)" and cb["label"] == "PERMX"
    _, lay = annotate(np.full((768, 1024, 4), 255, np.uint8),
                      Annotations(colorbar=_bar(label="PORO", lo=0.05, hi=0.35, unit="fraction")))
    texts = [t["text"] for t in lay["colorbar"]["ticks"]]
    assert texts[:3] == ["0.05", "0.1", "0.15"] and lay["colorbar"]["label"] == "PORO [fraction]"


def test_text_follows_the_picture_size():
    assert font_px(768) == 14 and font_px(2160) == 39 and font_px(100) == 11
    for w, h in ((1024, 768), (3840, 2160)):
        _, lay = annotate(np.full((h, w, 4), 255, np.uint8), Annotations("title", "2001-01-01"))
        assert lay["font_px"] >= 0.018 * h - 0.5
        assert [t["text"] for t in lay["title"]] == ["title", "2001-01-01"]


def test_a_long_legend_wraps_into_columns():
    entries = tuple((f"{i} unit {i}", (i * 7 % 255, 90, 200, 255)) for i in range(60))
    _, lay = annotate(np.full((768, 1024, 4), 255, np.uint8),
                      Annotations(legend=Legend("strat", entries)))
    leg = lay["legend"]
    assert leg["columns"] >= 2 and len(leg["entries"]) == 60
    assert max(e["y"] for e in leg["entries"]) < 0.85 * 768      # fits the picture's height
    assert leg["bbox"][0] >= 0


def test_only_covered_pixels_change_and_transparency_is_kept():
    rng = np.random.default_rng(0)
    img = rng.integers(0, 255, (240, 320, 4)).astype(np.uint8)
    img[..., 3] = 0                                   # a transparent background
    img[100:140, 100:200, 3] = 255
    ann = Annotations("a title", "sub", _bar(), None, triad_axes(np.eye(4)), ScaleBar(2.0, "m"))
    out, _ = annotate(img, ann)
    over, _ = annotate(np.zeros_like(img), ann)
    free = over[..., 3] == 0
    assert free.mean() > 0.6
    np.testing.assert_array_equal(out[free], img[free])
    assert (out[~free, 3] > 0).all()                  # text readable on transparency too


def test_scale_bar_is_a_round_length():
    _, lay = annotate(np.full((768, 1024, 4), 255, np.uint8),
                      Annotations(scalebar=ScaleBar(3.7, "m")))
    sb = lay["scalebar"]
    assert sb["value"] == nice_length(0.2 * 1024 * 3.7) == 500.0
    assert sb["text"] == "500 m" and abs(sb["length_px"] - 500 / 3.7) < 0.01


def test_triad_directions_follow_the_camera():
    from geoshade.render.camera import Camera

    top = Camera.framed([[0, 0, 0], [1, 1, 1]], "top", ortho=True)
    labels = {a[0]: a[1] for a in triad_axes(top.view_matrix()).axes}
    assert np.allclose(labels["E"], (1, 0)) and np.allclose(labels["N"], (0, 1))
    assert np.allclose(labels["Up"], (0, 0), atol=1e-9)      # towards the viewer


def test_a_constant_property_has_one_tick_not_five_equal_ones():
    import numpy as np

    from geoshade.styles.annotate import Annotations, ColorBar, annotate
    from geoshade.styles.palette import colormap

    pal = (np.asarray(colormap("viridis")(np.linspace(0, 1, 256))) * 255).astype(np.uint8)
    ann = Annotations("t", "", colorbar=ColorBar("PORO", 0.3 - 1e-7, 0.3 + 1e-7, pal))
    _, lay = annotate(np.zeros((480, 640, 4), np.uint8), ann)
    ticks = lay["colorbar"]["ticks"]
    assert [t["text"] for t in ticks] == ["0.3"] and lay["colorbar"]["scale"] == "one value"
    _, lay = annotate(np.zeros((480, 640, 4), np.uint8),
                      Annotations("t", "", colorbar=ColorBar("PORO", 0.1, 0.3, pal)))
    texts = [t["text"] for t in lay["colorbar"]["ticks"]]
    assert len(texts) > 2 and len(set(texts)) == len(texts) and lay["colorbar"]["scale"] == ""


def test_long_title_lines_end_in_an_ellipsis_inside_the_picture():
    """A title or subtitle line wider than the picture is shortened to what fits, ending in
    "…", and nothing is drawn in the right margin of the title rows (E2: a DEM's note was cut
    at the edge)."""
    import numpy as np

    from geoshade.styles.annotate import Annotations, annotate, font_px

    w, h = 320, 240
    img = np.zeros((h, w, 4), np.uint8)
    long = "reprojected from EPSG:4326 to UTM zone 14N (EPSG:32614) " * 3
    out, layout = annotate(img, Annotations(title="jacksboro_dem_4326.tif — elevation",
                                            subtitle=f"vertical exaggeration ×3\n{long}"))
    sub = layout["title"][1]["text"].split("\n")
    assert sub[0] == "vertical exaggeration ×3" and sub[1].endswith("…")
    assert long.startswith(sub[1][:-1].rstrip())
    margin = round(0.8 * font_px(h))
    rows = slice(0, layout["title"][1]["y"] + 3 * font_px(h))
    assert not out[rows, w - margin // 2:, 3].any()


def test_a_step_change_redraws_only_the_title_strip(monkeypatch):
    """With a cache (a viewer's frames): a new subtitle (step, date) redraws the title strip
    only — the colour bar and the camera layer are reused — and the picture equals the one
    drawn without a cache, pixel for pixel (issue 26: bookkeeping never waits)."""
    import geoshade.styles.annotate as ann_mod

    rng = np.random.default_rng(1)
    img = rng.integers(0, 255, (300, 400, 4), dtype=np.uint8)
    bar = ann_mod.ColorBar("SWAT", 0.1, 0.9, palette("viridis"), unit="fraction")
    tri = ann_mod.triad_axes(np.eye(4))
    calls = {"keys": 0, "camera": 0}
    real_static, real_camera = ann_mod._static_overlay, ann_mod._camera_overlay

    def static(*a):
        calls["keys"] += 1
        return real_static(*a)

    def camera(*a):
        calls["camera"] += 1
        return real_camera(*a)

    monkeypatch.setattr(ann_mod, "_static_overlay", static)
    monkeypatch.setattr(ann_mod, "_camera_overlay", camera)
    cache: dict = {}
    for step in range(4):
        sub = f"step {step} of 37 · 2001-0{step + 1}-01"
        ann = ann_mod.Annotations(title="case — SWAT", subtitle=sub, colorbar=bar, triad=tri)
        out, layout = ann_mod.annotate(img, ann, cache)
        fresh, fresh_layout = ann_mod.annotate(img, ann)
        np.testing.assert_array_equal(out, fresh)
        assert layout == fresh_layout
        assert layout["title"][1]["text"].startswith(f"step {step} of 37")
    assert calls == {"keys": 1 + 4, "camera": 1 + 4}   # once cached, + once per fresh call
    np.testing.assert_array_equal(img[110:200, 120:280], out[110:200, 120:280])   # the middle


def test_a_new_range_redraws_ticks_and_title_from_cached_glyphs_as_a_fresh_picture():
    """A selection slider moves: the colour bar's range, its ticks and the title's numbers
    change every frame. With the View's cache (glyphs and words kept, the bar's frame kept)
    the picture equals one drawn from nothing, pixel for pixel, and the ticks are the
    locator's round values at the right rows."""
    from matplotlib.ticker import MaxNLocator

    img = np.zeros((768, 1024, 4), np.uint8)
    cache: dict = {}

    def ann(hi):
        return Annotations(f"core.tif — values 1889..{hi} selected", f"{hi * 431:,} voxels",
                           ColorBar("grey value", 1889.0, float(hi), palette("gray")))

    annotate(img, ann(10632), cache)
    for hi in (9000, 7321, 20000, 10632):
        cached, lay = annotate(img, ann(hi), cache)
        fresh, lay2 = annotate(img, ann(hi))
        np.testing.assert_array_equal(cached, fresh)
        assert lay == lay2
        cb = lay["colorbar"]
        want = [v for v in MaxNLocator(nbins=6).tick_values(1889.0, hi) if 1889 <= v <= hi]
        assert [t["value"] for t in cb["ticks"]] == want and (cb["lo"], cb["hi"]) == (1889, hi)
        x0, top, _, bh = cb["bbox"]
        for t in cb["ticks"]:
            assert t["y"] == round(top + bh * (1 - (t["value"] - 1889.0) / (hi - 1889.0)))
            assert fresh[t["y"], x0 - 3, 3] == 255      # the tick mark, left of the bar
            # its number, right-aligned before the mark: ink in the row band left of it
            assert fresh[t["y"] - 5:t["y"] + 6, x0 - 60:x0 - 8, 3].any()
        assert lay["title"][0]["text"] == f"core.tif — values 1889..{hi} selected"


def test_glyph_text_is_laid_out_as_matplotlib_lays_it_out():
    """The glyph font's advances are FreeType's (as matplotlib's): a line is as wide as
    matplotlib measures it (within hinting's few per cent), and each glyph is matplotlib's own
    rendering of that character."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from geoshade.styles.glyphs import GlyphFont

    text = "4,567,969 voxels — values 1889..10632 selected"
    font = GlyphFont(9.0, halo=0)
    fig = Figure(figsize=(6, 1), dpi=100)
    canvas = FigureCanvasAgg(fig)
    art = fig.text(0.01, 0.5, text, fontsize=9.0)
    canvas.draw()
    ref = art.get_window_extent(canvas.get_renderer()).width
    assert abs(font.width(text) - ref) <= 0.03 * ref
    out = np.zeros((30, 400, 4), np.uint8)
    box = font.draw(out, text, 5, 20)
    assert abs(box[2] - ref) <= 0.04 * ref and out[..., 3].any()
    # a character the font lacks is not drawn from glyphs (the title falls back to matplotlib)
    assert font.has("values 1889") and not font.has("井 A-1")
    _, lay = annotate(np.zeros((240, 320, 4), np.uint8), Annotations("井 A-1", "2001-01-01"))
    assert [t["text"] for t in lay["title"]] == ["井 A-1", "2001-01-01"]
