"""Bit maps, patch and brick maps, colour index map, slab streaming and GPU byte counts."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import zarr

from geoshade.compute.voxels.bitmaps import (
    brick_occupancy,
    brick_occupancy_from_bits,
    build_selection_maps,
    color_index,
    gpu_bytes_breakdown,
    gpu_bytes_estimate,
    pack_bits,
    patch_bitmap,
    patch_grid,
    unpack_bits,
)
from geoshade.compute.voxels.skipmap import skip_map
from geoshade.compute.voxels.synthetic import random_labels, synthetic_core
from geoshade.errors import InputError
from geoshade.models import Box, VoxelVolume


@pytest.mark.parametrize("shape", [(5, 7, 33), (1, 1, 1), (3, 2, 32), (2, 3, 64), (4, 4, 100)])
def test_pack_unpack_round_trip(shape):
    sel = np.random.default_rng(sum(shape)).random(shape) < 0.4
    words = pack_bits(sel)
    nz, ny, nx = shape
    assert words.dtype == np.uint32 and words.shape == (nz, ny, math.ceil(nx / 32))
    np.testing.assert_array_equal(unpack_bits(words, nx), sel)
    # bit x % 32 of word x // 32 is voxel x
    z, y, x = (np.asarray(i) for i in np.nonzero(np.ones(shape, bool)))
    bit = (words[z, y, x // 32] >> (x % 32).astype(np.uint32)) & 1
    np.testing.assert_array_equal(bit.astype(bool), sel[z, y, x])
    # padding bits are zero
    if nx % 32:
        assert not (words[..., -1] >> np.uint32(nx % 32)).any()


def test_patch_grid():
    assert patch_grid(65, 65, 3) == (1, 1, 3)
    assert patch_grid(66, 130, 2) == (2, 2, 2)
    assert patch_grid(131, 1, 1) == (3, 1, 1)
    assert patch_grid(10, 10, 10, l=2) == (4, 4, 10)
    with pytest.raises(InputError):
        patch_grid(10, 10, 10, l=0)


@pytest.mark.parametrize("l", [2, 4, 64])
def test_patch_bitmap_vs_brute_force(l):
    rng = np.random.default_rng(l)
    sel = rng.random((3, 17, 23)) < 0.01
    sel[1, 16, 22] = True
    got = patch_bitmap(sel, l)
    n_p, m_p, q_p = patch_grid(23, 17, 3, l)
    assert got.shape == (q_p, m_p, n_p) and got.dtype == bool
    L = l + 1
    for k, i, j in itertools.product(range(q_p), range(m_p), range(n_p)):
        assert got[k, i, j] == sel[k, i * L : (i + 1) * L, j * L : (j + 1) * L].any()
    packed = pack_bits(got)
    np.testing.assert_array_equal(unpack_bits(packed, n_p), got)


@pytest.mark.parametrize("brick", [1, 3, 8])
def test_brick_occupancy_vs_brute_force(brick):
    rng = np.random.default_rng(brick)
    sel = rng.random((13, 9, 20)) < 0.02
    got = brick_occupancy(sel, brick)
    shape = tuple(math.ceil(n / brick) for n in sel.shape)
    assert got.shape == shape and got.dtype == np.uint8
    for k, i, j in itertools.product(*(range(n) for n in shape)):
        b = brick
        expect = sel[k * b : (k + 1) * b, i * b : (i + 1) * b, j * b : (j + 1) * b].any()
        assert got[k, i, j] == int(expect)
    if 32 % brick == 0:
        np.testing.assert_array_equal(brick_occupancy_from_bits(pack_bits(sel), 20, brick), got)


@pytest.mark.parametrize("brick", [1, 2, 4, 8, 16, 32])
@pytest.mark.parametrize("nx", [1, 31, 33, 70])
def test_brick_occupancy_from_bits_equals_mask_version(brick, nx):
    sel = np.random.default_rng(nx + brick).random((11, 10, nx)) < 0.01
    np.testing.assert_array_equal(
        brick_occupancy_from_bits(pack_bits(sel), nx, brick), brick_occupancy(sel, brick)
    )


@pytest.mark.parametrize("dtype", ["uint8", "uint16", "int8", "int16", "int32", "float32"])
def test_color_index_endpoints_and_formula(dtype):
    info = np.iinfo(dtype) if np.dtype(dtype).kind in "iu" else None
    lo, hi = (-20, 100) if (info is None or info.min < 0) else (10, 100)
    v = np.arange(lo - 5, hi + 6).astype(dtype)
    got = color_index(v, lo, hi)
    assert got.dtype == np.uint8
    assert got[v == lo][0] == 0 and got[v == hi][0] == 255
    assert (got[v < lo] == 0).all() and (got[v > hi] == 255).all()
    expect = np.clip(np.rint((v.astype(np.float64) - lo) / (hi - lo) * 255), 0, 255)
    np.testing.assert_array_equal(got, expect.astype(np.uint8))
    assert (color_index(v, 50, 50) == 0).all()


def test_color_index_nan_and_bad_range():
    got = color_index(np.array([np.nan, 0.0, 1.0]), 0.0, 1.0)
    assert got.tolist() == [0, 0, 255]
    with pytest.raises(InputError, match=r"colour range: lo 2 > hi 1"):
        color_index(np.zeros(3), 2, 1)
    with pytest.raises(InputError, match="finite"):
        color_index(np.zeros(3), 0, np.inf)


def _one_shot(a, box, lo, hi, clo, chi, l, brick):
    block = a[box.slices()]
    sel = (block >= lo) & (block <= hi)
    return sel, color_index(block, clo, chi), patch_bitmap(sel, l), brick_occupancy(sel, brick)


@pytest.mark.parametrize("brick", [8, 4, 3])
def test_build_selection_maps_slabs_equal_one_shot(brick):
    vol = synthetic_core(shape=(40, 30, 50), porosity=0.3, seed=2)
    box = Box((3, 2, 1), (35, 27, 45))
    lo, hi = vol.meta["pore_range"]
    clo, chi = 5000, 20000
    calls = []
    maps = build_selection_maps(
        vol,
        box,
        lo,
        hi,
        clo,
        chi,
        l=8,
        brick=brick,
        slab_bytes=1,
        progress=lambda d, t: calls.append((d, t)),
    )
    depth = math.lcm(8, brick)
    assert len(calls) == math.ceil(45 / depth) and calls[-1] == (45, 45)  # several slabs
    sel, color, patches, bricks = _one_shot(vol.data, box, lo, hi, clo, chi, 8, brick)
    one = build_selection_maps(vol.data, box, lo, hi, clo, chi, l=8, brick=brick)
    for m in (maps, one):
        assert m.count == int(sel.sum())
        assert m.shape_xyz == (35, 27, 45)
        np.testing.assert_array_equal(unpack_bits(m.bits, 35), sel)
        np.testing.assert_array_equal(m.color, color)
        np.testing.assert_array_equal(m.patch_mask, patches)
        np.testing.assert_array_equal(m.patch_bits, pack_bits(patches))
        np.testing.assert_array_equal(m.bricks, bricks)
        assert m.patch_shape == patch_grid(35, 27, 45, 8)
        assert m.active_patches == int(patches.sum())


def test_build_selection_maps_memmap_and_defaults(tmp_path):
    vol = random_labels((37, 11, 19), 0.1, seed=4)
    path = tmp_path / "labels.raw"
    vol.data.tofile(path)
    mm = np.memmap(path, dtype=np.uint8, mode="r", shape=vol.data.shape)
    maps = build_selection_maps(mm, None, 100, 200, slab_bytes=37 * 11 * 8)
    sel = (vol.data >= 100) & (vol.data <= 200)
    assert maps.count == round(0.1 * vol.data.size) == int(sel.sum())
    np.testing.assert_array_equal(unpack_bits(maps.bits, 37), sel)
    np.testing.assert_array_equal(maps.color, color_index(vol.data, 100, 200))
    assert maps.color_range == (100.0, 200.0)
    with pytest.raises(InputError, match="outside the volume"):
        build_selection_maps(mm, [0, 0, 0, 38, 1, 1], 0, 1)
    with pytest.raises(InputError, match=r"range: 300 outside uint8 \[0, 255\]"):
        build_selection_maps(VoxelVolume(mm), None, 0, 300)


def test_gpu_bytes_formula():
    nx, ny, nz = 200, 131, 70
    n_p, m_p, q_p = math.ceil(nx / 65), math.ceil(ny / 65), nz
    bits = 4 * nz * ny * math.ceil(nx / 32)
    patch = 4 * q_p * m_p * math.ceil(n_p / 32)
    bricks = 12 * math.ceil(nx / 8) * math.ceil(ny / 8) * math.ceil(nz / 8)  # RGB32UI skip map
    color = nx * ny * nz
    assert gpu_bytes_estimate((nx, ny, nz), "trefoil") == bits + patch + color + 1024
    assert gpu_bytes_estimate((nx, ny, nz), "raycast") == bits + bricks + color + 1024
    assert gpu_bytes_estimate((nx, ny, nz), "gs", count=1000) == bits + color + 1024 + 4000
    assert gpu_bytes_estimate((nx, ny, nz), "cubes", count=10) == 1024 + 36 * 8 * 10
    assert (
        sum(gpu_bytes_breakdown((nx, ny, nz), "raycast").values()) == bits + bricks + color + 1024
    )
    # matches the arrays build_selection_maps makes
    a = np.zeros((nz, ny, nx), np.uint8)
    m = build_selection_maps(a, None, 0, 0)
    assert bits == m.bits.nbytes and patch == m.patch_bits.nbytes
    assert bricks == skip_map(m.bits, nx).nbytes and color == m.color.nbytes
    assert m.gpu_bytes("gs") == bits + color + 1024 + 4 * m.count
    with pytest.raises(InputError, match="needs count"):
        gpu_bytes_estimate((nx, ny, nz), "gs")
    with pytest.raises(InputError, match="unknown 'vtk'"):
        gpu_bytes_estimate((nx, ny, nz), "vtk")


def test_color_index_blocks_of_big_non_contiguous_arrays():
    rng = np.random.default_rng(9)
    base = rng.integers(-3000, 3000, (2, 1200, 1000), dtype=np.int16)
    view = base[:, ::-1, 1:]  # not contiguous, > 1M values per slice: split inside a slice
    out = np.zeros((2, 1000, 1200), np.uint8).transpose(0, 2, 1)[:, :, :999]  # strided out
    color_index(view, -1000, 1000, out=out)
    expect = np.clip(np.rint((view.astype(np.float64) + 1000) / 2000 * 255), 0, 255)
    np.testing.assert_array_equal(out, expect.astype(np.uint8))
    f = view.astype(np.float32)
    np.testing.assert_array_equal(color_index(f, -1000, 1000), expect.astype(np.uint8))


class _SliceOnly:
    """An array-like that only supports basic slicing (like a lazy store)."""

    def __init__(self, a):
        self._a, self.shape, self.dtype = a, a.shape, a.dtype
        self.reads = 0

    def __getitem__(self, idx):
        self.reads += 1
        return self._a[idx].copy()


def test_build_selection_maps_on_zarr_and_slice_only_arrays():
    vol = random_labels((21, 13, 30), 0.2, seed=6)
    ref = build_selection_maps(vol.data, [1, 2, 3, 20, 10, 25], 100, 200)
    lazy = _SliceOnly(vol.data)
    got = build_selection_maps(lazy, [1, 2, 3, 20, 10, 25], 100, 200, slab_bytes=1)
    assert lazy.reads == 4  # 25 slices in slabs of 8
    z = zarr.create_array(store={}, shape=vol.data.shape, chunks=(4, 13, 21), dtype="uint8")
    z[...] = vol.data
    got_z = build_selection_maps(z, [1, 2, 3, 20, 10, 25], 100, 200, slab_bytes=1)
    for m in (got, got_z):
        assert m.count == ref.count
        for name in ("bits", "patch_bits", "bricks", "color"):
            np.testing.assert_array_equal(getattr(m, name), getattr(ref, name))


def test_slab_chunks_on_the_thread_pool_give_the_same_maps(monkeypatch):
    from geoshade.compute.voxels import bitmaps

    rng = np.random.default_rng(21)
    a = rng.integers(0, 4000, (37, 50, 70)).astype(np.uint16)
    whole = build_selection_maps(a, [1, 2, 3, 66, 45, 33], 800, 2600)
    monkeypatch.setattr(bitmaps, "WORK_BYTES", 3 * 45 * 66 * 2)  # chunks of 8 slices
    calls = []
    real = bitmaps._pool_map
    monkeypatch.setattr(bitmaps, "_pool_map", lambda fn, items: calls.append(len(items))
                        or real(fn, items))
    chunked = build_selection_maps(a, [1, 2, 3, 66, 45, 33], 800, 2600)
    assert calls == [5]  # 33 slices: four chunks of 8 and one of 1
    for name in ("bits", "patch_bits", "bricks", "color"):
        np.testing.assert_array_equal(getattr(chunked, name), getattr(whole, name), err_msg=name)
    assert chunked.count == whole.count == int(((a >= 800) & (a <= 2600))[3:36, 2:47, 1:67].sum())
