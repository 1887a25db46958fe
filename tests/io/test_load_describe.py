"""load() dispatch and hints; describe() and its text."""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import tifffile

import geoshade.io as gio
from geoshade.errors import InputError
from geoshade.io import describe, format_description, formats, load, register_reader
from geoshade.io.describe import volume_stats
from geoshade.models import VoxelVolume


def test_every_format_through_load(tmp_path):
    a = np.arange(60, dtype=np.uint16).reshape(3, 4, 5)
    a.tofile(tmp_path / "v.raw")
    tifffile.imwrite(tmp_path / "v.tif", a, photometric="minisblack")
    np.save(tmp_path / "v.npy", a)
    np.savez(tmp_path / "v.npz", volume=a)
    gio.write_zarr(VoxelVolume(a), tmp_path / "v.zarr")
    (tmp_path / "slices").mkdir()
    for z in range(3):
        tifffile.imwrite(tmp_path / "slices" / f"s{z}.tif", a[z])
    expected = {
        "v.raw": "raw",
        "v.tif": "tiff",
        "v.npy": "npy",
        "v.npz": "npz",
        "v.zarr": "zarr",
        "slices": "tiff-folder",
    }
    for name, fmt in expected.items():
        hints = {"shape": (5, 4, 3), "dtype": "u2"} if name.endswith(".raw") else {}
        vol = load(tmp_path / name, **hints)
        assert vol.meta["format"] == fmt, name
        np.testing.assert_array_equal(vol.read_box(), a, err_msg=name)


def test_missing_and_unknown(tmp_path):
    with pytest.raises(InputError, match=r"nowhere\.tif: no such file"):
        load(tmp_path / "nowhere.tif")
    f = tmp_path / "model.xyz"
    f.write_text("1 2 3")
    with pytest.raises(InputError) as e:
        load(f)
    msg = str(e.value)
    assert "model.xyz" in msg and "'.xyz'" in msg
    for suffix in (".raw", ".tif", ".npy", ".zarr", "folder of TIFF slices"):
        assert suffix in msg
    d = tmp_path / "misc"
    d.mkdir()
    (d / "a.txt").write_text("x")
    with pytest.raises(InputError, match=r"misc: folder is not a known volume; expected one of"):
        load(d)


def test_hints(tmp_path):
    a = np.zeros((3, 4, 5), np.uint8)
    np.save(tmp_path / "v.npy", a)
    vol = load(tmp_path / "v.npy", spacing=(1, 2, 3), unit="mm", origin=5, dtype=None)
    assert vol.spacing == (1.0, 2.0, 3.0) and vol.unit == "mm" and vol.origin == (5.0,) * 3
    assert "assumed" not in vol.meta
    with pytest.raises(InputError) as e:
        load(tmp_path / "v.npy", shape=(5, 4, 3))
    assert "v.npy" in str(e.value) and "shape does not apply" in str(e.value)
    with pytest.raises(InputError, match=r"v\.npy: spacing: expected 1 or 3 positive"):
        load(tmp_path / "v.npy", spacing=-1)


def test_registry_is_open_for_new_formats(tmp_path):
    def read_txt(path, scale=1):
        return VoxelVolume(np.full((1, 1, 1), scale, np.uint8), name=Path(path).name)

    register_reader([".gsvol"], read_txt, "test format")
    try:
        f = tmp_path / "x.gsvol"
        f.write_text("")
        assert int(load(f, scale=3).data[0, 0, 0]) == 3
        with pytest.raises(
            InputError, match=r"x\.gsvol: colour does not apply.*takes origin, scale"
        ):
            load(f, scale=2, colour="red")
    finally:
        formats.unregister("gsvol")
    with pytest.raises(InputError, match=r"x\.gsvol: unknown file type '\.gsvol'"):
        load(f)


def test_describe_volume_json():
    a = np.arange(2 * 3 * 4, dtype=np.uint16).reshape(2, 3, 4)
    vol = VoxelVolume(
        a,
        spacing=(0.5, 0.5, 1),
        unit="um",
        name="demo",
        meta={"format": "npy", "assumed": ["origin 0"]},
    )
    d = describe(vol)
    json.dumps(d)
    assert d["kind"] == "volume"
    assert d["shape_xyz"] == [4, 3, 2]
    assert d["dtype"] == "uint16"
    assert d["spacing"] == [0.5, 0.5, 1.0] and d["unit"] == "um"
    assert d["origin"] == [0.0, 0.0, 0.0]
    assert d["bytes"] == 48 and d["lazy"] is False
    assert (d["min"], d["max"], d["mean"]) == (0, 23, 11.5)
    assert d["assumed"] == ["origin 0"]
    text = format_description(d)
    assert "demo" in text and "4 × 3 × 2" in text and "min 0, max 23, mean 11.5" in text
    assert "assumed  origin 0" in text and "um" in text
    assert "min" not in describe(vol, stats=False)


def test_describe_streams_in_slabs(monkeypatch):
    seen = []

    class Spy:
        """Array-like that records the z-slabs asked of it."""

        def __init__(self, a):
            self.a, self.shape, self.dtype = a, a.shape, a.dtype

        def __getitem__(self, key):
            seen.append(key)
            return self.a[key]

    a = np.random.default_rng(5).integers(0, 1000, size=(40, 8, 8)).astype(np.int32)
    # ``geoshade.io.describe`` is the function; the module is reached through sys.modules
    module = importlib.import_module("geoshade.io.describe")
    monkeypatch.setattr(module, "SLAB_BYTES", 8 * 8 * 4 * 7)  # 7 planes a slab
    stats = volume_stats(VoxelVolume(Spy(a)))
    assert len(seen) == 6 and all(k.stop - k.start <= 7 for k in seen)
    assert stats["min"] == a.min() and stats["max"] == a.max()
    assert stats["mean"] == pytest.approx(a.mean())


def test_describe_float_with_nan():
    a = np.array([np.nan, 1.0, 3.0, np.inf, 2.0, np.nan, 0.0, 6.0], np.float32).reshape(2, 2, 2)
    d = describe(VoxelVolume(a))
    assert d["nan_count"] == 2
    assert (d["min"], d["max"], d["mean"]) == (0.0, 6.0, 2.4)
    assert "2 NaN" in format_description(d)
    empty = describe(VoxelVolume(np.full((1, 1, 2), np.nan)))
    assert empty["min"] is None and empty["nan_count"] == 2
    json.dumps(empty)


def test_describe_unknown_model():
    class Thing:
        name = "t"

    assert describe(Thing()) == {"kind": "Thing", "name": "t"}
    assert "Thing" in format_description(describe(Thing()))


def test_layer_rule_no_gl_imports():
    code = (
        "import sys, geoshade.io, geoshade.io.describe; "
        "bad = [m for m in sys.modules if m.split('.')[0] in ('moderngl', 'glcontext') "
        "or m.startswith(('geoshade.render', 'geoshade.compute', 'geoshade.styles'))]; "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    src = Path(gio.__file__).parent
    for f in src.glob("*.py"):
        # code lines only: a docstring example (``>>> from geoshade.compute ...``) may make its
        # data with anything, it runs in the tests, not when io is imported
        text = "\n".join(line for line in f.read_text().splitlines()
                         if not line.lstrip().startswith((">>>", "...")))
        for banned in ("moderngl", "geoshade.render", "geoshade.compute", "geoshade.styles"):
            assert f"import {banned}" not in text and f"from {banned}" not in text, f.name
