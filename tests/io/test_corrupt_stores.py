"""Issue 12, class 7: damaged zarr stores, ``core verify``, and one ingest at a time per store.

A seeded raw volume is ingested into a two-level store; damaged copies of it (chunks deleted,
swapped, truncated, flipped, replaced by a folder; ``zarr.json`` files emptied, broken, edited to
another dtype, shape or chunk shape, stripped of their checksum record or ingest record) are run
through ``geoshade info``, ``core porosity``, ``core verify`` and ``core ingest``.  Each must fail
cleanly (:func:`tests.corruption.clean_failure`) naming the store (and the chunk or array), and
never read a lost chunk as zeros: the porosity of a store with a missing chunk is an error.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading

import numpy as np
import pytest
import zarr

from tests.corruption import Tally, listing, run_cli

SEED = 707
TALLY = Tally("zarr stores")
SHAPE = (16, 10, 12)  # (nz, ny, nx)
CHUNKS = (4, 5, 6)


def _volume() -> np.ndarray:
    a = np.random.default_rng(SEED).integers(1, 200, SHAPE).astype(np.uint8)
    a[:4] = 0  # a row of all-zero chunks: stored too, so that losing one is seen
    return a


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    from geoshade.io.stores.ingest import ingest

    d = tmp_path_factory.mktemp("store")
    _volume().tofile(d / "v.raw")
    nz, ny, nx = SHAPE
    ingest(d / "v.raw", d / "v.zarr", chunks=CHUNKS, levels=2, shape=(nx, ny, nz),
           dtype="uint8", spacing=(0.5, 0.5, 0.5), unit="um")
    return d / "v.zarr"


def _copy(store, tmp_path, tag: str):
    d = tmp_path / tag
    d.mkdir()
    shutil.copytree(store, d / store.name)
    return d / store.name


_clean = TALLY.clean_failure


def _commands(p, tmp_path):
    return [["info", p], ["core", "porosity", p, "--select", 0, 80, "-o", tmp_path / "p.png"],
            ["core", "verify", p], ["core", "ingest", p, "-o", tmp_path / "again.zarr"]]


def _all_fail(capsys, p, tmp_path, expect=None):
    lines = [_clean(capsys, argv, [p], [tmp_path], names=p.name, expect=expect)
             for argv in _commands(p, tmp_path)]
    assert not (tmp_path / "again.zarr.partial").exists()
    return lines


def _chunk_files(p, level="0"):
    return sorted(f for f in (p / level / "c").rglob("*") if f.is_file())


# --- chunks ----------------------------------------------------------------------------------
def test_good_store_reads_and_verifies(store, capsys):
    rc, out, err = run_cli(capsys, ["core", "verify", store])
    assert rc == 0 and "18 chunks of 2 level(s) (0, 1) match their CRC-32" in out, err
    files = _chunk_files(store)
    assert len(files) == 16  # all-zero chunks are stored too
    rc, out, _ = run_cli(capsys, ["core", "porosity", store, "--select", 0, 80, "-o",
                                  store.parent / "ok.png"])
    assert rc == 0
    (store.parent / "ok.png").unlink()


def test_missing_chunk_is_an_error_never_zeros(store, tmp_path, capsys):
    from geoshade import core
    from geoshade.io import load
    from geoshade.io.stores.chunks import DamagedStoreError

    rng = np.random.default_rng(SEED)
    files = _chunk_files(store)
    picks = {0, len(files) - 1, *rng.integers(0, len(files), 3).tolist()}  # chunk 0 is zeros
    for k in sorted(picks):
        p = _copy(store, tmp_path, f"miss{k}")
        rel = files[k].relative_to(store)
        (p / rel).unlink()
        for line in _all_fail(capsys, p, tmp_path):
            assert f"chunk {rel}" in line and "missing" in line
        with pytest.raises(DamagedStoreError, match="is missing"):
            core.porosity(load(p), (0, 80))
        TALLY(True)


@pytest.mark.parametrize("damage", ["swap", "flip", "truncate", "empty", "folder", "garbage"])
def test_damaged_chunk(damage, store, tmp_path, capsys):
    rng = np.random.default_rng(SEED + len(damage))
    files = _chunk_files(store)
    for k in sorted(set(rng.integers(0, len(files), 3).tolist())):
        p = _copy(store, tmp_path, f"{damage}{k}")
        rel = files[k].relative_to(store)
        f = p / rel
        data = f.read_bytes()
        if damage == "swap":  # a valid chunk with other values
            other = files[(k + 5) % len(files)]
            f.write_bytes(other.read_bytes())
            if other.read_bytes() == data:
                continue
        elif damage == "flip":
            b = bytearray(data)
            b[int(rng.integers(4, len(b)))] ^= 0x41
            f.write_bytes(bytes(b))
        elif damage == "truncate":
            f.write_bytes(data[: int(rng.integers(1, len(data)))])
        elif damage == "empty":
            f.write_bytes(b"")
        elif damage == "folder":
            f.unlink()
            f.mkdir()
        else:
            f.write_bytes(rng.integers(0, 256, 64).astype(np.uint8).tobytes())
        for line in _all_fail(capsys, p, tmp_path):
            assert f"chunk {rel}" in line, line


def test_level_one_damage_is_found(store, tmp_path, capsys):
    from geoshade.io.stores.chunks import DamagedStoreError
    from geoshade.io.stores.zarr_io import read_level

    p = _copy(store, tmp_path, "lvl1")
    _chunk_files(p, "1")[0].unlink()
    line = _clean(capsys, ["core", "verify", p], [p], [tmp_path])
    assert "chunk 1/c/0/0/0 is missing" in line
    with pytest.raises(DamagedStoreError, match="chunk 1/c/0/0/0 is missing"):
        read_level(p, 1).read_box()
    TALLY(True)


# --- metadata --------------------------------------------------------------------------------
def _edit(path, fn):
    meta = json.loads(path.read_text())
    fn(meta)
    path.write_text(json.dumps(meta))


META_DAMAGE = {
    "group {}": ("zarr.json", lambda f: f.write_text("{}"), "lost its ingest record"),
    "group deleted": ("zarr.json", lambda f: f.unlink(), "metadata are missing"),
    "group broken": ("zarr.json", lambda f: f.write_text(f.read_text()[:200]), "JSONDecodeError"),
    "group binary": ("zarr.json", lambda f: f.write_bytes(b"\xff\xfe\0\0" * 8), "zarr store"),
    "incomplete": ("zarr.json", lambda f: _edit(f, lambda m: m["attributes"]["ingest"].update(
        complete=False)), "incomplete store"),
    "ingest junk": ("zarr.json", lambda f: _edit(f, lambda m: m["attributes"].update(
        ingest="junk")), "'ingest' attribute is damaged"),
    "multiscales junk": ("zarr.json", lambda f: _edit(f, lambda m: m["attributes"]["ome"].update(
        multiscales=[{"datasets": 5}])), "multiscales"),
    "array {}": ("0/zarr.json", lambda f: f.write_text("{}"), "array 0"),
    "array deleted": ("0/zarr.json", lambda f: f.unlink(), "0"),
    "array broken": ("0/zarr.json", lambda f: f.write_text(f.read_text()[:300]), "array 0"),
    "dtype uint16": ("0/zarr.json", lambda f: _edit(f, lambda m: m.update(data_type="uint16")),
                     "uint16"),
    "dtype int8": ("0/zarr.json", lambda f: _edit(f, lambda m: m.update(data_type="int8")),
                   "int8"),
    "dtype float32": ("0/zarr.json", lambda f: _edit(f, lambda m: m.update(
        data_type="float32")), "float32"),
    "dtype junk": ("0/zarr.json", lambda f: _edit(f, lambda m: m.update(data_type="banana")),
                   "banana"),
    "shape": ("0/zarr.json", lambda f: _edit(f, lambda m: m.update(shape=[16, 10, 13])),
              "array 0"),
    "chunk shape": ("0/zarr.json", lambda f: _edit(f, lambda m: m["chunk_grid"][
        "configuration"].update(chunk_shape=[4, 5, 12])), "array 0"),
    "codecs": ("0/zarr.json", lambda f: _edit(f, lambda m: m.update(codecs=[{"name": "bytes"}])),
               "is damaged ("),
    "no checksums": ("0/zarr.json", lambda f: _edit(f, lambda m: m["attributes"].pop(
        "checksums")), "checksum record is missing"),
    "checksums short": ("0/zarr.json", lambda f: _edit(f, lambda m: m["attributes"][
        "checksums"].update(crc32=[1, 2, 3])), "damaged checksum record"),
    "checksums junk": ("0/zarr.json", lambda f: _edit(f, lambda m: m["attributes"].update(
        checksums="junk")), "damaged checksum record"),
}


@pytest.mark.parametrize("case", list(META_DAMAGE))
def test_damaged_metadata(case, store, tmp_path, capsys):
    rel, damage, expect = META_DAMAGE[case]
    p = _copy(store, tmp_path, "meta")
    damage(p / rel)
    for line in _all_fail(capsys, p, tmp_path):
        assert expect in line, line
        assert "\n" not in line


def test_unfinished_store_without_its_group_record_is_still_unfinished(store, tmp_path,
                                                                       capsys):
    """An ingest marks its arrays as pending until the end: a renamed .partial whose group
    zarr.json became {} is refused as incomplete, not read with unwritten chunks as zeros."""
    p = _copy(store, tmp_path, "pending")
    (p / "zarr.json").write_text("{}")
    for level in ("0", "1"):
        _edit(p / level / "zarr.json", lambda m: m["attributes"].update(checksums="pending"))
    for line in _all_fail(capsys, p, tmp_path):
        assert "incomplete store" in line, line


def test_flipped_metadata_bytes_never_crash(store, tmp_path, capsys):
    """A flipped byte in a zarr.json may leave valid JSON that says something else (a digit of
    the spacing): then exit 0; otherwise a clean failure."""
    rng = np.random.default_rng(SEED + 3)
    for rel in ("zarr.json", "0/zarr.json"):
        size = (store / rel).stat().st_size
        for k, pos in enumerate(sorted(set(rng.integers(0, size, 6).tolist()))):
            p = _copy(store, tmp_path, f"flip{rel[0]}{k}")
            b = bytearray((p / rel).read_bytes())
            b[pos] ^= 0x20 if chr(b[pos]).isalpha() else 0x41
            (p / rel).write_bytes(bytes(b))
            rc, _, err = run_cli(capsys, ["info", p])
            if rc == 0:
                TALLY("Traceback" not in err)
                continue
            _clean(capsys, ["info", p], [p], [tmp_path])


# --- stores geoshade did not write -----------------------------------------------------------
def test_foreign_store_missing_chunks_are_said_not_hidden(tmp_path, capsys):
    z = zarr.open_array(str(tmp_path / "f.zarr"), mode="w", shape=(4, 4, 4), chunks=(2, 2, 2),
                        dtype="u1")
    z[:2] = 5  # zarr stores no chunk for the zeros
    rc, _out, err = run_cli(capsys, ["core", "porosity", tmp_path / "f.zarr", "--select", 1, 9,
                                    "-o", tmp_path / "p.png"])
    assert rc == 0
    assert "4 of 8 chunks are not stored and read as the fill value 0" in err
    # a damaged chunk of a foreign store is still one line naming it
    f = tmp_path / "f.zarr" / "c" / "0" / "0" / "0"
    f.write_bytes(f.read_bytes()[:5])
    line = _clean(capsys, ["info", tmp_path / "f.zarr"], [tmp_path / "f.zarr"], [tmp_path],
                  names="f.zarr")
    assert "chunk c/0/0/0 is damaged" in line
    rc, _out, _ = run_cli(capsys, ["core", "verify", tmp_path / "f.zarr"])
    assert rc != 0


def test_write_zarr_stores_are_verified_too(tmp_path, capsys):
    from geoshade.io.stores.zarr_io import write_zarr
    from geoshade.models import VoxelVolume

    p = write_zarr(VoxelVolume(_volume()), tmp_path / "w.zarr", chunks=CHUNKS)
    assert len(list((p / "c").rglob("*"))) >= 16
    next(f for f in (p / "c").rglob("*") if f.is_file()).unlink()
    line = _clean(capsys, ["core", "porosity", p, "--select", 0, 80, "-o", tmp_path / "p.png"],
                  [p], [tmp_path])
    assert "is missing" in line


# --- the ingest lock -------------------------------------------------------------------------
def _src(tmp_path):
    f = tmp_path / "src.raw"
    _volume().tofile(f)
    nz, ny, nx = SHAPE
    return f, ("--shape", nx, ny, nz, "--dtype", "uint8", "--chunks", *CHUNKS, "--levels", 1)


def test_second_ingest_into_the_same_store_refuses_and_leaves_nothing(tmp_path, capsys,
                                                                     monkeypatch):
    import geoshade.io.stores.ingest as ing
    from geoshade.io.stores.zarr_io import verify_store

    src, args = _src(tmp_path)
    out = tmp_path / "c.zarr"
    started, go = threading.Event(), threading.Event()
    real = ing._write_slab

    def slow(*a):
        started.set()
        assert go.wait(30)
        return real(*a)

    monkeypatch.setattr(ing, "_write_slab", slow)
    nz, ny, nx = SHAPE
    result: dict = {}

    def first():
        try:
            result["report"] = ing.ingest(src, out, chunks=CHUNKS, levels=1, shape=(nx, ny, nz),
                                          dtype="uint8")
        except BaseException as err:  # reported below
            result["error"] = err

    t = threading.Thread(target=first)
    t.start()
    try:
        assert started.wait(30)
        line = _clean(capsys, ["core", "ingest", src, "-o", out, *args], [src, out.parent],
                      [tmp_path], names="c.zarr",
                      expect=f"another ingest is writing c.zarr (pid {os.getpid()}")
        assert "\n" not in line
    finally:
        go.set()
        t.join(60)
    assert "error" not in result, result
    assert verify_store(out)["chunks"] == 16
    assert sorted(q.name for q in tmp_path.iterdir()) == ["c.zarr", "src.raw"]


_HOLD = r"""
import sys, time
from geoshade.io.stores.ingest_lock import IngestLock
with IngestLock(sys.argv[1]):
    print("held", flush=True)
    time.sleep(60)
