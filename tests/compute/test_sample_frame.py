"""The air detector fires only on a frame around a sample, and says what it measured either way;
label images get their labels, never values that are 0 % of them.  Oracles: synthetic volumes
whose sample, air and labels are known voxel by voxel (numpy), scikit-image's Otsu."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade import core
from geoshade.compute.voxels.sample import (
    CONVEX,
    RING_AIR,
    FrameMeasure,
    border_ring,
    detect_sample,
)
from geoshade.compute.voxels.threshold import thresholds, value_histogram
from geoshade.core.values import box_values, core_colours
from geoshade.errors import InputError
from geoshade.models import VoxelVolume
from geoshade.styles.options import ColorStyle

filters = pytest.importorskip("skimage.filters")
ndi = pytest.importorskip("scipy.ndimage")


def porous_filler(n=64, solid=0.2, seed=0, dtype="uint8"):
    """A porous material that fills the box: smoothed noise thresholded into solid (bright)
    and pores (dark) everywhere, touching every side."""
    rng = np.random.default_rng(seed)
    field = ndi.gaussian_filter(rng.normal(size=(n, n, n)), 2.5)
    t = np.quantile(field, 1 - solid)
    a = np.where(field > t, 200, 40) + rng.integers(0, 20, (n, n, n))
    return VoxelVolume(a.astype(dtype), name="filler"), field > t


@pytest.mark.parametrize("solid", [0.1, 0.2, 0.5])
def test_a_porous_material_that_fills_the_box_has_no_air(solid):
    vol, _solid_mask = porous_filler(solid=solid, seed=int(solid * 10))
    a = np.asarray(vol.data)
    s = detect_sample(vol)
    assert s.status == "no air" and s.roi is None
    assert s.measured is not None and not s.measured.is_frame()
    assert "no air around the sample" in s.text() and s.measured.why_not() in s.text()
    res = core.porosity(vol, "auto")
    t = float(filters.threshold_otsu(a))
    assert res.porosity == np.count_nonzero(a <= t) / a.size   # every voxel counts
    assert res.warning is None and res.sample["measured"]["frame"] == "dark"


def _in_frame(fill: int, n=48, r=16.0):
    """A porous cylinder (solid 200, pores 40) inside a frame of value ``fill``."""
    vol, _ = porous_filler(n=n, solid=0.6, seed=3)
    a = np.asarray(vol.data).copy()
    y, x = np.mgrid[0:n, 0:n] + 0.5
    disc = (x - n / 2) ** 2 + (y - n / 2) ** 2 <= r * r
    a[:, ~disc] = fill
    return VoxelVolume(a, name="framed"), disc


def test_a_sample_in_air_is_found_with_its_numbers():
    vol, disc = _in_frame(fill=35)
    s = detect_sample(vol)
    assert s.status == "in air" and s.frame == "dark"
    foot = s.roi.footprint   # the disc, less a porous rim a voxel wide where it is weak
    assert not (foot & ~disc).any() and foot.sum() >= 0.97 * disc.sum()
    m = s.measured
    assert m.ring_air == 1.0 and m.convexity >= CONVEX and m.footprint == disc.mean()
    d = s.to_dict()
    assert d["frame"] == "dark" and d["measured"]["limits"]["ring_air"] == RING_AIR
    assert "border ring 100.0 % air" in s.text()


def test_a_bright_fill_frame_is_found():
    """A reconstruction filled outside its circle with the brightest value: the frame is not
    sample (it would count as solid), found from the other side of Otsu's threshold."""
    vol, disc = _in_frame(fill=255)
    s = detect_sample(vol)
    assert s.status == "in air" and s.frame == "bright"
    assert s.measured.fill > 0.99   # a few noisy sample voxels
    inside = s.roi.inside(slice(0, 48), slice(0, 48), slice(0, 48))[0]
    assert (inside == disc).mean() > 0.99
    assert "bright frame" in s.text()
    res = core.porosity(vol, (0, 100))
    a = np.asarray(vol.data)
    want = np.count_nonzero((a <= 100) & inside) / (inside.sum() * a.shape[0])
    assert res.porosity == want and res.total == inside.sum() * a.shape[0]


def test_frame_measure_says_every_test_it_fails():
    m = FrameMeasure("dark", 0.62, 0.493, 0.894, 4)
    assert not m.is_frame()
    assert m.why_not() == ("border ring 49.3 % air (a frame needs 50%), solid 89.4 % convex "
                           "(a sample needs 95%)")
    assert FrameMeasure("dark", 0.4, 1.0, 0.99, 2).is_frame()
    assert not FrameMeasure("bright", 0.4, 1.0, 0.99, 2, fill=0.5).is_frame()
    assert FrameMeasure("bright", 0.4, 1.0, 0.99, 2, fill=0.95).is_frame()
    ring = border_ring((50, 100))
    assert ring[:2].all() and not ring[2, 2:98].any() and ring.sum() == 2 * 2 * 100 + 2 * 2 * 46


