"""Acceptance: porous materials that fill the box, their 3-label segmentation, a print resolution.

Real cases (tests/data/real/puma_porous_materials, NASA PuMA's example data, NOSA 1.3):

- FiberForm, a carbon fibre preform, X-ray micro-CT 100³ uint8: no air anywhere (its pores
  reach every side), porosity 0.846 with Otsu's threshold; its only resolution is a print
  resolution (100 pixels/inch);
- a woven composite, 150³ uint8, no air, porosity 0.300; and its segmentation, a label image
  0 (void, 30.1 %), 1 (49.2 %), 2 (20.7 %).

And the other side of the air detector: spam's concrete cylinder in air (a true positive) and the
snow cube (uint16 6237..40103, shared data) for the colour range over the data.

Oracles: numpy (fractions, label counts), scikit-image (threshold_otsu, threshold_multiotsu),
tifffile (the tags as stored).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import geoshade
from tests.acceptance.conftest import annotations, legend_entries, title_text, view_screenshot

CASE = "puma_porous_materials"
filters = pytest.importorskip("skimage.filters")
tifffile = pytest.importorskip("tifffile")


@pytest.fixture(scope="module")
def materials(real):
    folder = real / CASE
    if not folder.is_dir():
        pytest.skip(f"{folder} is absent")
    return {name: folder / f"{name}.tif"
            for name in ("100_fiberform", "small_weave", "small_weave_tag")}


def _drawn(img: np.ndarray, rgba) -> int:
    """Pixels of ``img`` in the hue of ``rgba`` (any shade: the light scales the colour)."""
    rgb = img[..., :3].astype(float)
    want = np.asarray(rgba[:3], float)
    norm = np.linalg.norm(rgb, axis=-1, keepdims=True)
    cos = (rgb / np.maximum(norm, 1e-9)) @ (want / np.linalg.norm(want))
    return int(((cos > 0.999) & (norm[..., 0] > 20)).sum())


def _porosity(cli, tmp_path, *args) -> tuple[int, dict | None, str, str]:
    js = tmp_path / "p.json"
    rc, out, err = cli("core", "porosity", *args, "-o", tmp_path / "p.png", "--json", js)
    return rc, (json.loads(js.read_text()) if rc == 0 else None), out, err


@pytest.mark.parametrize("name, want", [("100_fiberform", 0.846046),
                                        ("small_weave", 0.300457)])
def test_a_material_that_fills_the_box_has_no_air(cli, tmp_path, materials, name, want):
    """Every dark voxel is a pore: porosity is numpy's over every voxel, and the detector says
    what it measured (the border ring is not a frame of air)."""
    a = tifffile.imread(materials[name])
    t = float(filters.threshold_otsu(a))
    rc, d, out, err = _porosity(cli, tmp_path, materials[name], "--select", "auto")
    assert rc == 0, err
    assert d["select"] == [float(a.min()), t]
    assert d["porosity"] == float((a <= t).mean()) and round(d["porosity"], 6) == want
    assert d["total"] == a.size and d["outside"] is None and d["warning"] is None
    smp = d["sample"]
    assert smp["status"] == "no air" and smp["frame"] is None
    m = smp["measured"]
    assert m["ring_air"] < m["limits"]["ring_air"] or m["convexity"] < m["limits"]["convexity"]
    assert "no air around the sample" in out and "border ring" in smp["text"]
    assert d["quantity"] == "porosity"


def test_the_concrete_in_air_is_still_found(concrete):
    """The true positive: a frame of air around a convex sample, and the numbers say so."""
    found = geoshade.core.detect_sample(geoshade.load(concrete))
    assert found.status == "in air" and found.frame == "dark"
    m = found.measured
    assert m.ring_air > 0.9 and m.convexity > 0.95 and 0.6 < m.footprint < 0.8
    assert "border ring" in found.text() and "air" in found.text()


@pytest.mark.gl
def test_render_draws_the_whole_cube_of_pores(cli, materials):
    """``core render --select auto`` on FiberForm: the pore voxels of the whole box (was a
    10×10 sliver), and the picture says there is no air."""
    a = tifffile.imread(materials["100_fiberform"])
    t = float(filters.threshold_otsu(a))
    st = cli.render("fiberform_auto", "core", "render", materials["100_fiberform"], "--select",
                    "auto", "--size", "640x480", "--frames", "1")
    assert st["voxels_selected"] == int((a <= t).sum())
    assert st["box"] == [0, 0, 0, 100, 100, 100] and "roi" not in st
    assert st["sample"]["status"] == "no air"
    assert "no air around the sample" in title_text(st)


def test_a_print_resolution_is_not_a_voxel_size(cli, materials):
    f = materials["100_fiberform"]
    with tifffile.TiffFile(f) as tf:   # what the file holds: 100 pixels per inch
        tags = tf.pages[0].tags
        assert tags["XResolution"].value[0] / tags["XResolution"].value[1] == 100
        assert tf.imagej_metadata["unit"] == "inch"
    vol = geoshade.load(f)
    assert vol.spacing == (1.0, 1.0, 1.0) and vol.unit == ""
    assert vol.meta["print_resolution"] == "100 pixels/inch"
    assert any(a.startswith("spacing 1.0 (the file's 100 pixels/inch is a print resolution")
               for a in vol.meta["assumed"])
    assert any(a.startswith("unit voxel") for a in vol.meta["assumed"])
    rc, out, err = cli("info", f)
    assert rc == 0, err
    assert "print resolution" in out and "0.01" not in out.split("values")[0], out
    given = geoshade.load(f, spacing=1.3, unit="um")   # the user says what it is
    assert given.spacing == (1.3, 1.3, 1.3) and given.unit == "um"
    assert not any("spacing" in a or "unit" in a for a in given.meta.get("assumed", []))


@pytest.mark.gl
def test_unknown_length_unit_is_assumed_in_stats_and_picks(materials):
    vol = geoshade.load(materials["100_fiberform"])
    with geoshade.view(vol, select=(0, 108), size=(320, 240), view="top", ortho=True,
                       annotations=True) as v:
        _, st = v.draw(frames=1)
        pick = v.pick(160, 120)
    assert st["length_unit"] == "voxels (assumed)" and st["length_unit_assumed"] is True
    assert pick is not None and pick.length_unit == "voxels (assumed)"
    assert "voxels (assumed)" in pick.text()
    bar = annotations(st).get("scalebar") or {}
    assert "voxels (assumed)" in bar.get("text", ""), bar


def test_label_image_suggestions_name_the_labels(cli, tmp_path, materials):
    """Otsu on a label image names labels present, never a value that is 0 % of the image;
    every label is offered, the 49.2 % one included; ``--select auto`` asks which is pore."""
    f = materials["small_weave_tag"]
    a = tifffile.imread(f)
    u, c = np.unique(a, return_counts=True)
    t = geoshade.core.thresholds(geoshade.load(f))
    assert t.labels == [(float(v), int(n)) for v, n in zip(u, c, strict=True)]
    present = set(u.tolist())
    assert t.otsu in present and all(v in present for v in t.multiotsu)
    assert t.otsu == float(filters.threshold_otsu(a))   # 0: already a label
    assert sorted(t.label_choices()) == [0.0, 1.0, 2.0]
    rc, _d, _, err = _porosity(cli, tmp_path, f, "--select", "auto")
    assert rc != 0 and "\n" not in err.strip()
    for v, n in zip(u, c, strict=True):
        assert f"--select {v} {v}" in err and f"{v}: {100 * n / a.size:.1f} %" in err, err
    rc, out, err = cli("info", f)
    assert rc == 0, err
    line = next(x for x in out.splitlines() if x.strip().startswith("labels"))
    assert all(f"--select {v} {v}" in line for v in u), line
    assert "Otsu" not in out


def test_a_solid_label_is_never_titled_porosity(cli, tmp_path, materials):
    f = materials["small_weave_tag"]
    a = tifffile.imread(f)
    rc, d, out, err = _porosity(cli, tmp_path, f, "--select", "1", "1")
    assert rc == 0, err
    assert d["porosity"] == float((a == 1).mean()) and d["quantity"] == "selected fraction"
    assert d["label_image"] is True and out.startswith("selected fraction ")
    rc, d, out, err = _porosity(cli, tmp_path, f, "--select", "0", "0")
    assert rc == 0, err
    assert d["porosity"] == float((a == 0).mean()) and d["quantity"] == "porosity"


@pytest.mark.gl
def test_label_image_drawn_as_classes_with_a_legend(cli, materials):
    f = materials["small_weave_tag"]
    a = tifffile.imread(f)
    st = cli.render("weave_labels", "core", "render", f, "--size", "640x480", "--frames", "1")
    assert st["label_image"] is True and st["categories"] == [0.0, 1.0, 2.0]
    assert st["colours"]["source"] == "labels" and st["color_range"] == [0.0, 2.0]
    ann = annotations(st)
    assert ann.get("colorbar") is None, ann.get("colorbar")
    texts = legend_entries(st)
    want = [f"{v}  {100 * (a == v).mean():.1f} %" for v in (0, 1, 2)]
    assert texts == want, texts
    assert ann["legend"]["title"] == "label"
    for lab in st["colours"]["labels"]:
        assert lab["voxels"] == int((a == lab["value"]).sum())
    # each label's colour is drawn (the cube's faces show every phase, shaded)
    from PIL import Image

    img = np.asarray(Image.open(cli.pictures / "weave_labels.png").convert("RGB"))
    for entry in ann["legend"]["entries"]:
        assert _drawn(img, entry["rgba"]) > 1000, entry
    assert re.search(r"labels 0, 1, 2 selected", title_text(st)), title_text(st)


@pytest.mark.gl
def test_categorical_false_keeps_a_colour_bar(materials):
    vol = geoshade.load(materials["small_weave_tag"])
    _img, st = geoshade.core.render(vol, size=(320, 240), frames=1, annotations=True,
                                   color=geoshade.styles.options.ColorStyle(categorical=False))
    assert st["label_image"] is False and "categories" not in st
    assert annotations(st).get("colorbar") is not None
    assert st["color_range"] == [0.0, 2.0] and st["colours"]["source"] == "data"


@pytest.mark.gl
def test_colour_range_spans_the_data_not_the_dtype(shared):
    tif = shared / "microct_spam_snow" / "snow.tif"
    a = tifffile.imread(tif)
    assert a.dtype == np.uint16 and (int(a.min()), int(a.max())) == (6237, 40103)
    _img, st = geoshade.core.render(geoshade.load(tif), size=(320, 240), frames=1,
                                   annotations=True)
    assert st["color_range"] == [6237.0, 40103.0] and st["colours"]["source"] == "data"
    bar = annotations(st)["colorbar"]
    assert bar["lo"] == 6237.0 and bar["hi"] == 40103.0


@pytest.mark.gl
def test_the_viewer_draws_the_label_image_as_classes(cli, pictures, materials):
    f = materials["small_weave_tag"]
    st = cli.render("weave_labels_480", "core", "render", f, "--size", "480x360",
                    "--frames", "1")
    shot = view_screenshot(pictures, "weave_labels_view", f)
    for lab in st["colours"]["labels"]:   # the window draws each label in its legend colour
        assert _drawn(shot, lab["rgba"]) > 1000, lab
