"""Synthetic volumes, palettes, light."""

from __future__ import annotations

import time

import numpy as np
import pytest

from geoshade.compute.voxels.synthetic import random_labels, synthetic_core
from geoshade.errors import InputError
from geoshade.styles import Light, Material, palette, random_palette


@pytest.mark.parametrize("target", [0.1, 0.2, 0.35])
def test_synthetic_core_porosity_and_determinism(target):
    vol = synthetic_core(48, porosity=target, seed=3)
    assert vol.shape_xyz == (48, 48, 48) and vol.dtype == np.uint16
    assert vol.unit == "um" and vol.spacing == (2.5, 2.5, 2.5)
    assert abs(vol.meta["porosity"] - target) < 0.01
    lo, hi = vol.meta["pore_range"]
    measured = ((vol.data >= lo) & (vol.data <= hi)).mean()
    assert abs(measured - target) < 0.03
    again = synthetic_core(48, porosity=target, seed=3)
    np.testing.assert_array_equal(vol.data, again.data)
    assert not np.array_equal(vol.data, synthetic_core(48, porosity=target, seed=4).data)


def test_synthetic_core_histogram_and_dtypes():
    vol = synthetic_core(32, porosity=0.3, seed=1)
    d = vol.data
    assert 6000 < np.median(d[d < vol.meta["threshold"]]) < 14000  # pore peak (blurred edges)
    assert np.median(d[d > vol.meta["threshold"]]) == pytest.approx(30000, rel=0.1)
    assert len(np.unique(d)) > 1000  # noisy, like CT
    v8 = synthetic_core(shape=(20, 16, 12), dtype="uint8")
    assert v8.data.shape == (12, 16, 20) and v8.dtype == np.uint8
    assert 100 < float(v8.data.mean()) < 200
    with pytest.raises(InputError, match="porosity"):
        synthetic_core(8, porosity=1.5)
    with pytest.raises(InputError, match="dtype"):
        synthetic_core(8, dtype="uint32")


def test_synthetic_core_is_fast():
    synthetic_core(16)
    t = time.perf_counter()
    synthetic_core(128, porosity=0.2)
    assert time.perf_counter() - t < 2.0  # < 1 s on a normal machine; slack for noisy CI


def test_random_labels():
    vol = random_labels((30, 20, 10), 0.3, seed=1)
    d = vol.data
    assert d.dtype == np.uint8 and d.shape == (10, 20, 30)
    sel = (d >= 100) & (d <= 200)
    assert sel.sum() == 1800
    assert d[~sel].max() <= 99 and d.max() <= 200
    assert len(np.unique(d[sel])) > 90 and len(np.unique(d[~sel])) == 100
    np.testing.assert_array_equal(d, random_labels((30, 20, 10), 0.3, seed=1).data)
    with pytest.raises(InputError, match="fraction"):
        random_labels((2, 2, 2), -0.1)


def test_palette():
    p = palette()
    assert p.shape == (256, 4) and p.dtype == np.uint8 and p.flags.c_contiguous
    import matplotlib

    np.testing.assert_array_equal(p, matplotlib.colormaps["viridis"](np.arange(256), bytes=True))
    g = palette("gray")
    assert g[0].tolist() == [0, 0, 0, 255] and g[255].tolist() == [255, 255, 255, 255]
    banded = palette("magma", n=5)
    assert len(np.unique(banded, axis=0)) == 5
    np.testing.assert_array_equal(banded[0], palette("magma")[0])
    with pytest.raises(InputError, match=r"unknown colour map 'nope'.*viridis"):
        palette("nope")
    with pytest.raises(InputError, match=r"1\.\.256"):
        palette("gray", n=0)


def test_random_palette_distinct():
    p = random_palette(2)
    assert p.shape == (256, 4) and p.dtype == np.uint8
    assert len(np.unique(p[:, :3], axis=0)) == 256
    diff = np.abs(p[:, None, :3].astype(int) - p[None, :, :3].astype(int)).max(axis=2)
    assert diff[~np.eye(256, dtype=bool)].min() >= 36
    np.testing.assert_array_equal(p, random_palette(2))
    assert not np.array_equal(p, random_palette(3))


def test_light_and_material():
    light = Light()
    assert np.linalg.norm(light.direction) == pytest.approx(1.0)
    np.testing.assert_allclose(
        light.direction, np.array([0.4, 0.6, 1.0]) / np.linalg.norm([0.4, 0.6, 1.0])
    )
    u = light.to_uniforms()
    assert set(u) == {"light_dir", "light_color"}
    m = Material()
    assert m.to_uniforms() == {"ambient": 0.25, "diffuse": 0.75, "specular": 0.2, "shininess": 32.0}
    with pytest.raises(InputError, match="non-zero"):
        Light((0, 0, 0))
    with pytest.raises(InputError, match="shininess"):
        Material(shininess=-1)
