"""HDF5 volumes: lazy reading, dataset choice, voxel size attributes, bad files."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.volumes.hdf5 import H5Array, read_hdf5

h5py = pytest.importorskip("h5py")


def _vol(shape=(6, 7, 9), dtype=np.uint16, seed=0):
    return np.random.default_rng(seed).integers(0, 5000, shape).astype(dtype)


def test_lazy_round_trip_and_box_reads_only_its_chunks(tmp_path, monkeypatch):
    a = _vol((40, 30, 20))
    f = tmp_path / "core.h5"
    with h5py.File(f, "w") as h:
        d = h.create_dataset("data", data=a, chunks=(8, 10, 20))
        d.attrs["spacing"] = [0.5, 0.5, 1.0]
        d.attrs["unit"] = "um"
    vol = load(f)
    assert vol.is_lazy and vol.meta["format"] == "hdf5" and vol.meta["dataset"] == "data"
    assert vol.spacing == (0.5, 0.5, 1.0) and vol.unit == "um" and "assumed" not in vol.meta
    assert vol.data.chunks[0] == (8,) * 5
    np.testing.assert_array_equal(vol.read_box(), a)
    reads = []
    orig = H5Array.__getitem__

    def spy(self, key):
        reads.append(key)
        return orig(self, key)

    monkeypatch.setattr(H5Array, "__getitem__", spy)
    box = [3, 4, 9, 5, 6, 9]  # z 9..17 -> chunks 1, 2; y 4..9 -> chunk 0; x -> chunk 0
    np.testing.assert_array_equal(vol.read_box(box), a[9:18, 4:10, 3:8])
    assert sorted(k[0].start for k in reads) == [8, 16]  # 2 of the 20 chunks, nothing else


def test_dataset_choice_and_element_size(tmp_path):
    f = tmp_path / "two.hdf5"
    a, b = _vol(seed=1), _vol(seed=2).astype(np.float32)
    with h5py.File(f, "w") as h:
        h.create_dataset("scan/raw", data=a)
        d = h.create_dataset("scan/filtered", data=b)
        d.attrs["element_size_um"] = [3.0, 2.0, 1.0]  # z, y, x
    with pytest.raises(InputError, match=r"several 3D datasets .*--dataset"):
        read_hdf5(f)
    vol = load(f, dataset="/scan/filtered")
    assert vol.spacing == (1.0, 2.0, 3.0) and vol.unit == "um"
    np.testing.assert_array_equal(vol.read_box(), b)
    with pytest.raises(InputError, match="no dataset 'nope'"):
        load(f, dataset="nope")
    with pytest.raises(InputError, match="is a group"):
        load(f, dataset="scan")


def test_no_spacing_is_assumed_and_said(tmp_path):
    f = tmp_path / "plain.h5"
    with h5py.File(f, "w") as h:
        h.create_dataset("volume", data=_vol())
        h.create_dataset("notes", data=np.zeros(3))
    vol = load(f)
    assert vol.meta["dataset"] == "volume"
    assert any("spacing 1.0" in a for a in vol.meta["assumed"])


def test_bad_files_one_line(tmp_path):
    f = tmp_path / "not.h5"
    f.write_bytes(b"this is not hdf5")
    with pytest.raises(InputError, match="not a readable HDF5 file"):
        load(f)
    g = tmp_path / "flat.h5"
    with h5py.File(g, "w") as h:
        h.create_dataset("image", data=np.zeros((4, 4)))
    with pytest.raises(InputError, match="no 3D dataset"):
        load(g)


def test_h5array_pickles_without_data(tmp_path):
    f = tmp_path / "p.h5"
    a = _vol()
    with h5py.File(f, "w") as h:
        h.create_dataset("data", data=a)
    arr = H5Array(f, "data")
    _ = arr[0]  # opens the file
    blob = pickle.dumps(arr)
    assert len(blob) < 1000  # the path, not the values
    np.testing.assert_array_equal(pickle.loads(blob)[2:4], a[2:4])
