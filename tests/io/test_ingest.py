"""Ingest into multiscale zarr: formats, pyramid, bounded slabs, resume, disk full, bad input."""

from __future__ import annotations

import errno
import json
import os

import numpy as np
import pytest
import tifffile
import zarr

from geoshade.errors import InputError
from geoshade.io import load, read_zarr
from geoshade.io.stores import ingest as ing
from geoshade.io.stores.ingest import (
    PARTIAL_SUFFIX,
    DiskFullError,
    downsample2,
    ingest,
    level_shapes,
    read_level,
    store_levels,
)
from geoshade.io.stores.partial_store import PROGRESS_FILE


def _vol(shape=(21, 18, 23), dtype=np.uint16, seed=0):
    return np.random.default_rng(seed).integers(1, 60000, shape).astype(dtype)


def _tiff_folder(path, a):
    path.mkdir()
    for z in range(a.shape[0]):
        tifffile.imwrite(path / f"slice_{z + 1:04d}.tif", a[z], resolution=(2.0, 2.0),
                         resolutionunit=5)  # 0.5 um pixels
    return path


def _raw(path, a):
    a.tofile(path)
    nz, ny, nx = a.shape
    return {"shape": (nx, ny, nz), "dtype": a.dtype.name}


def _leftovers(folder):
    return sorted(p.name for p in folder.iterdir())


def test_tiff_folder_to_multiscale_store(tmp_path):
    a = _vol()
    src = _tiff_folder(tmp_path / "slices", a)
    rep = ingest(src, tmp_path / "core.zarr", chunks=(4, 8, 16), levels=3)
    assert rep.shape_xyz == (23, 18, 21) and rep.levels == [(23, 18, 21), (12, 9, 11), (6, 5, 6)]
    assert rep.value_range == [int(a.min()), int(a.max())]
    assert rep.slabs_written == 6 + 3 + 2 and rep.slabs_skipped == 0
    vol = load(tmp_path / "core.zarr")  # read_zarr finds level 0 through the multiscales
    assert vol.is_lazy and vol.spacing[:2] == (0.5, 0.5) and vol.unit == "um"
    assert vol.meta["value_range"] == rep.value_range
    np.testing.assert_array_equal(vol.read_box(), a)
    for k in (1, 2):
        lv = read_level(tmp_path / "core.zarr", k)
        np.testing.assert_array_equal(lv.read_box(), a[:: 2**k, :: 2**k, :: 2**k])
        assert lv.spacing == tuple(s * 2**k for s in vol.spacing) and lv.origin == vol.origin
    attrs = zarr.open_group(str(tmp_path / "core.zarr"), mode="r").attrs
    assert attrs["ome"]["version"] == "0.5"  # OME-Zarr (NGFF 0.5): tests/io/test_ome_zarr.py
    ms = attrs["ome"]["multiscales"][0]
    assert [d["path"] for d in ms["datasets"]] == ["0", "1", "2"]
    assert [a_["name"] for a_ in ms["axes"]] == ["z", "y", "x"]
    assert ms["datasets"][1]["coordinateTransformations"][0]["scale"][2] == 1.0  # x: 0.5 * 2
    assert attrs["ingest"]["complete"] is True
    assert store_levels(tmp_path / "core.zarr") == 3
    arr = zarr.open_array(str(tmp_path / "core.zarr" / "0"), mode="r")
    assert arr.metadata.zarr_format == 3 and tuple(arr.chunks) == (4, 8, 16)
    assert _leftovers(tmp_path) == ["core.zarr", "slices"]


def test_raw_multipage_tiff_and_hdf5_inputs(tmp_path):
    h5py = pytest.importorskip("h5py")
    a = _vol((9, 10, 11), np.int16, seed=1)
    hints = _raw(tmp_path / "v.raw", a)
    r1 = ingest(tmp_path / "v.raw", tmp_path / "raw.zarr", chunks=(4, 4, 4), levels=1,
                spacing=(2, 2, 3), unit="mm", **hints)
    v = read_zarr(r1.path)
    assert v.spacing == (2.0, 2.0, 3.0) and v.unit == "mm" and v.dtype == np.int16
    np.testing.assert_array_equal(v.read_box(), a)
    tifffile.imwrite(tmp_path / "stack.tif", a, compression="zlib")  # not memory-mappable
    r2 = ingest(tmp_path / "stack.tif", tmp_path / "tif.zarr", chunks=(4, 4, 4), levels=2)
    np.testing.assert_array_equal(read_zarr(r2.path).read_box(), a)
    with h5py.File(tmp_path / "v.h5", "w") as h:
        h.create_dataset("a/b", data=a.astype(np.float32) / 7)
        h.create_dataset("c", data=a)
    r3 = ingest(tmp_path / "v.h5", tmp_path / "h5.zarr", chunks=(4, 4, 4), levels=2,
                dataset="a/b")
    got = read_zarr(r3.path).read_box()
    np.testing.assert_array_equal(got, a.astype(np.float32) / 7)
    assert r3.dtype == "float32" and np.isclose(r3.value_range[1], a.max() / 7)


