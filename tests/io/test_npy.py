"""NumPy .npy/.npz volumes."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import load, read_npy


def test_npy_round_trip_memmapped(tmp_path):
    a = np.random.default_rng(1).integers(0, 60000, size=(3, 4, 5), dtype=np.uint16)
    f = tmp_path / "v.npy"
    np.save(f, a)
    vol = read_npy(f)
    assert vol.shape_xyz == (5, 4, 3)
    assert isinstance(vol.data, np.memmap) or isinstance(vol.data.base, np.memmap)
    np.testing.assert_array_equal(vol.data, a)
    assert vol.meta["format"] == "npy"
    assert any("spacing" in s for s in vol.meta["assumed"])
    np.testing.assert_array_equal(load(f).data, a)


def test_npy_bool_viewed_as_uint8(tmp_path):
    a = np.random.default_rng(2).random((3, 4, 5)) > 0.5
    f = tmp_path / "mask.npy"
    np.save(f, a)
    vol = read_npy(f)
    assert vol.dtype == np.uint8
    np.testing.assert_array_equal(vol.data, a.astype(np.uint8))


@pytest.mark.parametrize("key", ["data", "volume"])
def test_npz_named_key(tmp_path, key):
    a = np.arange(60, dtype=np.float32).reshape(3, 4, 5)
    f = tmp_path / "v.npz"
    np.savez(f, **{key: a, "other": np.zeros(3)})
    vol = read_npy(f)
    np.testing.assert_array_equal(vol.data, a)
    assert vol.meta["key"] == key


def test_npz_single_array(tmp_path):
    a = np.arange(60, dtype=np.int16).reshape(3, 4, 5)
    f = tmp_path / "one.npz"
    np.savez_compressed(f, whatever=a)
    np.testing.assert_array_equal(load(f).data, a)


def test_npz_ambiguous(tmp_path):
    f = tmp_path / "two.npz"
    np.savez(f, a=np.zeros((2, 2, 2)), b=np.ones((2, 2, 2)))
    with pytest.raises(InputError) as e:
        read_npy(f)
    msg = str(e.value)
    assert "two.npz" in msg and "'data'" in msg and "'volume'" in msg and "'a'" in msg


def test_4d_npy_is_a_field_over_time(tmp_path):
    """(time, z, y, x) can only be a field: load() gives a FieldSeries, not an error."""
    from geoshade.models import FieldSeries

    f = tmp_path / "steps.npy"
    np.save(f, np.zeros((2, 3, 4, 5), np.float32))
    fs = read_npy(f)
    assert isinstance(fs, FieldSeries) and fs.nsteps == 2 and fs.shape == (3, 4, 5)


@pytest.mark.parametrize("shape", [(4, 5), (2, 3, 4, 5, 6)])
def test_not_3d(tmp_path, shape):
    f = tmp_path / "bad.npy"
    np.save(f, np.zeros(shape, np.uint8))
    with pytest.raises(InputError) as e:
        read_npy(f)
    msg = str(e.value)
    assert "bad.npy" in msg and f"{len(shape)} dimensions" in msg and "expected a 3D array" in msg
    g = tmp_path / "bad.npz"
    np.savez(g, data=np.zeros(shape, np.uint8))
    with pytest.raises(InputError, match=r"bad\.npz: array 'data' has .* expected a 3D array"):
        read_npy(g)


def test_unsupported_dtype_names_file(tmp_path):
    f = tmp_path / "c.npy"
    np.save(f, np.zeros((2, 2, 2), np.complex64))
    with pytest.raises(InputError, match=r"c\.npy.*complex64 is not supported; expected one of"):
        read_npy(f)


def test_garbage_and_missing(tmp_path):
    f = tmp_path / "junk.npy"
    f.write_bytes(b"not a numpy file at all")
    with pytest.raises(InputError, match=r"junk\.npy: not a readable \.npy array"):
        read_npy(f)
    with pytest.raises(InputError, match=r"gone\.npy: no such file"):
        read_npy(tmp_path / "gone.npy")
