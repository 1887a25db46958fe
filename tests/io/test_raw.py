"""Headerless raw volumes: round trips, no copy, and one-line errors."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.volumes.raw import RAW_DTYPES, raw_dtype, raw_nbytes, read_raw


def _array(dtype, shape_zyx=(3, 4, 5)):
    rng = np.random.default_rng(0)
    info = np.iinfo(dtype) if np.issubdtype(dtype, np.integer) else None
    if info is None:
        return rng.normal(size=shape_zyx).astype(dtype)
    return rng.integers(info.min, info.max, size=shape_zyx, endpoint=True, dtype=dtype)


@pytest.mark.parametrize("name", list(RAW_DTYPES))
@pytest.mark.parametrize("endian", ["little", "big"])
def test_round_trip_all_dtypes(tmp_path, name, endian):
    a = _array(np.dtype(name))
    f = tmp_path / f"v_{name}_{endian}.raw"
    a.astype(np.dtype(name).newbyteorder("<" if endian == "little" else ">")).tofile(f)
    vol = read_raw(f, shape=(5, 4, 3), dtype=name, endian=endian)
    assert vol.data.shape == (3, 4, 5)
    assert vol.shape_xyz == (5, 4, 3)
    assert vol.dtype.name == name
    np.testing.assert_array_equal(np.asarray(vol.data), a)


def test_x_varies_fastest(tmp_path):
    f = tmp_path / "ramp.raw"
    np.arange(2 * 3 * 4, dtype=np.uint8).tofile(f)
    vol = read_raw(f, (4, 3, 2), "uint8")
    assert vol.data[0, 0, 1] == 1  # next x
    assert vol.data[0, 1, 0] == 4  # next y = NX values later
    assert vol.data[1, 0, 0] == 12  # next z = NX*NY values later


def test_short_dtype_names(tmp_path):
    a = _array(np.dtype("<i2"))
    f = tmp_path / "s.raw"
    a.tofile(f)
    for name in ("i2", "int16", np.int16, np.dtype("int16")):
        np.testing.assert_array_equal(read_raw(f, (5, 4, 3), name).data, a)
    assert raw_dtype("u2", "big").str == ">u2"
    assert raw_dtype("f4").str == "<f4"
    assert raw_nbytes((10, 10, 10), "uint16") == 2000


def test_no_copy_and_read_only(tmp_path):
    a = _array(np.dtype("uint16"))
    f = tmp_path / "v.raw"
    a.tofile(f)
    before = f.read_bytes()
    vol = read_raw(f, (5, 4, 3), "uint16")
    data = vol.data
    assert isinstance(data, np.memmap) or isinstance(data.base, np.memmap)
    assert not data.flags.writeable
    with pytest.raises(ValueError):
        data[0, 0, 0] = 1
    assert f.read_bytes() == before


def test_offset_spacing_unit_origin(tmp_path):
    a = _array(np.dtype("uint8"))
    f = tmp_path / "hdr.raw"
    f.write_bytes(b"H" * 16 + a.tobytes())
    vol = read_raw(f, (5, 4, 3), "u1", offset=16, spacing=(0.5, 0.5, 2), unit="um", origin=1)
    np.testing.assert_array_equal(vol.data, a)
    assert vol.spacing == (0.5, 0.5, 2.0)
    assert vol.unit == "um"
    assert vol.origin == (1.0, 1.0, 1.0)
    assert "assumed" not in vol.meta
    plain = read_raw(f, (5, 4, 3), "u1", offset=16)
    assert plain.spacing == (1.0, 1.0, 1.0)
    assert any("spacing" in s for s in plain.meta["assumed"])


def test_size_mismatch_suggests_cube(tmp_path):
    f = tmp_path / "cube.raw"
    np.zeros(110**3, np.uint8).tofile(f)
    with pytest.raises(InputError) as e:
        read_raw(f, (100, 100, 100), "uint8")
    msg = str(e.value)
    assert "cube.raw" in msg
    assert "1331000 bytes" in msg and "110×110×110 uint8" in msg
    assert "expects 1000000" in msg
    assert "\n" not in msg


def test_size_mismatch_suggests_nz(tmp_path):
    f = tmp_path / "slab.raw"
    np.zeros((7, 4, 5), np.uint16).tofile(f)
    with pytest.raises(InputError, match=r"slab\.raw.*5×4×7 uint16.*expects 400 bytes"):
        read_raw(f, (5, 4, 10), "uint16")


def test_size_mismatch_suggests_dtype(tmp_path):
    f = tmp_path / "bytes.raw"
    np.zeros((3, 4, 5), np.uint8).tofile(f)
    with pytest.raises(InputError, match=r"bytes\.raw.*60 bytes = 5×4×3 uint8.*expects 120"):
        read_raw(f, (5, 4, 3), "uint16")


def test_truncated(tmp_path):
    f = tmp_path / "cut.raw"
    np.zeros(5 * 4 * 3 - 7, np.uint8).tofile(f)
    with pytest.raises(InputError) as e:
        read_raw(f, (5, 4, 3), "uint8")
    msg = str(e.value)
    assert "cut.raw" in msg and "53 bytes" in msg and "expects 60 bytes" in msg
    assert "truncated" in msg


def test_offset_counted_in_size(tmp_path):
    f = tmp_path / "h.raw"
    np.zeros(60, np.uint8).tofile(f)
    with pytest.raises(InputError, match=r"h\.raw.*after the 4-byte offset.*expects 64 bytes"):
        read_raw(f, (5, 4, 3), "uint8", offset=4)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match=r"nope\.raw: no such file"):
        read_raw(tmp_path / "nope.raw", (1, 1, 1), "uint8")


@pytest.mark.parametrize(
    "shape", [(0, 4, 3), (5, -1, 3), (5, 4), (5, 4, 3, 1), ("a", 4, 3), (2.5, 4, 3)]
)
def test_bad_shape(tmp_path, shape):
    f = tmp_path / "v.raw"
    np.zeros(60, np.uint8).tofile(f)
    with pytest.raises(InputError) as e:
        read_raw(f, shape, "uint8")
    msg = str(e.value)
    assert "v.raw" in msg and "shape" in msg
    assert "NX NY NZ" in msg or "positive integer" in msg


def test_unknown_dtype_lists_accepted(tmp_path):
    f = tmp_path / "v.raw"
    np.zeros(60, np.uint8).tofile(f)
    with pytest.raises(InputError) as e:
        read_raw(f, (5, 4, 3), "complex64")
    msg = str(e.value)
    assert "v.raw" in msg and "complex64" in msg
    assert all(name in msg for name in RAW_DTYPES)


def test_bad_endian_and_offset(tmp_path):
    f = tmp_path / "v.raw"
    np.zeros(60, np.uint8).tofile(f)
    with pytest.raises(InputError, match=r"v\.raw: endian: expected 'little' or 'big'"):
        read_raw(f, (5, 4, 3), "uint8", endian="middle")
    with pytest.raises(InputError, match=r"v\.raw: offset: expected a byte count >= 0"):
        read_raw(f, (5, 4, 3), "uint8", offset=-2)
    with pytest.raises(InputError, match=r"v\.raw: spacing: expected 1 or 3 positive"):
        read_raw(f, (5, 4, 3), "uint8", spacing=(1, 0, 1))


def test_load_raw_needs_shape_and_dtype(tmp_path):
    for suffix in (".raw", ".bin", ".img", ".vol", ".dat"):
        f = tmp_path / f"v{suffix}"
        np.arange(60, dtype=np.uint8).tofile(f)
        with pytest.raises(InputError) as e:
            load(f)
        assert f.name in str(e.value) and "give --shape NX NY NZ and --dtype" in str(e.value)
        with pytest.raises(InputError, match="--shape NX NY NZ and --dtype"):
            load(f, shape=(5, 4, 3))
        vol = load(f, shape=(5, 4, 3), dtype="uint8", endian=None)
        np.testing.assert_array_equal(vol.data.ravel(), np.arange(60))
