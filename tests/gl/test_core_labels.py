"""A label image in the core View: classes with a legend (as the grid draws region codes), the
colour range over the data, and the air detection said on the picture.  Oracles: numpy (label
counts, the values present), the categorical palette (each label's colour)."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.core import CoreView
from geoshade.models import VoxelVolume
from geoshade.styles.categories import categorical_palette
from geoshade.styles.options import ColorStyle

pytestmark = pytest.mark.gl

SIZE = (320, 240)


def labels_volume(n=24):
    """Three labels in slabs along x: 0 (a third), 1 (half), 2 (the rest)."""
    a = np.zeros((n, n, n), np.uint8)
    a[:, :, n // 3:] = 1
    a[:, :, n // 3 + n // 2:] = 2
    return VoxelVolume(a, name="labels.raw")


def _hue_pixels(img, rgba) -> int:
    """Pixels of the model's part of the picture (its middle: no triad, title or legend) in
    the hue of ``rgba``, any shade."""
    h, w = img.shape[:2]
    rgb = img[h // 5:h - h // 5, w // 5:w - w // 5, :3].astype(float)
    want = np.asarray(rgba[:3], float)
    norm = np.linalg.norm(rgb, axis=-1, keepdims=True)
    cos = (rgb / np.maximum(norm, 1e-9)) @ (want / np.linalg.norm(want))
    return int(((cos > 0.999) & (norm[..., 0] > 20)).sum())


def test_a_label_image_is_drawn_as_classes(ctx):
    vol = labels_volume()
    a = np.asarray(vol.data)
    pal = categorical_palette([0, 1, 2])
    with CoreView(vol, ctx=ctx, size=SIZE, annotations=True) as view:
        img, st = view.draw(frames=1)
    assert st["label_image"] and st["categories"] == [0.0, 1.0, 2.0]
    assert st["color_range"] == [0.0, 2.0] and st["colours"]["source"] == "labels"
    legend = st["annotations"]["legend"]
    assert [e["text"] for e in legend["entries"]] == [
        f"{v}  {100 * (a == v).mean():.1f} %" for v in (0, 1, 2)]
    assert [e["rgba"] for e in legend["entries"]] == [list(pal.rgba_of(v)) for v in (0, 1, 2)]
    assert st["annotations"].get("colorbar") is None
    for v in (0, 1, 2):
        assert _hue_pixels(img, pal.rgba_of(v)) > 50, v


def test_the_legend_follows_the_selection_and_colours_stay(ctx):
    vol = labels_volume()
    pal = categorical_palette([0, 1, 2])
    with CoreView(vol, ctx=ctx, size=SIZE, annotations=True) as view:
        view.update(select=(1, 2))
        img, st = view.draw(frames=1)
        assert st["categories"] == [1.0, 2.0]
        entries = st["annotations"]["legend"]["entries"]
        assert [e["rgba"] for e in entries] == [list(pal.rgba_of(v)) for v in (1, 2)]
        assert _hue_pixels(img, pal.rgba_of(0)) == 0   # label 0 is not selected
        view.update(color=ColorStyle(categorical=False))   # a colour bar, over the data
        _, st = view.draw(frames=1)
        assert not st["label_image"] and st["annotations"]["colorbar"] is not None


def test_the_default_colour_range_spans_the_data(ctx):
    a = (np.arange(16 ** 3, dtype=np.uint16).reshape(16, 16, 16) % 900) * 37 + 6237
    vol = VoxelVolume(a, name="grey.raw")
    with CoreView(vol, ctx=ctx, size=SIZE, annotations=True) as view:
        _, st = view.draw(frames=1)
        assert st["color_range"] == [float(a.min()), float(a.max())]
        assert st["colours"]["source"] == "data"
        bar = st["annotations"]["colorbar"]
        assert (bar["lo"], bar["hi"]) == (float(a.min()), float(a.max()))
        view.update(select=(10000, 20000))   # a selection asked for: its range
        _, st = view.draw(frames=1)
        assert st["color_range"] == [10000.0, 20000.0]
        assert st["colours"]["source"] == "selection"
        view.update(select=(0, 65535))        # back to everything: the data again
        _, st = view.draw(frames=1)
        assert st["color_range"] == [float(a.min()), float(a.max())]


def test_the_picture_says_the_air_detection_either_way(ctx):
    from tests.compute.test_sample import sample_in_air

    vol, _, _ = sample_in_air()
    with CoreView(vol, ctx=ctx, size=(640, 480), select=(0, 20000),
                  annotations=True) as view:
        _, st = view.draw(frames=1)
    assert st["sample"]["status"] == "in air" and st["sample"]["measured"]["ring_air"] == 1.0
    sub = "\n".join(t["text"] for t in st["annotations"]["title"])
    assert "border ring 100.0 % air" in sub
    cut = VoxelVolume(np.asarray(vol.data)[:, 18:42, 20:46].copy(), name="cut")
    with CoreView(cut, ctx=ctx, size=(640, 480), select=(0, 20000),
                  annotations=True) as view:
        _, st = view.draw(frames=1)
    assert st["sample"]["status"] == "no air"
    sub = "\n".join(t["text"] for t in st["annotations"]["title"])
    assert "no air around the sample" in sub


def test_render_and_viewer_options_agree_on_a_label_image(ctx):
    """The API's one-shot render and a View give the same picture (the colours are resolved
    the same way on every path, prepared or not)."""
    vol = labels_volume()
    img, st = geoshade.core.render(vol, size=SIZE, frames=1, ctx=ctx)
    model, prepared = CoreView.prepare_open(vol, size=SIZE)
    with CoreView(model, ctx=ctx, prepared=prepared, size=SIZE) as view:
        img2, st2 = view.draw(frames=1)
    assert np.array_equal(img, img2) and st["color_range"] == st2["color_range"] == [0.0, 2.0]