def test_raw_with_header_and_big_endian_is_read_with_file_reads(tmp_path, monkeypatch):
    a = _vol((10, 6, 7), np.dtype(">u2"), seed=6)
    f = tmp_path / "h.raw"
    f.write_bytes(b"H" * 100 + a.tobytes())
    monkeypatch.setattr(np.memmap, "__getitem__", None)  # slabs must not come from the map
    rep = ingest(f, tmp_path / "h.zarr", chunks=(3, 8, 8), levels=1, shape=(7, 6, 10),
                 dtype="uint16", endian="big", offset=100)
    monkeypatch.undo()
    got = read_zarr(rep.path).read_box()
    assert got.dtype == np.uint16 and np.array_equal(got, a.astype(np.uint16))


def test_mean_pyramid_matches_numpy_with_odd_sizes(tmp_path):
    a = _vol((7, 6, 5), np.uint8, seed=2)
    hints = _raw(tmp_path / "m.raw", a)
    rep = ingest(tmp_path / "m.raw", tmp_path / "m.zarr", chunks=(2, 4, 4), levels=2,
                 downsample="mean", **hints)
    p = np.pad(a, [(0, 1), (0, 0), (0, 1)], mode="edge").astype(np.int64)
    ref = (p.reshape(4, 2, 3, 2, 3, 2).sum(axis=(1, 3, 5)) + 4) // 8
    np.testing.assert_array_equal(read_level(rep.path, 1).read_box(), ref.astype(np.uint8))
    np.testing.assert_array_equal(downsample2(a, "nearest"), a[::2, ::2, ::2])
    assert level_shapes((7360, 2600, 2600))[-1] == (230, 82, 82)


def test_input_is_read_in_slabs_of_whole_chunk_rows(tmp_path, monkeypatch):
    a = _vol((30, 12, 14))
    hints = _raw(tmp_path / "s.raw", a)
    seen = []
    orig = ing._read

    def spy(data, sl):
        seen.append((sl[0].start, sl[0].stop))
        return orig(data, sl)

    monkeypatch.setattr(ing, "_read", spy)
    ingest(tmp_path / "s.raw", tmp_path / "s.zarr", chunks=(8, 16, 16), levels=2, **hints)
    assert seen == [(0, 8), (8, 16), (16, 24), (24, 30)]  # never more than one chunk row


class KilledError(Exception):
    pass


def _interrupt_after(monkeypatch, n):
    """Make the n+1-th slab write fail, as if the process were killed there."""
    calls = {"n": 0}
    orig = ing._write_slab

    def flaky(*args):
        calls["n"] += 1
        if calls["n"] > n:
            raise KilledError("killed")
        return orig(*args)

    monkeypatch.setattr(ing, "_write_slab", flaky)
    return calls