"""


def test_lock_held_by_another_process(tmp_path, capsys):
    src, args = _src(tmp_path)
    out = tmp_path / "c.zarr"
    proc = subprocess.Popen([sys.executable, "-c", _HOLD, str(out)], stdout=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout.readline().strip() == "held"
        _clean(capsys, ["core", "ingest", src, "-o", out, *args], [src], [tmp_path],
               names="c.zarr", expect=f"(pid {proc.pid}")
    finally:
        proc.kill()
        proc.wait()
    rc, _, err = run_cli(capsys, ["core", "ingest", src, "-o", out, *args])  # the kernel freed it
    assert rc == 0, err
    assert not (tmp_path / "c.zarr.lock").exists()


def test_stale_lock_of_a_dead_process_is_taken_over(tmp_path, capsys):
    from geoshade.io.stores.ingest import ingest

    src, _ = _src(tmp_path)
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    lock = tmp_path / "c.zarr.lock"
    lock.write_text(json.dumps({"pid": int(dead), "host": "here", "since": "earlier"}))
    nz, ny, nx = SHAPE
    rep = ingest(src, tmp_path / "c.zarr", chunks=CHUNKS, levels=1, shape=(nx, ny, nz),
                 dtype="uint8")
    assert any(f"pid {dead}" in n and "took over" in n for n in rep.notes), rep.notes
    assert not lock.exists()
    TALLY(True)


def test_two_ingests_at_once_one_store(tmp_path):
    """Both start together: one writes the store, the other stops with one line; no .partial,
    no lock file is left."""
    from geoshade.errors import GeoshadeError
    from geoshade.io.stores.ingest import ingest
    from geoshade.io.stores.zarr_io import verify_store

    src, _ = _src(tmp_path)
    nz, ny, nx = SHAPE
    barrier = threading.Barrier(2)
    outcome: list = []

    def run():
        barrier.wait()
        try:
            ingest(src, tmp_path / "c.zarr", chunks=(1, 5, 6), levels=2, shape=(nx, ny, nz),
                   dtype="uint8")
            outcome.append("ok")
        except GeoshadeError as err:
            outcome.append(str(err))

    threads = [threading.Thread(target=run) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert outcome.count("ok") == 1, outcome
    msg = next(o for o in outcome if o != "ok")
    assert "another ingest is writing c.zarr" in msg or "already exists" in msg, msg
    assert verify_store(tmp_path / "c.zarr")["checksums"]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["c.zarr", "src.raw"]
    TALLY(True)


def test_failed_fresh_ingest_leaves_nothing(tmp_path, capsys):
    """A damaged input found half-way: the new partial store is removed (nothing to resume)."""
    import tifffile

    d = tmp_path / "slices"
    d.mkdir()
    for z in range(6):
        tifffile.imwrite(d / f"s_{z}.tif", _volume()[z], compression="zlib")
    f = d / "s_5.tif"
    with tifffile.TiffFile(f) as tf:
        off = int(tf.pages[0].dataoffsets[0])
    b = bytearray(f.read_bytes())
    b[off + 3] ^= 0xFF
    f.write_bytes(bytes(b))
    seen = listing([tmp_path])
    line = _clean(capsys, ["core", "ingest", d, "-o", tmp_path / "new" / "c.zarr", "--chunks",
                           2, 10, 12], [d], [tmp_path], names="s_5.tif")
    assert "damaged TIFF image data" in line
    assert listing([tmp_path]) == seen  # not even the folder 'new'


def test_zz_report():
    print(TALLY)
    assert TALLY.clean == TALLY.tried
