"""``geoshade core ingest`` and ``--scheduler/--bricks/--level`` end to end, with bad inputs."""

from __future__ import annotations

import errno
import json

import numpy as np
import pytest
import tifffile

from geoshade.cli.main import main


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


@pytest.fixture
def slices(tmp_path):
    a = np.random.default_rng(0).integers(0, 4000, (20, 24, 28)).astype(np.uint16)
    d = tmp_path / "scan"
    d.mkdir()
    for z in range(a.shape[0]):
        tifffile.imwrite(d / f"scan_{z:03d}.tif", a[z])
    return d, a


@pytest.mark.gl
def test_ingest_then_porosity_and_render(capsys, tmp_path, slices):
    src, a = slices
    store = tmp_path / "core.zarr"
    rc, out, err = run(capsys, "core", "ingest", src, "-o", store, "--chunks", 8, 16, 16,
                       "--levels", 2, "--spacing", 2, 2, 2, "--unit", "um")
    assert rc == 0, err
    assert "28×24×20 uint16, 2 levels" in out and "slabs written" in out
    js = tmp_path / "p.json"
    rc, out, err = run(capsys, "core", "porosity", store, "--select", 0, 1000, "--axis", "y",
                       "-o", tmp_path / "p.png", "--json", js, "--scheduler", "threads")
    assert rc == 0, err
    res = json.loads(js.read_text())
    sel = (a <= 1000)
    assert res["count"] == int(sel.sum())
    assert res["profile"] == [float(v) for v in sel.sum(axis=(0, 2)) / (20 * 28)]
    st = tmp_path / "s.json"
    rc, out, err = run(capsys, "core", "render", store, "--select", 0, 1000, "--bricks", 16,
                       "--size", "64x48", "--frames", 1, "-o", tmp_path / "r.png", "--stats", st)
    assert rc == 0, err
    s = json.loads(st.read_text())
    assert s["bricks"] == 8 and s["voxels_selected"] == int(sel.sum())
    rc, out, err = run(capsys, "core", "render", store, "--select", 0, 1000, "--level", 1,
                       "--size", "64x48", "--frames", 1, "-o", tmp_path / "o.png", "--stats", st)
    assert rc == 0, err
    assert "pyramid level 1, 14×12×10" in out
    assert json.loads(st.read_text())["voxels_selected"] == int((a[::2, ::2, ::2] <= 1000).sum())


def _one_error_line(err):
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("geoshade: error:"), err
    assert "Traceback" not in err
    return lines[0]


@pytest.mark.parametrize("problem", ["size", "dtype", "gap"])
def test_bad_slices_one_line(capsys, tmp_path, slices, problem):
    src, _ = slices
    if problem == "size":
        tifffile.imwrite(src / "scan_005.tif", np.zeros((24, 30), np.uint16))
    elif problem == "dtype":
        tifffile.imwrite(src / "scan_005.tif", np.zeros((24, 28), np.uint8))
    else:
        (src / "scan_005.tif").unlink()
    rc, _, err = run(capsys, "core", "ingest", src, "-o", tmp_path / "bad.zarr")
    line = _one_error_line(err)
    assert rc == 2 and ("scan_005" in line or "slice 5 is missing" in line)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scan"]


def test_unreachable_scheduler_one_line(capsys, tmp_path, slices, monkeypatch):
    import geoshade.scheduler

    monkeypatch.setattr(geoshade.scheduler, "CONNECT_TIMEOUT_S", 1)
    src, _ = slices
    rc, _, err = run(capsys, "core", "porosity", src, "--select", 0, 10, "-o", tmp_path / "p.png",
                     "--scheduler", "tcp://127.0.0.1:9")
    line = _one_error_line(err)
    assert rc == 2 and "unreachable" in line and not (tmp_path / "p.png").exists()


def test_disk_full_one_line_nothing_claimed_complete(capsys, tmp_path, slices, monkeypatch):
    from zarr.storage import LocalStore

    src, _ = slices
    orig = LocalStore.set

    async def full(self, key, value):
        if "/c/" in key:
            raise OSError(errno.ENOSPC, "No space left on device")
        return await orig(self, key, value)

    monkeypatch.setattr(LocalStore, "set", full)
    rc, _, err = run(capsys, "core", "ingest", src, "-o", tmp_path / "full.zarr")
    line = _one_error_line(err)
    assert rc == 9 and "disk full" in line
    assert not (tmp_path / "full.zarr").exists()


def test_foreign_zarr_store_says_what_is_assumed(capsys, tmp_path):
    import zarr

    z = zarr.open_array(str(tmp_path / "other.zarr"), mode="w", shape=(6, 7, 8), dtype="u1",
                        chunks=(3, 7, 8))
    z[:] = np.arange(6 * 7 * 8, dtype=np.uint8).reshape(6, 7, 8) % 50
    rc, _out, err = run(capsys, "core", "porosity", tmp_path / "other.zarr", "--select", 0, 9,
                       "-o", tmp_path / "p.png")
    assert rc == 0
    assert "without geoshade attributes; assumed spacing 1.0" in err and "origin 0.0" in err


def test_existing_output_one_line(capsys, tmp_path, slices):
    src, _ = slices
    (tmp_path / "x.zarr").mkdir()
    rc, _, err = run(capsys, "core", "ingest", src, "-o", tmp_path / "x.zarr")
    assert rc == 2 and "--overwrite" in _one_error_line(err)


def test_ingest_unreachable_scheduler_writes_nothing(capsys, tmp_path, slices, monkeypatch):
    import geoshade.scheduler

    monkeypatch.setattr(geoshade.scheduler, "CONNECT_TIMEOUT_S", 1)
    src, _ = slices
    rc, _, err = run(capsys, "core", "ingest", src, "-o", tmp_path / "c.zarr", "--scheduler",
                     "tcp://127.0.0.1:9")
    assert rc == 2 and "unreachable" in _one_error_line(err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scan"]
