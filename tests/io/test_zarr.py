"""Zarr stores: round trip, groups, attributes, atomic writing."""

from __future__ import annotations

import numpy as np
import pytest
import zarr

from geoshade.errors import InputError
from geoshade.io import load, read_zarr, write_zarr
from geoshade.models import VoxelVolume


def _create(group, name, shape, dtype, chunks=None):
    """``group.create_array`` (zarr 3) or ``create_dataset`` (zarr 2)."""
    make = getattr(group, "create_array", None) or group.create_dataset
    return make(name, shape=shape, dtype=dtype, chunks=chunks or shape)


def _vol(dtype=np.uint16, shape=(5, 6, 7), **kw):
    a = np.random.default_rng(4).integers(0, 200, size=shape).astype(dtype)
    return VoxelVolume(a, **kw)


def test_round_trip_with_attributes(tmp_path):
    src = _vol(spacing=(0.5, 0.5, 2.0), origin=(1, 2, 3), unit="um")
    out = write_zarr(src, tmp_path / "v.zarr", chunks=(2, 4, 64))
    assert out == tmp_path / "v.zarr"
    vol = read_zarr(out)
    assert vol.spacing == (0.5, 0.5, 2.0)
    assert vol.origin == (1.0, 2.0, 3.0)
    assert vol.unit == "um"
    assert vol.is_lazy
    assert "assumed" not in vol.meta
    assert vol.meta["chunks"] == (2, 4, 7)
    assert tuple(vol.data.shape) == (5, 6, 7) and vol.dtype == np.uint16
    np.testing.assert_array_equal(vol.read_box(), src.data)
    np.testing.assert_array_equal(np.asarray(vol.data[1:3, 2:4, 0:5]), src.data[1:3, 2:4, 0:5])
    # no temporary folders left behind
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.zarr"]


def test_big_endian_memmap_source(tmp_path):
    f = tmp_path / "be.raw"
    a = np.arange(60, dtype=">u2").reshape(3, 4, 5)
    a.tofile(f)
    vol = load(f, shape=(5, 4, 3), dtype="uint16", endian="big")
    np.testing.assert_array_equal(read_zarr(write_zarr(vol, tmp_path / "be.zarr")).read_box(), a)


def test_group_with_data_or_level0(tmp_path):
    a = np.arange(24, dtype=np.float32).reshape(2, 3, 4)
    for name in ("data", "0"):
        g = zarr.open_group(str(tmp_path / f"g{name}.zarr"), mode="w")
        arr = _create(g, name, a.shape, a.dtype)
        arr[:] = a
        g.attrs.update({"spacing": [1, 2, 3], "unit": "mm"})
        vol = read_zarr(tmp_path / f"g{name}.zarr")
        np.testing.assert_array_equal(vol.read_box(), a)
        assert vol.spacing == (1.0, 2.0, 3.0) and vol.unit == "mm"
        assert vol.meta["assumed"] == ["origin 0.0 (no 'origin' attribute)"]


def test_ome_multiscales(tmp_path):
    a = np.arange(24, dtype=np.uint8).reshape(2, 3, 4)
    g = zarr.open_group(str(tmp_path / "ome"), mode="w")
    arr = _create(g, "s0", a.shape, a.dtype)
    arr[:] = a
    axes = [{"name": n, "type": "space", "unit": "micrometer"} for n in "zyx"]
    g.attrs["multiscales"] = [
        {
            "axes": axes,
            "datasets": [
                {
                    "path": "s0",
                    "coordinateTransformations": [
                        {"type": "scale", "scale": [3.0, 2.0, 1.0]},
                        {"type": "translation", "translation": [30.0, 20.0, 10.0]},
                    ],
                }
            ],
        }
    ]
    vol = load(tmp_path / "ome")  # a folder without .zarr suffix, found by its metadata
    np.testing.assert_array_equal(vol.read_box(), a)
    assert vol.spacing == (1.0, 2.0, 3.0)
    # NGFF translations place voxel centres; geoshade's origin is the first voxel's corner
    assert vol.origin == (10.0 - 0.5, 20.0 - 1.0, 30.0 - 1.5)
    assert vol.unit == "um"


def test_missing_attributes_are_assumed(tmp_path):
    z = zarr.open_array(str(tmp_path / "bare.zarr"), mode="w", shape=(2, 2, 2), dtype="u1")
    z[:] = 7
    vol = read_zarr(tmp_path / "bare.zarr")
    assert vol.spacing == (1.0, 1.0, 1.0)
    assert any("spacing 1.0" in s for s in vol.meta["assumed"])
    assert any("origin" in s for s in vol.meta["assumed"])
    assert int(vol.read_box().sum()) == 56


def test_errors(tmp_path):
    z = zarr.open_array(str(tmp_path / "flat.zarr"), mode="w", shape=(4, 4), dtype="u1")
    z[:] = 0
    with pytest.raises(InputError, match=r"flat\.zarr: expected a 3D array \(nz, ny, nx\)"):
        read_zarr(tmp_path / "flat.zarr")
    g = zarr.open_group(str(tmp_path / "grp.zarr"), mode="w")
    _create(g, "other", (2, 2, 2), "u1")
    with pytest.raises(InputError) as e:
        read_zarr(tmp_path / "grp.zarr")
    msg = str(e.value)
    assert "grp.zarr" in msg and "'data'" in msg and "'0'" in msg and "other" in msg
    (tmp_path / "empty.zarr").mkdir()
    with pytest.raises(InputError, match=r"empty\.zarr: not a readable zarr store"):
        read_zarr(tmp_path / "empty.zarr")
    with pytest.raises(InputError, match=r"gone\.zarr: no such file"):
        read_zarr(tmp_path / "gone.zarr")
    z = zarr.open_array(str(tmp_path / "bad.zarr"), mode="w", shape=(2, 2, 2), dtype="u1")
    z.attrs["spacing"] = [1, -1, 1]
    with pytest.raises(InputError, match=r"bad\.zarr: spacing attribute: expected 1 or 3 pos"):
        read_zarr(tmp_path / "bad.zarr")


def test_write_refuses_existing_unless_overwrite(tmp_path):
    p = write_zarr(_vol(np.uint8), tmp_path / "o.zarr")
    with pytest.raises(InputError, match=r"o\.zarr: already exists; pass overwrite=True"):
        write_zarr(_vol(np.uint8), p)
    new = _vol(np.int16, (2, 3, 4), unit="mm")
    write_zarr(new, p, overwrite=True)
    vol = read_zarr(p)
    np.testing.assert_array_equal(vol.read_box(), new.data)
    assert vol.unit == "mm"
    assert sorted(q.name for q in tmp_path.iterdir()) == ["o.zarr"]


def test_write_failure_leaves_nothing(tmp_path):
    class Broken:
        shape, dtype = (4, 4, 4), np.dtype("uint8")

        def __getitem__(self, key):
            raise RuntimeError("disk on fire")

    vol = VoxelVolume(Broken())
    with pytest.raises(RuntimeError, match="disk on fire"):
        write_zarr(vol, tmp_path / "x.zarr")
    assert list(tmp_path.iterdir()) == []


def test_bad_chunks(tmp_path):
    with pytest.raises(InputError, match=r"chunks: expected 3 positive integers"):
        write_zarr(_vol(), tmp_path / "c.zarr", chunks=(0, 4, 4))