def test_label_image_thresholds_name_labels_present():
    """Labels 0, 128, 255: Otsu of the histogram falls between labels (a value that is 0 % of
    the image); it is named by the label at or below, the same split."""
    rng = np.random.default_rng(2)
    a = rng.choice(np.array([0, 128, 255], np.uint8), size=(10, 20, 20), p=[0.2, 0.3, 0.5])
    t = thresholds(value_histogram(a))
    raw = float(filters.threshold_otsu(a))
    present = {0.0, 128.0, 255.0}
    assert t.otsu in present and all(v in present for v in t.multiotsu)
    assert (a <= t.otsu).sum() == (a <= raw).sum()   # the same classes
    u, c = np.unique(a, return_counts=True)
    assert t.labels == [(float(v), int(n)) for v, n in zip(u, c, strict=True)]
    assert t.to_dict()["label_select"] == [[v, v] for v in t.label_choices()]


def test_every_label_is_offered_but_none_that_reads_zero():
    """The 94.4 % label is offered (was cut after the three rarest); a label of a few voxels
    that reads 0.0 % is listed with its share but not offered."""
    n = 100_000
    a = np.concatenate([np.full(2, 5), np.full(3, 7), np.full(5590, 2), np.full(n - 5595, 1)])
    vol = VoxelVolume(a.astype(np.uint8).reshape(10, 100, 100), name="seg")
    t = core.thresholds(vol)
    assert t.label_choices() == [2.0, 1.0]
    with pytest.raises(InputError) as e:
        core.porosity(vol, "auto")
    msg = str(e.value)
    assert "1: 94.4 %" in msg and "--select 1 1" in msg and "--select 2 2" in msg
    assert "--select 5 5" not in msg and "--select 7 7" not in msg and "5: 0.0 %" in msg


def test_a_label_that_is_most_of_the_image_is_a_selected_fraction():
    a = np.ones((10, 20, 20), np.uint8)
    a[:, :4] = 0           # 20 %: the lowest label, a minority: pores by convention
    a[:, 4:9] = 2
    vol = VoxelVolume(a, name="seg")
    assert core.porosity(vol, (0, 0)).quantity == "porosity"
    assert core.porosity(vol, (1, 1)).quantity == "selected fraction"   # a solid phase
    assert core.porosity(vol, (0, 1)).quantity == "selected fraction"   # two labels
    inv = VoxelVolume(np.where(a == 0, 9, 0).astype(np.uint8), name="inv")  # 0: 80 %
    r = core.porosity(inv, (0, 0))
    assert r.quantity == "selected fraction" and r.to_dict()["label_image"] is True
    assert core.porosity_line(r).startswith("selected fraction 0.8000")


def test_box_values_and_the_colours_of_a_box():
    g = VoxelVolume((np.arange(24, dtype=np.uint16) * 1000 + 6237).reshape(2, 3, 4))
    b = box_values(g)
    assert (b.vmin, b.vmax, b.codes) == (6237.0, 29237.0, None) and not b.labels
    c = core_colours(g, (0, 65535), g.full_box(), ColorStyle())
    assert c.source == "data" and c.style.range == (6237.0, 29237.0)
    # a selection asked for is kept; a range asked for too
    assert core_colours(g, (0, 20000), g.full_box(), ColorStyle()).source == "selection"
    kept = core_colours(g, (0, 65535), g.full_box(), ColorStyle(range=(0.0, 100.0)))
    assert kept.source == "style" and kept.style.range == (0.0, 100.0)
    # a box: its own values
    sub = box_values(g, [0, 0, 1, 4, 3, 1])
    assert sub.vmin == 18237.0
    labels = VoxelVolume(np.array([[[3, 9, 3, 7]]], np.uint8))
    c = core_colours(labels, (0, 255), labels.full_box(), ColorStyle())
    assert c.source == "labels" and c.counts == {3.0: 2, 7.0: 1, 9.0: 1}
    assert [e["rgba"] for e in c.to_dict()["labels"]] == [
        list(c.categories.rgba_of(v)) for v in (3, 7, 9)]
    off = core_colours(labels, (0, 255), labels.full_box(), ColorStyle(categorical=False))
    assert off.categories is None and off.style.range == (3.0, 9.0)
    floats = VoxelVolume(np.array([[[0.5, 1.0, 1.5]]], np.float32))
    forced = core_colours(floats, (0, 2), floats.full_box(), ColorStyle(categorical=True))
    assert forced.categories is None and "categorical" in forced.note
