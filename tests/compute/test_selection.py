"""Ranges and selection masks."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.voxels.selection import check_range, iter_z_slabs, select, slab_depth
from geoshade.errors import InputError
from geoshade.models import Box, VoxelVolume


def test_check_range_messages():
    assert check_range(100, 200, np.uint16) == (100.0, 200.0)
    with pytest.raises(InputError, match=r"^range: lo 200 > hi 100; expected LO <= HI$"):
        check_range(200, 100, np.uint16)
    with pytest.raises(InputError, match=r"^range: 70000 outside uint16 \[0, 65535\]$"):
        check_range(0, 70000, "uint16")
    with pytest.raises(InputError, match=r"^range: -1 outside uint8 \[0, 255\]$"):
        check_range(-1, 3, "uint8")
    with pytest.raises(InputError, match=r"^range: lo is NaN"):
        check_range(float("nan"), 3, "uint8")
    with pytest.raises(InputError, match=r"^range: hi is NaN"):
        check_range(0, np.nan, "float32")
    with pytest.raises(InputError, match=r"^pore range: hi 'x' is not a number"):
        check_range(0, "x", None, name="pore range")
    # floats may be unbounded; a message is one line
    assert check_range(-np.inf, np.inf, "float32") == (-np.inf, np.inf)
    with pytest.raises(InputError) as err:
        check_range(5, 1, "int16")
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("dtype", ["uint8", "uint16", "int16", "int32", "float32", "float64"])
def test_select_equals_numpy(dtype):
    rng = np.random.default_rng(1)
    a = rng.integers(-100 if dtype[0] != "u" else 0, 250, (7, 9, 11)).astype(dtype)
    for lo, hi in [(0, 0), (10, 120), (3.5, 99.5), (0, 249), (120.2, 120.7)]:
        if np.dtype(dtype).kind == "u" and lo < 0:
            continue
        expect = (a >= lo) & (a <= hi)
        got = select(a, lo, hi)
        assert got.dtype == bool and got.shape == a.shape
        np.testing.assert_array_equal(got, expect)


def test_select_full_dtype_range_and_nan():
    a = np.array([0, 1, 254, 255], np.uint8)
    assert select(a, 0, 255).all()
    np.testing.assert_array_equal(select(a, 0, 1), [True, True, False, False])
    np.testing.assert_array_equal(select(a, 254, 255), [False, False, True, True])
    f = np.array([np.nan, -1.0, 0.0, 2.0], np.float32)
    np.testing.assert_array_equal(select(f, -np.inf, np.inf), [False, True, True, True])
    np.testing.assert_array_equal(select(f, -1, 0), [False, True, True, False])
    with pytest.raises(InputError, match="outside uint8"):
        select(a, 0, 256)


def test_slab_depth_and_iteration_cover_the_box():
    vol = VoxelVolume(np.arange(20 * 6 * 5, dtype=np.uint16).reshape(20, 6, 5))
    box = Box((1, 2, 3), (3, 4, 15))
    assert slab_depth(box.size, 2, 8, slab_bytes=1) == 8
    assert slab_depth((100, 100, 100), 2, 8, slab_bytes=64 * 2**20) % 8 == 0
    seen = []
    calls = []
    for z, slab in iter_z_slabs(vol.data, box, 8, 1, lambda d, t: calls.append((d, t))):
        seen.append((z, slab.shape))
    assert seen == [(0, (8, 4, 3)), (8, (7, 4, 3))]
    assert calls == [(8, 15), (15, 15)]
    whole = np.concatenate([s for _, s in iter_z_slabs(vol.data, box, 8, 1)])
    np.testing.assert_array_equal(whole, vol.read_box(box))
