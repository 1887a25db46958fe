"""Hostile files (issue 25): planted links, budgets before work, files that change or point
elsewhere.

Each case runs the real CLI in a child process (:mod:`tests.hostile`) and asserts the one
clean line, that no file outside the outputs changed or appeared (SHA-256 of every file in the
folder, the planted link's target included) and the child's peak memory. The last test prints
the tried / clean counts of each class (``pytest -s`` shows them).
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np
import pytest

from tests.hostile import RESULTS, changed, one_error_line, record, run, snapshot, summary

LINKS, BUDGETS, CHANGING = "1 planted links", "3 budgets before work", "4 files that change"
SECRET = b"precious: must never be truncated, overwritten or copied\n"


@pytest.fixture
def case(tmp_path):
    """A folder with a small volume ``v.npy`` and a file outside every output."""
    d = tmp_path / "shared"
    d.mkdir()
    np.save(d / "v.npy", np.random.default_rng(0).integers(0, 255, (16, 16, 16)).astype("u1"))
    victim = tmp_path / "victim.txt"
    victim.write_bytes(SECRET)
    return d, victim


def _grid(folder):
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.grdecl_writer import write_grdecl

    write_grdecl(synthetic_grid(4, 3, 2, seed=1), folder / "g.grdecl")
    return folder / "g.grdecl"


# --------------------------------------------------------------------------------------------
# 1. planted links: never followed, never written through
# --------------------------------------------------------------------------------------------
PLANTS = [
    ("core ingest, *.zarr.lock -> victim", "core", "lock", "symlink", "out.zarr.lock"),
    ("core ingest, *.zarr.lock hard link to victim", "core", "lock", "hardlink",
     "has 2 hard links"),
    ("core ingest, *.zarr.partial -> victim", "core", "partial", "symlink", "out.zarr.partial"),
    ("core ingest, *.partial -> a folder", "core", "partial", "dirlink", "symbolic link"),
    ("core ingest, progress file -> victim", "core", "progress", "symlink",
     "progress.json"),
    ("grid ingest, *.zarr.lock -> victim", "grid", "lock", "symlink", "out.zarr.lock"),
    ("grid ingest, *.zarr.partial -> victim", "grid", "partial", "symlink", "out.zarr.partial"),
]


@pytest.mark.parametrize(("name", "part", "where", "how", "needle"), PLANTS,
                         ids=[p[0] for p in PLANTS])
def test_planted_link_is_refused_and_nothing_outside_changes(case, name, part, where, how,
                                                             needle):
    d, victim = case
    target = victim
    if how == "dirlink":
        target = victim.parent / "elsewhere"
        target.mkdir()
        (target / "keep.txt").write_bytes(SECRET)
    plant = d / {"lock": "out.zarr.lock", "partial": "out.zarr.partial",
                 "progress": "out.zarr.partial.progress.json"}[where]
    if how == "hardlink":
        os.link(victim, plant)
    else:
        os.symlink(target, plant)
    src = "v.npy" if part == "core" else _grid(d).name
    before = snapshot(victim.parent)
    r = run(["geoshade", part, "ingest", src, "-o", "out.zarr"], d, timeout=120)
    why = one_error_line(r, needle) or ("" if r.rc == 2 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(victim.parent)))
    why = why or ("" if victim.read_bytes() == SECRET else "the victim changed")
    why = why or ("" if r.maxrss_mb < 1500 else f"{r.maxrss_mb:.0f} MB")
    record(LINKS, name, why, r)


def test_a_planted_link_removed_the_ingest_runs(case):
    """After the refusal, removing the link is all it takes (the lock is made afresh, O_EXCL)."""
    d, victim = case
    os.symlink(victim, d / "out.zarr.lock")
    assert run(["geoshade", "core", "ingest", "v.npy", "-o", "out.zarr"], d).rc == 2
    (d / "out.zarr.lock").unlink()
    r = run(["geoshade", "core", "ingest", "v.npy", "-o", "out.zarr"], d)
    why = "" if r.rc == 0 and (d / "out.zarr").is_dir() else f"exit {r.rc}: {r.lines[-1:]}"
    why = why or ("" if not (d / "out.zarr.lock").exists() else "the lock file was left")
    why = why or ("" if victim.read_bytes() == SECRET else "the victim changed")
    record(LINKS, "ingest after the link is removed", why, r)


def test_lock_fstat_checks_in_process(tmp_path):
    """The lock opened is a regular file, owned, one link: a FIFO in its place is refused
    (no hang), and a lock this user made is reused."""
    from geoshade.errors import InputError
    from geoshade.io.stores.ingest_lock import IngestLock

    os.mkfifo(tmp_path / "c.zarr.lock")
    with pytest.raises(InputError, match=r"c\.zarr\.lock: is not a regular file"):
        IngestLock(tmp_path / "c.zarr").acquire()
    (tmp_path / "c.zarr.lock").unlink()
    with IngestLock(tmp_path / "c.zarr") as lock:
        st = os.lstat(lock.path)
        assert st.st_nlink == 1 and st.st_uid == os.geteuid()
    assert not (tmp_path / "c.zarr.lock").exists()
    record(LINKS, "FIFO in the lock's place (in process)", "")


# --------------------------------------------------------------------------------------------
# 3. budgets before work
# --------------------------------------------------------------------------------------------
@pytest.mark.gl
def test_bricks_planned_before_any_is_built(tmp_path):
    """``--bricks 2`` on a 1.3 MB volume: 166,375 bricks, refused before one is built (it reached
    17.8 GB); the child stays under 1 GB."""
    np.random.default_rng(1).integers(0, 255, (110, 110, 110)).astype("u1").tofile(
        tmp_path / "small.raw")
    before = snapshot(tmp_path)
    r = run(["geoshade", "core", "render", "small.raw", "--shape", "110", "110", "110",
             "--dtype", "uint8", "--bricks", "2", "-o", "s.png", "--size", "64x48"], tmp_path,
            timeout=300)
    why = one_error_line(r, "166,375 bricks", "--bricks") or ("" if r.rc == 2 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    why = why or ("" if r.maxrss_mb < 1024 else f"peak {r.maxrss_mb:.0f} MB")
    record(BUDGETS, "core render --bricks 2 on 1.3 MB", why, r)


def test_brick_budget_counts_exactly():
    """The count planned equals the bricks plan_bricks makes; a whole volume beyond memory and
    one brick beyond it are refused, a fitting plan passes with its host bytes."""
    from geoshade.compute.voxels.bricks import (
        HOST_BYTES_PER_BRICK,
        brick_count,
        check_brick_budget,
        estimate_bytes,
        plan_bricks,
    )
    from geoshade.errors import InputError
    from geoshade.models.volume import Box

    for size, side in [((110, 110, 110), 7), ((300, 70, 41), 64), ((4096, 17, 9), 2048)]:
        box = Box((0, 0, 0), size)
        assert brick_count(box, side) == len(plan_bricks(box, side))
    box = Box((0, 0, 0), (512, 512, 512))
    plan = check_brick_budget(box, 256, "raycast", 2**34)
    assert plan["count"] == 8
    assert plan["host_bytes_per_brick"] == estimate_bytes((256,) * 3, "raycast") + \
        HOST_BYTES_PER_BRICK
    with pytest.raises(InputError, match="whole volume"):
        check_brick_budget(box, 256, "raycast", 2**20, default_box_bytes=512**3)
    with pytest.raises(InputError, match="one brick"):
        check_brick_budget(box, 256, "raycast", 2**20)
    record(BUDGETS, "brick plan counted exactly (in process)", "")


def _include_chain(folder, n=23):
    (folder / "f00.inc").write_text("SPECGRID\n 1 1 1 1 F /\n")
    for i in range(1, n):
        (folder / f"f{i:02d}.inc").write_text(
            f"INCLUDE\n 'f{i - 1:02d}.inc' /\nINCLUDE\n 'f{i - 1:02d}.inc' /\n")
    (folder / "CASE.grdecl").write_text(f"INCLUDE\n 'f{n - 1:02d}.inc' /\n")


def test_include_doubling_is_refused(tmp_path):
    """23 files each including the next twice (2^22 opens from 108 KB) end in one line."""
    _include_chain(tmp_path)
    before = snapshot(tmp_path)
    r = run(["geoshade", "info", "CASE.grdecl"], tmp_path, timeout=120)
    why = one_error_line(r, "f00.inc", "INCLUDEd 65 times") or (
        "" if r.rc == 2 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    why = why or ("" if r.maxrss_mb < 800 else f"peak {r.maxrss_mb:.0f} MB")
    record(BUDGETS, "INCLUDE doubling 2^22", why, r)


def test_include_total_budget_in_process(tmp_path, monkeypatch):
    """The total budget (distinct files, each read once) counts every open."""
    from geoshade.errors import InputError
    from geoshade.io.grids import includes
    from geoshade.io.grids.grdecl import read_grdecl

    monkeypatch.setattr(includes, "MAX_INCLUDE_OPENS", 10)
    (tmp_path / "g0.inc").write_text("SPECGRID\n 1 1 1 1 F /\n")
    for i in range(1, 12):
        (tmp_path / f"g{i}.inc").write_text(f"INCLUDE\n 'g{i - 1}.inc' /\n")
    (tmp_path / "CASE.grdecl").write_text("INCLUDE\n 'g11.inc' /\n")
    with pytest.raises(InputError, match="more than 10 INCLUDE files opened in all"):
        read_grdecl(tmp_path / "CASE.grdecl")
    record(BUDGETS, "INCLUDE total opens (in process)", "")


def _huge_store(folder):
    d = folder / "huge.zarr"
    d.mkdir()
    meta = {"zarr_format": 3, "node_type": "array", "shape": [100000] * 3, "data_type": "uint8",
            "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [64] * 3}},
            "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
            "fill_value": 0, "codecs": [{"name": "bytes", "configuration": {}}],
            "attributes": {}}
    (d / "zarr.json").write_text(json.dumps(meta))
    return d


@pytest.mark.parametrize("cmd", [
    "info", pytest.param("render --sample none", marks=pytest.mark.gl),
    pytest.param("render", marks=pytest.mark.gl),   # the sample detection has a read budget
    "porosity",
])
def test_declared_huge_store(tmp_path, cmd):
    """A 400-byte zarr.json declaring 100000³ voxels: info lists the stored chunks (none) and
    computes no statistics; render refuses the whole volume beyond memory."""
    _huge_store(tmp_path)
    before = snapshot(tmp_path)
    if cmd == "info":
        r = run(["geoshade", "info", "huge.zarr"], tmp_path, timeout=120)
        why = "" if r.rc == 0 and "statistics not computed" in r.out and \
            "3818360547 of 3818360547 chunks are not stored" in r.out else \
            f"exit {r.rc}: {r.lines[-2:]!r}"
    elif cmd == "porosity":   # counted from chunks never written: refused, not crawled
        r = run(["geoshade", "core", "porosity", "huge.zarr", "--select", "0", "0", "-o",
                 "p.png"], tmp_path, timeout=120)
        why = one_error_line(r, "never written", "--box") or ("" if r.rc == 2 else
                                                               f"exit {r.rc}")
    else:
        r = run(["geoshade", "core", "render", "huge.zarr", "-o", "h.png", "--size", "64x48",
                 *cmd.split()[1:]], tmp_path, timeout=200)
        why = one_error_line(r, "whole volume", "--box") or ("" if r.rc in (2, 6) else
                                                             f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    why = why or ("" if r.maxrss_mb < 1024 else f"peak {r.maxrss_mb:.0f} MB")
    record(BUDGETS, f"declared 100000³ store: {cmd}", why, r)


def test_declared_huge_store_read_lazily_counts_by_listing(tmp_path):
    """read_zarr (info, napari's reader) counts stored chunks by listing: two chunk files
    written are counted, never the declared 3.8e9 keys."""
    from geoshade.io.stores.zarr_io import read_zarr

    d = _huge_store(tmp_path)
    for key in ("c/0/0/0", "c/5/1/2"):
        (d / key).parent.mkdir(parents=True, exist_ok=True)
        (d / key).write_bytes(bytes(64**3))
    vol = read_zarr(d)
    notes = " ".join(vol.meta["assumed"])
    assert "3818360545 of 3818360547 chunks are not stored" in notes
    record(BUDGETS, "stored chunks counted by listing (in process)", "")


def test_filter_operands_combined_as_they_go():
    """166 `or` terms at 1e6 cells: the same cells as numpy's, and peak memory of a few
    operands (tracemalloc sees numpy's buffers), not 166."""
    import tracemalloc

    from geoshade.compute.grid.filters import cell_filter

    n = 1_000_000
    p = np.random.default_rng(0).random(n).astype(np.float32)
    cuts = [0.5 + i / 1000 for i in range(166)]
    expr = " or ".join(f"P>{c:g}" for c in cuts)
    tracemalloc.start()
    got = cell_filter(expr, {"P": p}, (n,))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    oracle = np.zeros(n, bool)
    for c in cuts:
        oracle |= p > np.float32(c)
    why = "" if np.array_equal(got, oracle) else "differs from numpy"
    why = why or ("" if peak < 8 * n else f"peak {peak / 2**20:.1f} MiB for {n} cells")
    record(BUDGETS, f"166 or-terms filter memory (peak {peak / 2**20:.1f} MiB)", why)


def test_filter_never_writes_into_a_property():
    """A boolean property used as the first operand is not changed by the in-place or."""
    from geoshade.compute.grid.filters import cell_filter

    flag = np.array([True, False, False, True])
    keep = flag.copy()
    got = cell_filter("F or P > 1", {"F": flag, "P": np.array([0.0, 2.0, 0.0, 0.0])}, (4,))
    why = "" if np.array_equal(flag, keep) else "the property was modified"
    why = why or ("" if got.tolist() == [True, True, False, True] else f"got {got}")
    record(BUDGETS, "filter leaves properties alone", why)


def test_rlimit_as_is_read_with_the_memory_limits(tmp_path):
    """Under ``ulimit -v`` the memory check sees the address-space limit and says so."""
    code = ("from geoshade.io.paths import mem_available, check_memory\n"
            "n = mem_available(); print(n)\n"
            "check_memory(2 * 1024**3, 'big.npy', 'the array')\n")
    r = run([sys.executable, "-c", code], tmp_path, rlimit_as=1536 * 2**20, timeout=120)
    avail = int(r.out.split()[0]) if r.out.split() else -1
    why = "" if 0 < avail < 1536 * 2**20 else f"mem_available {avail} under a 1.5 GiB limit"
    why = why or ("" if "RLIMIT_AS 1.5 GiB" in r.err and "big.npy" in r.err else r.err[-300:])
    record(BUDGETS, "RLIMIT_AS read", why, r)


@pytest.mark.parametrize("limit_mb", [500, 600, 900])
def test_low_ulimit_v_before_a_render_is_one_line(tmp_path, limit_mb):
    """Under ``ulimit -v`` below what llvmpipe and OpenBLAS need (SIGSEGV, an OpenBLAS error
    before): one line naming the limit, no picture, nothing else changed."""
    np.save(tmp_path / "v.npy", np.random.default_rng(0).integers(0, 255, (12, 12, 12))
            .astype("u1"))
    before = snapshot(tmp_path)
    r = run(["geoshade", "core", "render", "v.npy", "-o", "r.png", "--size", "64x48",
             "--select", "0", "100"], tmp_path, rlimit_as=limit_mb * 2**20, timeout=120)
    why = one_error_line(r, "RLIMIT_AS", "raise the limit") or ("" if r.rc in (2, 4, 6) else
                                                                f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    record(BUDGETS, f"core render under ulimit -v {limit_mb} MB", why, r)


# --------------------------------------------------------------------------------------------
# 4. files that change or point elsewhere
# --------------------------------------------------------------------------------------------
SHRINK = """
import os, sys, numpy as np
from geoshade.io import load
f = sys.argv[1]
if f.endswith(".npy"):
    np.save(f, np.zeros((64, 64, 64), "u1"))
    vol = load(f)
else:
    np.zeros((64, 64, 64), "u1").tofile(f)
    vol = load(f, shape=(64, 64, 64), dtype="uint8")
os.truncate(f, 1000)
print(int(np.asarray(vol.data[-1]).sum()))
"""


@pytest.mark.parametrize("name", ["core.raw", "core.npy"])
def test_file_shrunk_while_mapped(tmp_path, name):
    """A mapped file truncated under the reader: one line naming it, exit 74 (was SIGBUS)."""
    r = run([sys.executable, "-c", SHRINK, name], tmp_path, timeout=120)
    why = one_error_line(r, name, "shrank while it was read") or (
        "" if r.rc == 74 else f"exit {r.rc}")
    record(CHANGING, f"{name} shrinks while mapped", why, r)


def _h5(folder):
    h5py = pytest.importorskip("h5py")
    (folder / "elsewhere").mkdir()
    (folder / "elsewhere" / "secret.bin").write_bytes(SECRET[:120].ljust(120, b"!"))
    d = folder / "in"
    d.mkdir()
    with h5py.File(d / "ext.h5", "w") as h:
        h.create_dataset("data", shape=(4, 5, 6), dtype="u1",
                         external=[("../elsewhere/secret.bin", 0, 120)])
    with h5py.File(folder / "elsewhere" / "src.h5", "w") as h:
        h.create_dataset("data", data=np.ones((4, 5, 6), "u1"))
    layout = h5py.VirtualLayout(shape=(4, 5, 6), dtype="u1")
    layout[:] = h5py.VirtualSource("../elsewhere/src.h5", "data", shape=(4, 5, 6))
    with h5py.File(d / "virt.h5", "w") as h:
        h.create_virtual_dataset("data", layout)
    os.mkfifo(d / "pipe.bin")
    with h5py.File(d / "fifo.h5", "w") as h:
        h.create_dataset("data", shape=(4, 5, 6), dtype="u1", external=[("pipe.bin", 0, 120)])
    return d


H5_CASES = [("ext.h5", "info", "secret.bin"), ("ext.h5", "ingest", "secret.bin"),
            ("ext.h5", "render", "secret.bin"), ("virt.h5", "info", "src.h5"),
            ("virt.h5", "ingest", "src.h5"), ("fifo.h5", "info", "pipe.bin"),
            ("fifo.h5", "ingest", "pipe.bin")]


@pytest.mark.parametrize(("name", "cmd", "outside"), H5_CASES,
                         ids=[f"{a}-{b}" for a, b, _ in H5_CASES])
def test_hdf5_data_in_other_files_refused(tmp_path, name, cmd, outside):
    """External storage and virtual datasets are refused, naming the outside file: nothing is
    drawn, no store copies it, a FIFO does not hang the reader."""
    d = _h5(tmp_path)
    argv = {"info": ["geoshade", "info", name],
            "ingest": ["geoshade", "core", "ingest", name, "-o", "copy.zarr"],
            "render": ["geoshade", "core", "render", name, "-o", "x.png", "--size", "64x48",
                       "--select", "0", "255"]}[cmd]
    before = snapshot(tmp_path)
    r = run(argv, d, timeout=120)
    why = one_error_line(r, name, outside, "other files") or ("" if r.rc == 2 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    record(CHANGING, f"HDF5 {name} {cmd}", why, r)


def test_zz_counts():
    """The tried / clean table of this file's classes (``pytest -s`` prints it)."""
    for cls in (LINKS, BUDGETS, CHANGING):
        if cls in RESULTS:
            print(summary(cls))
            assert all(ok for _, ok, _ in RESULTS[cls]), summary(cls)
