"""VoxelVolume and Box contracts."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.models.volume import Box, VoxelVolume


def test_volume_contract_and_bounds():
    v = VoxelVolume(np.zeros((4, 5, 6), np.uint16), spacing=(2, 3, 4), origin=(1, 1, 1))
    assert v.shape_xyz == (6, 5, 4)
    np.testing.assert_array_equal(v.bounds(), [[1, 1, 1], [13, 16, 17]])
    np.testing.assert_array_equal(v.bounds([1, 1, 1, 2, 2, 2]), [[3, 4, 5], [7, 10, 13]])
    assert v.value_limits() == (0.0, 65535.0)


@pytest.mark.parametrize(
    ("kwargs", "msg"),
    [
        ({"data": np.zeros((4, 5))}, "expected 3 dimensions"),
        ({"data": np.zeros((4, 5, 0))}, ">= 1"),
        ({"data": np.zeros((2, 2, 2), complex)}, "not supported"),
        ({"data": np.zeros((2, 2, 2)), "spacing": (1, 0, 1)}, "positive"),
        ({"data": np.zeros((2, 2, 2)), "origin": (1, np.nan, 1)}, "finite"),
        ({"data": [1, 2, 3]}, "expected an array"),
    ],
)
def test_volume_rejects_bad_arrays(kwargs, msg):
    with pytest.raises(InputError, match=msg):
        VoxelVolume(**kwargs, name="v.raw")


@pytest.mark.parametrize(
    ("box", "msg"),
    [
        ([0, 0, 0, 0, 1, 1], "empty"),
        ([-1, 0, 0, 2, 2, 2], "outside"),
        ([5, 0, 0, 2, 2, 2], "outside"),
        ([0, 0], "6 integers"),
    ],
)
def test_box_checks(box, msg):
    v = VoxelVolume(np.zeros((4, 5, 6), np.uint8), name="v.raw")
    with pytest.raises(InputError, match=msg):
        v.resolve_box(box)


def test_box_slices_are_zyx():
    b = Box((1, 2, 3), (4, 5, 6))
    assert b.slices() == (slice(3, 9), slice(2, 7), slice(1, 5))
    assert b.nvoxels == 120 and b.stop == (5, 7, 9)