def test_interrupted_ingest_resumes_without_rewriting(tmp_path, monkeypatch):
    a = _vol((24, 10, 12))
    hints = _raw(tmp_path / "r.raw", a)
    out = tmp_path / "r.zarr"
    partial = tmp_path / ("r.zarr" + PARTIAL_SUFFIX)
    _interrupt_after(monkeypatch, 3)
    with pytest.raises(KilledError):
        ingest(tmp_path / "r.raw", out, chunks=(4, 8, 8), levels=2, **hints)
    assert not out.exists() and partial.is_dir()
    with pytest.raises(InputError, match="incomplete store"):
        read_zarr(partial)  # a half-written store is never presented as complete
    progress = tmp_path / ("r.zarr" + PARTIAL_SUFFIX + PROGRESS_FILE)
    done = json.loads(progress.read_text())["done"]["0"]
    assert sorted(done, key=int) == ["0", "1", "2"]
    chunk = partial / "0" / "c" / "0" / "0" / "0"
    stamp = chunk.stat().st_mtime_ns
    monkeypatch.undo()
    written = []
    orig = ing._write_slab
    monkeypatch.setattr(ing, "_write_slab",
                        lambda *args: written.append(args[2:4]) or orig(*args))
    rep = ingest(tmp_path / "r.raw", out, chunks=(4, 8, 8), levels=2, **hints)
    assert rep.resumed and rep.slabs_skipped == 3
    assert written == [(0, 3), (0, 4), (0, 5), (1, 0), (1, 1), (1, 2)]
    assert not partial.exists() and not progress.exists()
    np.testing.assert_array_equal(read_zarr(out).read_box(), a)
    np.testing.assert_array_equal(read_level(out, 1).read_box(), a[::2, ::2, ::2])
    assert (out / "0" / "c" / "0" / "0" / "0").stat().st_mtime_ns == stamp  # not rewritten


def test_resume_checks_settings_and_verifies_crc(tmp_path, monkeypatch):
    a = _vol((16, 8, 8))
    hints = _raw(tmp_path / "v.raw", a)
    out = tmp_path / "v.zarr"
    _interrupt_after(monkeypatch, 2)
    with pytest.raises(KilledError):
        ingest(tmp_path / "v.raw", out, chunks=(4, 8, 8), levels=1, **hints)
    monkeypatch.undo()
    with pytest.raises(InputError, match=r"another input or settings \(chunks"):
        ingest(tmp_path / "v.raw", out, chunks=(2, 8, 8), levels=1, **hints)
    # damage a recorded slab behind the progress file's back: verify=True finds and rewrites it
    partial = tmp_path / ("v.zarr" + PARTIAL_SUFFIX)
    zarr.open_array(str(partial / "0"), mode="r+")[0:4] = 7
    rep = ingest(tmp_path / "v.raw", out, chunks=(4, 8, 8), levels=1, verify=True, **hints)
    assert rep.slabs_skipped == 1 and rep.slabs_written == 3
    np.testing.assert_array_equal(read_zarr(out).read_box(), a)


def test_disk_full_one_line_then_resume(tmp_path, monkeypatch):
    from zarr.storage import LocalStore

    a = _vol((20, 8, 8))
    hints = _raw(tmp_path / "d.raw", a)
    out = tmp_path / "d.zarr"
    orig = LocalStore.set
    count = {"n": 0}

    async def full(self, key, value):
        if "/c/" in key:
            count["n"] += 1
            if count["n"] > 2:
                raise OSError(errno.ENOSPC, "No space left on device")
        return await orig(self, key, value)

    monkeypatch.setattr(LocalStore, "set", full)
    with pytest.raises(DiskFullError) as err:
        ingest(tmp_path / "d.raw", out, chunks=(4, 8, 8), levels=1, **hints)
    msg = str(err.value)
    assert "\n" not in msg and "disk full" in msg and "resume" in msg and "d.zarr" in msg
    assert err.value.exit_code == 9
    assert not out.exists()  # nothing claims to be complete
    with pytest.raises(InputError, match="incomplete store"):
        read_zarr(tmp_path / ("d.zarr" + PARTIAL_SUFFIX))
    monkeypatch.undo()
    rep = ingest(tmp_path / "d.raw", out, chunks=(4, 8, 8), levels=1, **hints)
    assert rep.slabs_skipped == 2
    np.testing.assert_array_equal(read_zarr(out).read_box(), a)


def test_threads_write_the_same_store(tmp_path):
    a = _vol((33, 9, 10))
    hints = _raw(tmp_path / "t.raw", a)
    r = ingest(tmp_path / "t.raw", tmp_path / "t.zarr", chunks=(4, 8, 8), levels=3, workers=3,
               **hints)
    np.testing.assert_array_equal(read_zarr(r.path).read_box(), a)
    np.testing.assert_array_equal(read_level(r.path, 2).read_box(), a[::4, ::4, ::4])


