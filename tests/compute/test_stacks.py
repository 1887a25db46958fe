"""Voxels ⇄ stacks (exact), interval counts, boreholes, the GPU form, layout memory, octree."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import geoshade.compute.stacks as stacks_module
from geoshade.compute.stacks import (
    exact_rect,
    gpu_intervals,
    interval_counts,
    layout_plan,
    memory_table,
    min_perimeter_rect,
    place_boreholes,
    stacks_to_voxels,
    synthetic_layers,
    voxels_to_stacks,
)
from geoshade.compute.voxels.octree import octree_memory, octree_of_labels, octree_of_stacks
from geoshade.errors import GPUMemoryError, InputError
from geoshade.models.stacks import EMPTY, BoreholeLogs, StackModel


def layered(rng, nz=30, ny=7, nx=9, layers=5, empty=0, caves=True) -> np.ndarray:
    """Random layer cake (codes 1..layers, pinch-outs), air on top and a few caves."""
    cuts = np.sort(rng.integers(0, nz + 1, (layers, ny, nx)), axis=0)
    z = np.arange(nz)[:, None, None]
    a = np.full((nz, ny, nx), empty, np.int16)
    for k in range(layers):  # (loop over layers, not columns)
        lo = cuts[k - 1] if k else 0
        a[(z >= lo) & (z < cuts[k])] = rng.integers(1, 7)
    if caves:
        a[(rng.random(a.shape) < 0.03)] = empty
    return a


def runs_oracle(a: np.ndarray, empty) -> np.ndarray:
    """Intervals per column by itertools.groupby, column by column (the independent oracle)."""
    _, ny, nx = a.shape
    out = np.zeros((ny, nx), np.int64)
    for y, x in itertools.product(range(ny), range(nx)):
        col = [(None if (v == empty or v != v) else v) for v in a[:, y, x].tolist()]
        groups = [k for k, _ in itertools.groupby(col)]
        out[y, x] = len(groups) - (1 if groups and groups[0] is None else 0)
    return out


@pytest.mark.parametrize("seed", range(4))
def test_round_trip_exact_and_counts_on_random_layered_models(seed):
    rng = np.random.default_rng(seed)
    a = layered(rng)
    m = voxels_to_stacks(a, empty=0)
    assert np.array_equal(stacks_to_voxels(m, np.int16, fill=0), a)
    expect = runs_oracle(a, 0)
    assert m.counts().reshape(a.shape[1:]).tolist() == expect.tolist()
    assert interval_counts(a, empty=0).tolist() == expect.tolist()
    assert m.nintervals == int(expect.sum())
    # numpy count of runs (diff of the column, the leading empty run not counted)
    d = (np.diff(a, axis=0) != 0).sum(axis=0) + 1 - (a[0] == 0)
    assert d.tolist() == expect.tolist()


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_round_trip_float_labels_with_nan(dtype):
    rng = np.random.default_rng(5)
    a = layered(rng).astype(dtype) * 1000
    a[a == 0] = np.nan
    m = voxels_to_stacks(a)
    back = stacks_to_voxels(m, dtype)
    assert np.array_equal(back, a, equal_nan=True)
    assert m.counts().reshape(a.shape[1:]).tolist() == runs_oracle(a, np.nan).tolist()


def test_round_trip_uint8_without_empty_and_in_several_slabs(monkeypatch):
    monkeypatch.setattr(stacks_module, "SLAB_CELLS", 64)  # force many y-slabs
    a = np.random.default_rng(1).integers(0, 3, (9, 11, 5)).astype(np.uint8)
    m = voxels_to_stacks(a)
    assert m.legend.codes.tolist() == [0, 1, 2]
    assert np.array_equal(stacks_to_voxels(m, np.uint8), a)


def test_region_of_stacks_to_voxels():
    a = layered(np.random.default_rng(2))
    m = voxels_to_stacks(a, empty=0)
    r = stacks_to_voxels(m, np.int16, fill=0, region=(2, 7, 1, 5, 3, 20))
    assert np.array_equal(r, a[3:20, 1:5, 2:7])


def test_fractional_heights_sample_level_centres_and_match_the_integer_path():
    m = StackModel([0, 2, 4], [0, 2.5, 1, 3], [1, 2, 3, EMPTY], (2, 1), 5)
    v = stacks_to_voxels(m)
    assert v[:, 0, 0].tolist() == [1, 1, 2, 2, 2] and v[:, 0, 1].tolist() == [EMPTY, 3, 3,
                                                                                EMPTY, EMPTY]
    a = layered(np.random.default_rng(9)).astype(np.int32)
    m = voxels_to_stacks(a, empty=0)
    frac = StackModel(m.offsets, m.starts, m.codes, m.shape, m.nlevels, legend=m.legend)
    frac.starts[-1] += 0.25                  # one fractional start: the general path
    r = (0, 9, 0, 6, 0, 30)                  # the last column (x 8, y 6) is outside r
    assert np.array_equal(stacks_to_voxels(frac, region=r), stacks_to_voxels(m, region=r))


def test_bad_labels_are_one_line_errors():
    with pytest.raises(InputError, match="non-integer"):
        voxels_to_stacks(np.full((2, 2, 2), 1.5))
    with pytest.raises(InputError, match="reserved for empty"):
        voxels_to_stacks(np.full((2, 2, 2), -1, np.int8))
    with pytest.raises(InputError, match="3D array"):
        voxels_to_stacks(np.zeros((2, 2)))
    m = voxels_to_stacks(np.full((2, 2, 2), -1, np.int8), empty=-1)
    assert m.nintervals == 0


def test_synthetic_layers_are_exact_voxel_models():
    m = synthetic_layers(17, 13, 40, max_intervals=7, mean_intervals=4.0, seed=4)
    g = gpu_intervals(m)
    assert g.max_count == 7 and abs(g.n / m.ncols - 4.0) < 0.8
    v = stacks_to_voxels(m)
    back = voxels_to_stacks(v, empty=EMPTY, legend=m.legend)
    assert np.array_equal(back.offsets, m.offsets) and np.array_equal(back.codes, m.codes)
    assert np.array_equal(back.starts, m.starts)


def test_gpu_form_leading_empty_no_trailing_air_and_log_flags():
    m = StackModel([0, 3, 4], [2, 3, 5, 0], [4, 6, EMPTY, 4], (2, 1), 8,
                   borehole=[False, True], log_base=[0, 0])
    g = gpu_intervals(m)
    # column 0: (empty to 2), 4 to 3, 6 to 5; column 1: 4 to 8 (the model top)
    assert g.count.tolist() == [3, 1] and g.first.tolist() == [0, 3]
    assert g.mat.tolist() == [0, 1, 2, 1] and g.end.tolist() == [2, 3, 5, 8]
    assert g.log.tolist() == [False, False, False, True]
    assert (g.max_count, g.ztop) == (3, 8.0)


def deep_column_model(nlev=20) -> StackModel:
    a = np.zeros((nlev, 1, 3), np.int16)
    a[:15] = 1
    a[:5] = 2
    return voxels_to_stacks(a, empty=0, spacing=(10.0, 10.0, 1.0), origin=(0.0, 0.0, -10.0))


def test_boreholes_are_spliced_into_their_columns():
    m = deep_column_model()
    # B1 in column 1 (x 15): layers from 5 m down to -2 m; B2 in column 1 too but shallower;
    # B3 outside the grid
    logs = BoreholeLogs(["B1", "B1", "B1", "B2", "B3"], [15, 15, 15, 12, 99], [5, 5, 5, 5, 5],
                        top=[5.0, 2.0, 0.0, 5.0, 0.0], bottom=[2.0, 1.0, -2.0, 4.0, -1.0],
                        code=[7, 8, 8, 9, 9])
    b = place_boreholes(m, logs)
    assert b.borehole.tolist() == [False, True, False]
    assert b.meta["boreholes"] == {"boreholes": 3, "placed": 1, "outside": 1, "duplicates": 1,
                                   "layers_clipped": 0, "columns": 1}
    s, e = b.offsets[1], b.offsets[2]
    # levels: z = -10 + level; the model below -2 m (level 8): code 2 to level 5, code 1 to 8;
    # the log: code 8 from 8 (-2 m) to 10 (0 m), a gap to 11, code 8 to 12, code 7 to 15 (5 m),
    # air above
    assert b.starts[s:e].tolist() == [0, 5, 8, 10, 11, 12, 15]
    assert b.codes[s:e].tolist() == [2, 1, 8, EMPTY, 8, 7, EMPTY]
    assert b.log_intervals()[s:e].tolist() == [False, False] + [True] * 5
    assert b.log_base[1] == 8.0
    # the other columns are untouched
    assert np.array_equal(stacks_to_voxels(b, np.int16, fill=0)[:, :, [0, 2]],
                          stacks_to_voxels(m, np.int16, fill=0)[:, :, [0, 2]])


def test_overlapping_log_layers_clip_or_raise():
    m = deep_column_model()
    logs = BoreholeLogs(["B"] * 2, [15, 15], [5, 5], top=[3.0, 1.0], bottom=[0.0, -1.0],
                        code=[7, 8])
    with pytest.raises(InputError, match="overlapping"):
        place_boreholes(m, logs, strict=True)
    b = place_boreholes(m, logs)
    assert b.meta["boreholes"]["layers_clipped"] == 1
    s, e = b.offsets[1], b.offsets[2]
    assert b.starts[s:e].tolist() == [0, 5, 9, 10, 13] and b.codes[s:e].tolist() == [
        2, 1, 8, 7, EMPTY]


def test_layout_plan_reproduces_table3_of_the_paper():
    mib = 2**20
    a = {lay: layout_plan(lay, (200, 250), 309433, 10) for lay in
         ("textures", "r-supertexels", "l-supertexels", "texture3d", "ssbo")}
    assert round(a["textures"]["consumed"] / mib, 2) == 1.56
    assert a["textures"]["wasted"] == 4 and a["ssbo"]["wasted"] == 0   # 3.81e-6 MB
    assert a["textures"]["objects"]["intervals"] == (646, 479)          # the paper's 479×646
    for lay in ("r-supertexels", "l-supertexels", "texture3d"):
        assert round(a[lay]["consumed"] / mib, 2) == 1.91
        assert round(a[lay]["wasted"] / mib, 2) == 0.73
    c = layout_plan("texture3d", (800, 1000), 6_018_000, 16)
    assert round(c["consumed"] / mib, 2) == 48.83


def test_rectangles():
    assert min_perimeter_rect(5) == (3, 2)      # the paper's example: supertexels of 3×2
    assert min_perimeter_rect(15) == (5, 3)
    assert min_perimeter_rect(1) == (1, 1)
    w, h = exact_rect(1_000_003, 16384)         # a prime: one more
    assert w * h == 1_000_004 and w <= 16384 and h > 1
    assert exact_rect(7, 16384) == (7, 1)       # small primes fit in one row


def test_layout_limits_are_clear_errors():
    # the paper's example: 1024×1024 columns, 17 intervals: a 17408×1024 L-supertexel texture
    with pytest.raises(GPUMemoryError, match=r"17408×1024.*16384"):
        layout_plan("l-supertexels", (1024, 1024), 10_000_000, 17)
    with pytest.raises(GPUMemoryError, match="limit of 2048"):
        layout_plan("texture3d", (4000, 10), 100, 5)
    with pytest.raises(GPUMemoryError, match="SSBO"):
        layout_plan("ssbo", (10, 10), 100, 3, {"max_ssbo_bytes": 256})
    with pytest.raises(GPUMemoryError, match="r-supertexels"):
        layout_plan("r-supertexels", (100, 100), 1000, 9, {"max_texture_size": 128})
    with pytest.raises(InputError, match="unknown layout"):
        layout_plan("bricks", (10, 10), 100, 3)


def test_memory_table_bytes():
    m = synthetic_layers(20, 10, 30, max_intervals=5, seed=1)
    t = memory_table(m)
    g = gpu_intervals(m)
    assert t["bytes_voxels"] == 20 * 10 * 30 * 4
    assert t["bytes_stacks"] == 200 * 8 + g.n * 4
    assert t["intervals"] == m.nintervals and t["gpu_intervals"] == g.n


# --- octree -----------------------------------------------------------------------------------
def octree_nodes_oracle(a: np.ndarray) -> int:
    """Recursive region octree over ``a`` padded with EMPTY to a power-of-two cube."""
    n = 1 << int(np.ceil(np.log2(max(a.shape))))
    p = np.full((n, n, n), EMPTY, np.int64)
    p[: a.shape[0], : a.shape[1], : a.shape[2]] = a

    def nodes(z, y, x, s):
        blk = p[z:z + s, y:y + s, x:x + s]
        if s == 1 or (blk == blk.flat[0]).all():
            return 1
        h = s // 2
        return 1 + sum(nodes(z + i, y + j, x + k, h) for i in (0, h) for j in (0, h)
                       for k in (0, h))

    return nodes(0, 0, 0, n)


@pytest.mark.parametrize("shape, block", [((5, 6, 7), 2), ((9, 3, 4), 4), ((16, 16, 16), 8),
                                          ((3, 17, 2), 64)])
def test_octree_node_count_equals_a_recursive_octree(shape, block):
    a = layered(np.random.default_rng(sum(shape)), *shape, layers=3, caves=False).astype(np.int32)
    counts = octree_of_labels(a, block=block)
    assert octree_memory(counts)["nodes"] == octree_nodes_oracle(a)
    m = voxels_to_stacks(a)
    assert octree_of_stacks(m, block=block) == counts


def test_octree_bytes_and_depth_limit():
    a = layered(np.random.default_rng(7), 12, 10, 9, layers=3, caves=False)
    c = octree_of_labels(a)
    full, lim = octree_memory(c), octree_memory(c, max_depth=2)
    assert full["bytes"] == 4 * full["nodes"] and full["side"] == 16
    inner2 = sum(c["nonuniform"][:2])
    assert lim["nodes"] == 1 + 8 * inner2
    assert lim["brick_voxels"] == c["nonuniform"][2] * 4**3
