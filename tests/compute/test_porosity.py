"""Porosity, its profiles, its files and plot; on random data and the real micro-CT scans."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
import tifffile

from geoshade.compute.voxels.porosity import csv_text, porosity
from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.errors import InputError
from geoshade.io.output import write_json, write_text
from geoshade.models import Box, VoxelVolume

_SUM_AXES = {"x": (0, 1), "y": (0, 2), "z": (1, 2)}


def _check_exact(a, lo, hi, box=None, slab_bytes=64 * 2**20):
    full = np.asarray(a.data if isinstance(a, VoxelVolume) else a)
    b = Box.from_list(box) if box is not None else Box((0, 0, 0), full.shape[::-1])
    block = full[b.slices()]
    sel = (block >= lo) & (block <= hi)
    for axis in "xyz":
        r = porosity(a, lo, hi, box=box, axis=axis, slab_bytes=slab_bytes)
        assert r.porosity == sel.mean()  # exact, not approximate
        assert r.count == int(sel.sum()) and r.total == sel.size
        np.testing.assert_array_equal(r.profile, sel.mean(axis=_SUM_AXES[axis]))
        p = "xyz".index(axis)
        np.testing.assert_array_equal(r.positions, np.arange(b.offset[p], b.offset[p] + b.size[p]))
        assert r.axis == axis
    return r


@pytest.mark.parametrize("dtype", ["uint8", "uint16", "float32"])
def test_porosity_equals_numpy_random(dtype):
    rng = np.random.default_rng(3)
    a = (rng.random((23, 17, 29)) * 250).astype(dtype)
    _check_exact(a, 100, 200)
    _check_exact(a, 0, 249, box=[2, 3, 4, 20, 10, 17])
    _check_exact(a, 125, 125.5, box=[0, 0, 5, 29, 17, 18], slab_bytes=1)  # one slice a slab


def test_porosity_streams_slabs_and_reports_progress():
    vol = synthetic_core(32, porosity=0.25, seed=5)
    calls = []
    r = porosity(vol, *vol.meta["pore_range"], slab_bytes=1, progress=lambda d, t: calls.append(d))
    assert calls == list(range(1, 33))
    assert abs(r.porosity - 0.25) < 0.03
    assert r.unit == "um" and r.spacing == 2.5
    np.testing.assert_allclose(r.coordinates()[:2], [1.25, 3.75])


def test_porosity_bad_input():
    a = np.zeros((4, 4, 4), np.uint16)
    with pytest.raises(InputError, match=r"^range: lo 200 > hi 100; expected LO <= HI$"):
        porosity(a, 200, 100)
    with pytest.raises(InputError, match=r"^range: 70000 outside uint16 \[0, 65535\]$"):
        porosity(a, 0, 70000)
    with pytest.raises(InputError, match="axis: expected one of x, y, z, got 'w'"):
        porosity(a, 0, 1, axis="w")
    with pytest.raises(InputError, match="outside the volume"):
        porosity(a, 0, 1, box=[1, 1, 1, 4, 1, 1])


def test_csv_json_and_plot_files(tmp_path):
    vol = synthetic_core(24, porosity=0.3, seed=7)
    r = porosity(vol, *vol.meta["pore_range"], box=[2, 2, 2, 20, 18, 16], axis="y")
    csv_path = write_text(tmp_path / "poro.csv", csv_text(r))
    rows = list(csv.DictReader(csv_path.open()))
    assert list(rows[0]) == ["y", "y_um", "count", "voxels", "porosity"]
    assert [int(row["y"]) for row in rows] == r.positions.tolist()
    assert [float(row["porosity"]) for row in rows] == r.profile.tolist()  # full precision
    assert sum(int(row["count"]) for row in rows) == r.count

    js = json.loads(write_json(tmp_path / "poro.json", r.to_dict()).read_text())
    for key in ("porosity", "profile", "axis", "positions", "range", "box"):
        assert key in js
    assert js["porosity"] == r.porosity and js["profile"] == r.profile.tolist()
    assert js["axis"] == "y" and js["box"] == [2, 2, 2, 20, 18, 16]
    assert js["range"] == list(vol.meta["pore_range"])

    from matplotlib.image import imread

    from geoshade.core.plots import porosity_plot

    png = porosity_plot(r, tmp_path / "poro.png", title="test")
    img = imread(png)
    assert img.shape[0] > 100 and img.shape[1] > 100
    assert sorted(p.name for p in tmp_path.iterdir()) == ["poro.csv", "poro.json", "poro.png"]
    with pytest.raises(InputError, match="does not exist"):
        write_json(tmp_path / "missing" / "x.json", r.to_dict())
    with pytest.raises(InputError, match="does not exist"):
        porosity_plot(r, tmp_path / "missing" / "x.png")


def test_plot_does_not_touch_pyplot_backend():
    import sys

    import matplotlib

    before = matplotlib.get_backend() if "matplotlib.pyplot" in sys.modules else None
    import geoshade.core.plots  # noqa: F401

    if before is not None:
        assert matplotlib.get_backend() == before


@pytest.mark.data
def test_berea_porosity_real(shared_data):
    path = shared_data / "microct_dpm_berea" / "berea_pore.raw"
    a = np.fromfile(path, dtype=np.uint8).reshape(110, 110, 110)
    r = _check_exact(a, 0, 0)
    assert abs(r.porosity - 0.178) < 0.002
    grain = porosity(a, 1, 255)
    assert grain.count + r.count == a.size
    _check_exact(a, 0, 0, box=[10, 20, 30, 64, 50, 70], slab_bytes=4096)


@pytest.mark.data
def test_snow_16bit_range_real(shared_data):
    a = tifffile.imread(shared_data / "microct_spam_snow" / "snow.tif")
    assert a.dtype == np.uint16 and a.ndim == 3
    r = _check_exact(a, 6237, 20000)
    assert 0.0 < r.porosity < 1.0
    _check_exact(a, 6237, 20000, box=[5, 6, 7, 80, 70, 60], slab_bytes=9000)