@pytest.mark.parametrize("problem", ["size", "dtype", "gap"])
def test_bad_tiff_folder_one_line_nothing_written(tmp_path, problem):
    a = _vol((5, 6, 7), np.uint8)
    src = _tiff_folder(tmp_path / "sl", a)
    if problem == "size":
        tifffile.imwrite(src / "slice_0003.tif", np.zeros((6, 8), np.uint8))
        match = r"slice_0003.tif: slice is 8×6 uint8 .* expected all slices alike"
    elif problem == "dtype":
        tifffile.imwrite(src / "slice_0004.tif", np.zeros((6, 7), np.uint16))
        match = r"slice_0004.tif: slice is 7×6 uint16"
    else:
        os.remove(src / "slice_0003.tif")
        match = r"slice 3 is missing"
    with pytest.raises(InputError, match=match) as err:
        ingest(src, tmp_path / "bad.zarr")
    assert "\n" not in str(err.value)
    assert _leftovers(tmp_path) == ["sl"]


def test_existing_output_and_missing_input(tmp_path):
    a = _vol((4, 4, 4), np.uint8)
    hints = _raw(tmp_path / "e.raw", a)
    ingest(tmp_path / "e.raw", tmp_path / "e.zarr", levels=1, **hints)
    with pytest.raises(InputError, match="already exists"):
        ingest(tmp_path / "e.raw", tmp_path / "e.zarr", levels=1, **hints)
    (tmp_path / "e.raw").write_bytes((a + 1).tobytes())
    rep = ingest(tmp_path / "e.raw", tmp_path / "e.zarr", levels=1, overwrite=True, **hints)
    np.testing.assert_array_equal(read_zarr(rep.path).read_box(), a + 1)
    with pytest.raises(InputError, match="no such file"):
        ingest(tmp_path / "nothing.raw", tmp_path / "n.zarr")
    with pytest.raises(InputError, match="--shape"):
        ingest(tmp_path / "e.raw", tmp_path / "n.zarr")
    assert _leftovers(tmp_path) == ["e.raw", "e.zarr"]


def test_store_without_our_attributes_is_read_with_assumptions(tmp_path):
    g = zarr.open_group(str(tmp_path / "foreign.zarr"), mode="w")
    arr = g.create_array("data", shape=(4, 5, 6), chunks=(2, 5, 6), dtype="u1")
    arr[:] = 3
    vol = load(tmp_path / "foreign.zarr")
    assert vol.spacing == (1.0, 1.0, 1.0) and "value_range" not in vol.meta
    assert any("spacing" in a for a in vol.meta["assumed"])
    assert any("origin" in a for a in vol.meta["assumed"])
    assert store_levels(tmp_path / "foreign.zarr") == 1


def test_box_reads_only_the_chunks_it_touches(tmp_path, monkeypatch):
    from zarr.storage import LocalStore

    a = _vol((16, 16, 16))
    hints = _raw(tmp_path / "b.raw", a)
    rep = ingest(tmp_path / "b.raw", tmp_path / "b.zarr", chunks=(4, 8, 8), levels=1, **hints)
    vol = load(rep.path)
    keys = []
    orig = LocalStore.get

    async def spy(self, key, *args, **kw):
        if "/c/" in key:
            keys.append(key)
        return await orig(self, key, *args, **kw)

    monkeypatch.setattr(LocalStore, "get", spy)
    np.testing.assert_array_equal(vol.read_box([9, 1, 5, 4, 3, 4]), a[5:9, 1:4, 9:13])
    assert sorted(keys) == ["0/c/1/0/1", "0/c/2/0/1"]  # z chunks 1-2, y chunk 0, x chunk 1


def test_ingest_never_replaces_the_folder_holding_its_input(tmp_path):
    """``ingest IN -o DIR --overwrite`` where DIR holds IN (or is a link, or a folder geoshade did
    not write) is refused in one line before any work, and DIR is untouched."""
    d = tmp_path / "case"
    d.mkdir()
    raw = d / "v.raw"
    np.arange(64, dtype=np.uint8).tofile(raw)
    hints = {"shape": (4, 4, 4), "dtype": "uint8"}
    with pytest.raises(InputError, match=r"case: -o: .*(input|did not write)"):
        ingest(raw, d, overwrite=True, **hints)
    assert sorted(p.name for p in d.iterdir()) == ["v.raw"]
    (tmp_path / "link.zarr").symlink_to(d)
    with pytest.raises(InputError, match=r"link\.zarr: -o: a symbolic link"):
        ingest(raw, tmp_path / "link.zarr", overwrite=True, **hints)
    assert raw.read_bytes() == bytes(range(64))
