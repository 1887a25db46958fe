"""Acceptance: real tomography: a segmented rock, a sample in air, a cube cut inside a sample.

- Berea sandstone, segmented (../shared/data/microct_dpm_berea, MIT): 0 = pore (17.8 %), and the
  same image with the pore label 255 (make_cases.inverted_berea), as many segmentations ship;
- concrete cylinder in air, 16-bit X-ray (spam's wheel, GPL-3.0, make_cases.concrete_in_air):
  the sample ends inside the volume (the first and last slices are air) and fills a disc that
  touches the volume's sides;
- snow, 16-bit, a cube cut from inside a sample: no air (../shared/data/microct_spam_snow).

Oracles: numpy (counts), scipy.ndimage + scikit-image (Otsu, the sample's footprint per slice).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from tests.acceptance import make_cases
from tests.acceptance.conftest import title_text, view_screenshot

BEREA_SHAPE = ("--shape", "110", "110", "110", "--dtype", "uint8")
BEREA_PORE = 0.178


@pytest.fixture(scope="module")
def berea(shared):
    raw = shared / "microct_dpm_berea" / "berea_pore.raw"
    return raw, np.fromfile(raw, np.uint8).reshape(110, 110, 110)


@pytest.fixture
def berea255(shared, tmp_path):
    raw = make_cases.inverted_berea(tmp_path)
    return raw, np.fromfile(raw, np.uint8).reshape(110, 110, 110)


def _porosity(cli, tmp_path, *args) -> tuple[int, dict | None, str, str]:
    js = tmp_path / "p.json"
    rc, out, err = cli("core", "porosity", *args, "-o", tmp_path / "p.png", "--json", js)
    return rc, (json.loads(js.read_text()) if rc == 0 else None), out, err


def test_segmented_rock_porosity_is_the_pore_fraction(cli, tmp_path, berea):
    raw, a = berea
    rc, d, _, err = _porosity(cli, tmp_path, raw, *BEREA_SHAPE, "--select", "0", "0")
    assert rc == 0, err
    assert d["porosity"] == (a == 0).mean()
    assert round(d["porosity"], 3) == BEREA_PORE
    np.testing.assert_array_equal(d["profile"], (a == 0).mean(axis=(1, 2)))


def test_pore_label_255_is_never_read_as_dark_pores(cli, tmp_path, berea255):
    """A two-value label image: ``--select auto`` cannot know which value is pore. It gives
    the pore fraction 0.178 or refuses in one line listing the values, never 0.822."""
    raw, a = berea255
    rc, d, _out, err = _porosity(cli, tmp_path, raw, *BEREA_SHAPE, "--select", "auto")
    if rc == 0:
        assert round(d["porosity"], 3) == BEREA_PORE, d["porosity"]
    else:
        line = err.strip()
        assert "\n" not in line and "Traceback" not in line, err
        assert re.search(r"\b0\b", line) and "255" in line, line
        assert re.search(r"82\.2|0\.822", line) and re.search(r"17\.8|0\.178", line), line
    rc, d, _, err = _porosity(cli, tmp_path, raw, *BEREA_SHAPE, "--select", "255", "255")
    assert rc == 0, err
    assert d["porosity"] == (a == 255).mean()


def test_info_does_not_call_the_grain_label_pore_space(cli, berea255):
    raw, _ = berea255
    rc, out, err = cli("info", raw, *BEREA_SHAPE)
    assert rc == 0, err
    assert not re.search(r"pore space: --select 0 0", out), out


@pytest.mark.gl
def test_segmented_rock_render_counts_equal_numpy(cli, berea):
    raw, a = berea
    st = cli.render("berea_pores", "core", "render", raw, *BEREA_SHAPE, "--select", "0", "0",
                    "--size", "480x360", "--frames", "1")
    assert st["voxels_selected"] == int((a == 0).sum())


@pytest.mark.gl
def test_core_picture_says_its_exaggeration(cli, berea):
    raw, _ = berea
    st = cli.render("berea_exaggeration2", "core", "render", raw, *BEREA_SHAPE, "--select",
                    "0", "0", "--exaggeration", "2", "--size", "480x360", "--frames", "1")
    assert re.search(r"exaggerat\w*\D{0,6}2|[×x]\s?2\b", title_text(st)), title_text(st)


def _sample_oracles(a: np.ndarray, t: float, lo: float, hi: float) -> tuple[float, float]:
    """Pore fraction inside the sample, two ways: the filled footprint of each slice (tight),
    and the footprint over the slices that hold the sample (loose: partial-volume rims)."""
    from scipy import ndimage as ndi

    sel = (a >= lo) & (a <= hi)
    per_slice = np.array([ndi.binary_fill_holes(s > t) for s in a])
    tight = sel[per_slice].mean()
    area = per_slice.mean(axis=(1, 2))
    holds = area > 0.5 * area.max()
    union = ndi.binary_fill_holes(per_slice[holds].any(axis=0))
    loose = sel[holds][:, union].mean()
    return float(tight), float(loose)


def test_sample_in_air_counts_the_pores_inside_the_sample(cli, tmp_path, concrete):
    import tifffile

    a = tifffile.imread(concrete)
    rc, d, out, err = _porosity(cli, tmp_path, concrete, "--select", "auto")
    assert rc == 0, err
    lo, hi = d["select"]
    naive = float(((a >= lo) & (a <= hi)).mean())
    tight, loose = _sample_oracles(a, d["sample"]["threshold"] if d.get("sample") else lo,
                                   lo, hi)
    assert tight - 0.005 <= d["porosity"] <= loose + 0.005, (d["porosity"], tight, loose)
    assert d["porosity"] < 0.25 * naive
    assert "sample" in out  # says what was counted
    # the warning: the share of the selection that is air, with its number
    assert d["outside_fraction"] is not None and d["outside_fraction"] > 0.5
    assert d["warning"] and re.search(r"\d+(\.\d)? ?%", d["warning"]), d["warning"]
    assert "\n" not in err.strip() or err.count("warning") <= 1


def test_info_of_the_sample_in_air(cli, concrete):
    import tifffile
    from skimage.filters import threshold_otsu

    a = tifffile.imread(concrete)
    rc, out, err = cli("info", concrete)
    assert rc == 0, err
    assert "100 × 100 × 100" in out and "uint16" in out
    assert f"min {a.min()}, max {a.max()}" in out, out
    otsu = re.search(r"Otsu ([\d,]+)", out)
    assert otsu, out
    value = int(otsu.group(1).replace(",", ""))
    assert value == int(threshold_otsu(a)) or re.search(r"sample|air", out), out


def test_cylinder_roi_counts_exactly_the_voxels_inside_it(cli, tmp_path, concrete):
    import tifffile

    a = tifffile.imread(concrete)
    rc, d, out, err = _porosity(cli, tmp_path, concrete, "--select", "auto", "--roi", "cylinder")
    assert rc == 0, err
    roi = d["roi"]
    y, x = np.mgrid[0:100, 0:100] + 0.5  # voxel centres
    inside = (x - roi["cx"]) ** 2 + (y - roi["cy"]) ** 2 <= roi["r"] ** 2
    lo, hi = d["select"]
    sel = (a >= lo) & (a <= hi)
    assert d["total"] == inside.sum() * a.shape[0]
    assert d["count"] == sel[:, inside].sum()
    # the fit reaches the volume's sides: the output says so
    if roi["cx"] - roi["r"] < 1 or roi["cy"] - roi["r"] < 1 or roi["cx"] + roi["r"] > 99:
        assert re.search(r"edge|side|border", out + err + roi.get("note", "")), out + err


def test_cube_inside_a_sample_keeps_every_voxel(cli, tmp_path, shared):
    """Snow cut from inside its sample: no air, so ``--roi cylinder`` keeps the whole volume."""
    import tifffile

    tif = shared / "microct_spam_snow" / "snow.tif"
    a = tifffile.imread(tif)
    rc, d, _out, err = _porosity(cli, tmp_path, tif, "--select", "0", "20000", "--roi",
                                "cylinder")
    assert rc == 0, err
    assert d["total"] == a.size
    assert d["porosity"] == ((a >= 0) & (a <= 20000)).mean()


@pytest.mark.gl
def test_sample_in_air_picture_says_what_was_counted(cli, concrete):
    st = cli.render("concrete_auto", "core", "render", concrete, "--select", "auto",
                    "--size", "640x480", "--frames", "1")
    title = title_text(st)
    assert re.search(r"sample|air", title, re.IGNORECASE), title
    assert re.search(r"Otsu|threshold|dark|≤", title), title


@pytest.mark.gl
def test_render_and_porosity_count_the_same_voxels(cli, tmp_path, concrete):
    """One selection, two paths: the picture draws the voxels the porosity counts (not the air
    around the sample)."""
    rc, d, _, err = _porosity(cli, tmp_path, concrete, "--select", "auto")
    assert rc == 0, err
    st = cli.render("concrete_auto_count", "core", "render", concrete, "--select", "auto",
                    "--size", "320x240", "--frames", "1")
    assert st["voxels_selected"] == d["count"], (st["voxels_selected"], d["count"])


def test_big_endian_tomogram_everywhere(concrete, tmp_path):
    """The same tomogram written big-endian: load, to_pyvista, to_xarray give the values."""
    import tifffile

    import geoshade

    a = tifffile.imread(concrete)
    be = tmp_path / "concrete_be.tif"
    tifffile.imwrite(be, a, byteorder=">")
    vol = geoshade.load(be)
    np.testing.assert_array_equal(np.asarray(vol.data).reshape(a.shape[::-1], order="F")
                                  if np.asarray(vol.data).shape != a.shape
                                  else np.asarray(vol.data), a)
    pytest.importorskip("pyvista")
    ds = geoshade.to_pyvista(vol)
    values = np.asarray(ds.point_data[ds.point_data.keys()[0]] if ds.point_data.keys()
                        else ds.cell_data[ds.cell_data.keys()[0]])
    assert sorted(np.unique(values).tolist())[:3] == sorted(np.unique(a).tolist())[:3]
    assert values.size == a.size and int(values.astype(np.int64).sum()) == int(
        a.astype(np.int64).sum())
    xr = geoshade.to_xarray(vol)
    assert int(np.asarray(xr).astype(np.int64).sum()) == int(a.astype(np.int64).sum())
    from geoshade.napari._reader import read_layers

    (layer,) = read_layers(str(be))
    data = layer[0][0] if isinstance(layer[0], list) else layer[0]
    data = np.asarray(data)
    assert data.dtype.isnative and int(data.astype(np.int64).sum()) == int(
        a.astype(np.int64).sum())


@pytest.mark.gl
def test_viewer_screenshots(pictures, concrete, berea):
    img = view_screenshot(pictures, "concrete_view", concrete, "--select", "auto")
    assert (np.abs(img[..., :3].astype(int) - 255).sum(-1) > 30).mean() > 0.05
    raw, _ = berea
    img = view_screenshot(pictures, "berea_view", raw, *BEREA_SHAPE, "--select", "0", "0")
    assert (np.abs(img[..., :3].astype(int) - 255).sum(-1) > 30).mean() > 0.05
