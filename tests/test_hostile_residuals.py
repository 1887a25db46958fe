"""Hostile round 4 (issue 32, item 5): the residuals — no signal, no hang, no traceback.

Each case runs the real CLI in a child process (:mod:`tests.hostile`: one ``geoshade: error:``
line, nothing outside the outputs changed, peak memory) or, where a child cannot reach it, the
function in process; oracles are numpy arrays, the files written and the counts planted.
``pytest -s`` prints the tried / clean table of each class.
"""

from __future__ import annotations

import datetime
import errno
import json
import os
import resource
import signal
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from geoshade.errors import InputError
from tests.hostile import RESULTS, changed, one_error_line, record, run, snapshot, summary

CRASH, LIMITS, NAMES, VALUES, CLUSTER = (
    "1 signals and hangs", "2 limits with their figure", "3 every message names its file",
    "4 bad values said", "5 not a scheduler")
ESC = "\x1b]52;c;cHduZWQ=\x07\x1b]0;title\x07"  # clipboard write, window title


@pytest.fixture
def folder(tmp_path):
    """A folder with a 32³ volume, a labelled 8³ volume and a 20×15×6 GRDECL grid."""
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.grdecl_writer import write_grdecl

    rng = np.random.default_rng(0)
    np.save(tmp_path / "v.npy", rng.integers(0, 255, (32, 32, 32)).astype("u1"))
    np.save(tmp_path / "lab.npy", rng.integers(0, 5, (8, 8, 8)).astype("i2"))
    write_grdecl(synthetic_grid(20, 15, 6, seed=1), tmp_path / "g.grdecl")
    return tmp_path


def _clean(r, rc: int, *needles: str) -> str:
    return one_error_line(r, *needles) or ("" if r.rc == rc else f"exit {r.rc}")


# --------------------------------------------------------------------------------------------
# 1. signals and hangs
# --------------------------------------------------------------------------------------------
@pytest.mark.gl
def test_small_bricks_beyond_memory_refused(tmp_path):
    """``--bricks 12`` on a 110³ volume: 1,960 resident bricks (~9.6 GiB of host memory), under
    a 3 GB address space; was SIGSEGV (or "LLVM ERROR" and SIGABRT at 6 GB)."""
    np.random.default_rng(1).integers(0, 255, (110, 110, 110)).astype("u1").tofile(
        tmp_path / "small.raw")
    before = snapshot(tmp_path)
    r = run(["geoshade", "core", "render", "small.raw", "--shape", "110", "110", "110",
             "--dtype", "uint8", "--bricks", "12", "-o", "s.png", "--size", "320x240"],
            tmp_path, timeout=300, rlimit_as=3 << 30)
    why = _clean(r, 2, "bricks 12", "1,960 bricks", "--bricks 16")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    why = why or ("" if r.maxrss_mb < 1500 else f"peak {r.maxrss_mb:.0f} MB")
    record(CRASH, "core render --bricks 12 on 110³ under 3 GB", why, r)


def test_resident_bricks_checked_in_process():
    """The host memory of resident bricks is counted as planned; streamed bricks are not."""
    from geoshade.compute.voxels.bricks import (
        HOST_BYTES_PER_BRICK,
        brick_count,
        check_resident,
        estimate_bytes,
        plan_bricks,
    )
    from geoshade.models.volume import Box

    box = Box((0, 0, 0), (110, 110, 110))
    need = sum(estimate_bytes(b.size, "raycast") + HOST_BYTES_PER_BRICK
               for b in plan_bricks(box, 16))
    assert brick_count(box, 16) == 343
    check_resident(box, 16, "raycast", None, need + 343 * 2**20)   # fits: nothing said
    with pytest.raises(InputError, match="343 bricks") as info:
        check_resident(box, 16, "raycast", None, need // 2)
    assert "--bricks" in str(info.value) and "\n" not in str(info.value)
    check_resident(box, 16, "raycast", 1, need // 2)   # streamed: one brick at a time
    record(CRASH, "resident bricks' host memory (in process)", "")


@pytest.mark.parametrize("mib", [400, 800])
def test_render_under_an_address_space_limit(folder, mib):
    """``core render`` under ``ulimit -v``: one line with the figure, exit 6 (800 MiB hung in
    scipy's OpenBLAS loader; 400 MiB had no figure)."""
    before = snapshot(folder)
    r = run(["geoshade", "core", "render", "v.npy", "-o", "o.png", "--size", "64x48"], folder,
            timeout=120, rlimit_as=mib << 20)
    why = _clean(r, 6, f"{mib} MiB", "ulimit -v")
    why = why or ", ".join(changed(before, snapshot(folder)))
    record(LIMITS, f"core render under ulimit -v {mib} MiB", why, r)


@pytest.mark.parametrize("cmd", [["info", "v.npy"], ["grid", "ingest", "g.grdecl", "-o",
                                                      "g.zarr"]])
def test_other_commands_under_400_mib(folder, cmd):
    r = run(["geoshade", *cmd], folder, timeout=120, rlimit_as=400 << 20)
    why = "" if r.rc == 0 and not [ln for ln in r.lines if "error" in ln] else \
        _clean(r, 6, "400 MiB", "ulimit -v")
    record(LIMITS, f"{' '.join(cmd[:2])} under ulimit -v 400 MiB", why, r)


def test_address_space_settings_only_under_a_limit(tmp_path):
    """Under a limit the CLI asks for one BLAS thread before numpy loads; without one, nothing."""
    code = ("import os; from geoshade.cli.main import _fit_address_space; _fit_address_space();"
            " print(os.environ.get('OPENBLAS_NUM_THREADS'))")
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    out = {}
    for name, limit in (("limit", 2 << 30), ("none", None)):

        def cap(lim=limit):
            if lim is not None:
                resource.setrlimit(resource.RLIMIT_AS, (lim, lim))

        r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, text=True,
                           capture_output=True, timeout=60, preexec_fn=cap)
        out[name] = r.stdout.strip()
    why = "" if out == {"limit": "1", "none": "None"} else repr(out)
    record(LIMITS, "one BLAS thread under a limit only (in a child)", why)


def test_napari_reader_refuses_a_declared_huge_plane(tmp_path):
    """A 400-byte zarr.json declaring 100000³ voxels: refused before napari reads a plane."""
    from geoshade.napari._reader import get_reader

    d = tmp_path / "huge.zarr"
    d.mkdir()
    (d / "zarr.json").write_text(json.dumps({
        "zarr_format": 3, "node_type": "array", "shape": [100000] * 3, "data_type": "uint8",
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [64] * 3}},
        "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
        "fill_value": 0, "codecs": [{"name": "bytes", "configuration": {}}], "attributes": {}}))
    reader = get_reader(str(d))
    with pytest.raises(InputError) as info:
        reader(str(d))
    text = str(info.value)
    why = "" if "huge.zarr" in text and "100000×100000" in text and "\n" not in text else text
    record(CRASH, "napari reader on 1e15 declared voxels (in process)", why)


def test_napari_reader_keeps_fitting_stores_lazy(tmp_path):
    from geoshade.io.stores.zarr_io import write_zarr
    from geoshade.models import VoxelVolume
    from geoshade.napari._reader import layer_data

    a = np.random.default_rng(2).integers(0, 255, (6, 5, 4)).astype("u1")
    write_zarr(VoxelVolume(a), tmp_path / "s.zarr")
    [(data, _kw, kind)] = layer_data(tmp_path / "s.zarr")
    why = "" if kind == "image" and np.array_equal(np.asarray(data), a) else "data differs"
    record(CRASH, "napari reader: a small store as before (in process)", why)


def test_raw_truncated_while_ingested(tmp_path):
    """The raw file is cut to 4 KiB once the ingest has written its first slabs: one line naming
    the file (was "cannot reshape array of size 4096 into shape (128,512,512)")."""
    raw = tmp_path / "big.raw"
    np.random.default_rng(3).integers(0, 255, (256, 512, 512), dtype=np.uint8).tofile(raw)

    def cut(proc):
        mark = tmp_path / "big.zarr.partial.progress.json"
        t0 = time.monotonic()
        while not mark.exists() and proc.poll() is None and time.monotonic() - t0 < 120:
            time.sleep(0.002)
        os.truncate(raw, 4096)

    r = run(["geoshade", "core", "ingest", "big.raw", "--shape", "512", "512", "256", "--dtype",
             "uint8", "-o", "big.zarr"], tmp_path, timeout=300, on_start=cut)
    why = _clean(r, 2, "big.raw", "truncated")
    why = why or ("" if not (tmp_path / "big.zarr").exists() else "a store was published")
    record(CRASH, "raw truncated during core ingest", why, r)


def test_truncated_slab_read_in_process(tmp_path):
    from geoshade.io.stores.ingest import _read

    f = tmp_path / "v.raw"
    np.arange(4 * 8 * 8, dtype=np.uint8).tofile(f)
    mm = np.memmap(f, np.uint8, "r", shape=(4, 8, 8))
    assert np.array_equal(_read(mm, (slice(0, 2),)), np.asarray(mm[0:2]))
    os.truncate(f, 100)
    with pytest.raises(InputError) as info:
        _read(mm, (slice(2, 4),))
    why = "" if "v.raw" in str(info.value) and "byte 256" in str(info.value) else str(info.value)
    record(CRASH, "slab of a truncated raw (in process)", why)


# --------------------------------------------------------------------------------------------
# 3. every message names its file; escapes from files never reach a terminal or a picture
# --------------------------------------------------------------------------------------------
def test_escapes_escaped_in_a_pipe(folder):
    """``info`` piped (``| less -R``, ``| tee`` end on a terminal): fault names escaped."""
    g = (folder / "g.grdecl").read_text() + f"\nFAULTS\n'F{ESC}' 3 3 1 5 1 6 I /\n/\n"
    (folder / "evil.grdecl").write_text(g)
    r = run(["geoshade", "info", "evil.grdecl"], folder, timeout=120)
    why = "" if r.rc == 0 and "F\\x1b]52;c;" in r.out else f"exit {r.rc}: {r.out[-200:]!r}"
    why = why or ("" if "\x1b" not in r.out and "\x07" not in r.out else "an escape on stdout")
    record(NAMES, "fault name with escapes through a pipe", why, r)


def test_picture_text_from_files(tmp_path):
    """Titles, legends, colour bars, labels: control characters drawn escaped, ``$…$`` as text
    (a well named ``W$\\foo$`` raised in matplotlib's mathtext)."""
    from geoshade.styles.annotate import Annotations, ColorBar, Label, Legend, annotate
    from geoshade.styles.palette import palette

    img = np.full((240, 320, 4), 255, np.uint8)
    for name in (f"W{ESC}", "W$\\foo$"):
        ann = Annotations(title=name, subtitle=name, labels=(Label(name, 100, 100),),
                          legend=Legend(name, ((name, (255, 0, 0, 255)),)),
                          colorbar=ColorBar(name, 0, 1, palette("viridis"), unit=name))
        out, layout = annotate(img, ann)
        texts = [t["text"] for t in layout["title"]] + [t["text"] for t in layout["labels"]] + [
            layout["legend"]["entries"][0]["text"], layout["colorbar"]["label"]]
        why = "" if out.shape == img.shape and not any(
            "\x1b" in t or "\x07" in t for t in texts) else f"{name!r}: {texts!r}"
        why = why or ("" if all("W" in t for t in texts) else f"{texts!r}")
        record(NAMES, f"picture text {name[:4]!r}… (in process)", why)


def test_summary_plot_names_as_text(tmp_path):
    from geoshade.models.summary_vectors import SummaryTable, SummaryVector
    from geoshade.styles.summary_plot import SummaryPlot

    vec = SummaryVector(f"WBHP:W$\\x${ESC}", "WBHP", "well", "BARSA", f"W$\\x${ESC}")
    table = SummaryTable(np.arange(1, 6) * 30.0, np.arange(5, dtype=np.float32)[:, None],
                         [vec], datetime.datetime(2001, 1, 1), name="CASE.SMSPEC")
    plot = SummaryPlot(table, size=(400, 300))
    img = plot.draw()
    texts = [t for lg in plot.layout["legend"] for t in lg["texts"]]
    why = "" if img.shape == (300, 400, 4) and texts and not any("\x1b" in t for t in texts) \
        else repr(texts)
    record(NAMES, "summary plot line named with $ and escapes (in process)", why)


def _disk_full(folder, monkeypatch, capsys) -> tuple:
    """``grid export`` into a full file system: a 64 KiB tmpfs where root may mount one, else a
    writer that fails with ENOSPC in process."""
    tiny = folder / "tiny"
    tiny.mkdir()
    mounted = os.geteuid() == 0 and subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(tiny)],
        capture_output=True).returncode == 0
    try:
        if mounted:
            r = run(["geoshade", "grid", "export", "g.grdecl", "-o", "tiny/out.grdecl"], folder,
                    timeout=120)
            return r.rc, r.err, r
        import geoshade.grid.export as export
        from geoshade.cli.main import main

        def full(*a, **k):
            raise OSError(errno.ENOSPC, "No space left on device")

        monkeypatch.setattr(export, "write_grdecl", full)
        monkeypatch.chdir(folder)
        rc = main(["grid", "export", "g.grdecl", "-o", "tiny/out.grdecl"])
        return rc, capsys.readouterr().err, None
    finally:
        if mounted:
            subprocess.run(["umount", str(tiny)], capture_output=True)


def test_disk_full_names_the_output(folder, monkeypatch, capsys):
    rc, err, r = _disk_full(folder, monkeypatch, capsys)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    why = "" if rc == 74 and len(lines) == 1 and "tiny/out.grdecl: no space left on device" in \
        lines[0] else f"exit {rc}: {lines!r}"
    why = why or ("" if not list((folder / "tiny").iterdir()) else "a file was left")
    record(NAMES, "disk full during grid export", why, r)


@pytest.mark.parametrize(("cmd", "needles"), [
    (["core", "render", "g.grdecl"], ["g.grdecl", "expected a VoxelVolume"]),
    (["stacks", "render", "g.grdecl"], ["g.grdecl", "labelled voxel volume"]),
    (["stacks", "render", "lab.npy", "--hide", "99"], ["lab.npy", "unknown material code 99"]),
], ids=["core render a grid", "stacks render a grid", "stacks --hide unknown code"])
def test_wrong_kind_and_codes_name_the_file(folder, cmd, needles):
    r = run(["geoshade", *cmd, "-o", "x.png", "--size", "64x48"], folder, timeout=120,
            env={"GEOSHADE_GL": "off"})   # refused before any GL
    record(NAMES, " ".join(cmd), _clean(r, 2, *needles), r)


def test_codes_missing_from_the_legend_name_the_model():
    from geoshade.models.stacks import Legend, StackModel

    with pytest.raises(InputError) as info:
        StackModel([0, 1], [0], [7], (1, 1), 4, legend=Legend.from_codes([1, 2]),
                   name="m.stacks.npz")
    text = str(info.value)
    why = "" if text.startswith("m.stacks.npz: material codes [7]") else text
    record(NAMES, "codes missing from the legend (in process)", why)


def test_second_grid_ingest_refused(tmp_path):
    """Two ``grid ingest`` into one store: the second is refused in one line while the first
    writes, the first completes and its store holds the grid's values."""
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io import load
    from geoshade.io.grids.grdecl_writer import write_grdecl

    grid = synthetic_grid(60, 50, 20, seed=1)
    write_grdecl(grid, tmp_path / "big.grdecl")
    first = subprocess.Popen([sys.executable, "-m", "geoshade.cli.main", "grid", "ingest",
                              "big.grdecl", "-o", "same.zarr"], cwd=tmp_path,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    lock = tmp_path / "same.zarr.lock"
    t0 = time.monotonic()
    while not lock.exists() and first.poll() is None and time.monotonic() - t0 < 120:
        time.sleep(0.005)
    os.kill(first.pid, signal.SIGSTOP)   # held while it writes: the second meets its lock
    try:
        r = run(["geoshade", "grid", "ingest", "big.grdecl", "-o", "same.zarr", "--overwrite"],
                tmp_path, timeout=300)
    finally:
        os.kill(first.pid, signal.SIGCONT)
    _, err = first.communicate(timeout=600)
    why = _clean(r, 75, "same.zarr", "another ingest is writing")
    why = why or ("" if first.returncode == 0 else f"the first ended {first.returncode}: "
                  f"{err.decode()[-300:]!r}")
    if not why:
        store = load(tmp_path / "same.zarr")
        poro = np.asarray(store.properties["PORO"])
        why = "" if np.allclose(poro, grid.properties["PORO"], equal_nan=True) else \
            "the store's PORO differs from the grid's"
    record(NAMES, "second grid ingest into one store", why, r)


# --------------------------------------------------------------------------------------------
# 4. bad values said: NaN/±1e30, a byte-order mark, upper bounds
# --------------------------------------------------------------------------------------------
def _kw(name: str) -> str:
    return f"{name:<8}"


def _restart_case(folder, bad: dict):
    """EGRID/INIT/UNRST (resfo) of a 12×10×5 grid whose last step's SWAT holds ``bad``
    (index -> value) among uniform values; returns the EGRID and the active SWAT written."""
    import resfo

    from geoshade.compute.grid.synthetic import synthetic_grid

    g = synthetic_grid(12, 10, 5, seed=2)
    nx, ny, nz = g.dims
    head = np.zeros(100, np.int32)
    head[:4] = (1, nx, ny, nz)
    resfo.write(folder / "CASE.EGRID", [
        (_kw("GRIDHEAD"), head),
        (_kw("COORD"), np.asarray(g.coord).transpose(1, 0, 2).reshape(-1).astype(np.float32)),
        (_kw("ZCORN"), np.asarray(g.zcorn).reshape(-1, order="F").astype(np.float32)),
        (_kw("ACTNUM"), np.asarray(g.actnum).reshape(-1, order="F").astype(np.int32)),
        (_kw("ENDGRID"), np.zeros(0, np.int32))])
    ih = np.zeros(411, np.int32)
    ih[8:12] = (nx, ny, nz, g.nactive)
    mask = g.active.reshape(-1, order="F")
    resfo.write(folder / "CASE.INIT", [(_kw("INTEHEAD"), ih), (_kw("PORO"), g.properties[
        "PORO"].reshape(-1, order="F")[mask])])
    rng = np.random.default_rng(0)
    entries = []
    for k in range(2):
        ihk = ih.copy()
        ihk[64:67] = (1, k + 1, 2001)
        sw = rng.uniform(0.1, 0.9, g.nactive).astype(np.float32)
        if k == 1:
            for i, v in bad.items():
                sw[i] = v
        entries += [(_kw("SEQNUM"), np.array([k], np.int32)), (_kw("INTEHEAD"), ihk),
                    (_kw("SWAT"), sw), (_kw("PRESSURE"), sw * 0 + 100)]
    resfo.write(folder / "CASE.UNRST", entries)
    return folder / "CASE.EGRID", sw


@pytest.mark.gl
def test_nan_and_huge_saturations_counted_and_said(tmp_path):
    bad = {**{i: np.nan for i in range(7)}, **{i: 1e30 for i in range(7, 12)},
           **{i: -1e30 for i in range(12, 15)}}
    _restart_case(tmp_path, bad)
    before = snapshot(tmp_path)
    r = run(["geoshade", "grid", "render", "CASE.EGRID", "--property", "SWAT", "-o", "s.png",
             "--size", "320x240", "--stats", "s.json"], tmp_path, timeout=300)
    said = [ln for ln in r.lines if "without a value" in ln]
    why = "" if r.rc == 0 else f"exit {r.rc}: {r.lines[-1:]}"
    why = why or ("" if len(said) == 1 and "CASE.EGRID: SWAT" in said[0] and
                  "15 active cells" in said[0] else f"said: {said!r}")
    if not why:
        stats = json.loads((tmp_path / "s.json").read_text())
        sub = [t["text"] for t in stats["annotations"]["title"]][-1]
        why = "" if stats["no_value_cells"] == len(bad) else f"stats {stats['no_value_cells']}"
        why = why or ("" if "15 cells without a value" in sub else f"subtitle {sub!r}")
    why = why or ", ".join(changed(before, snapshot(tmp_path), outputs=[tmp_path / "s.png",
                                                                        tmp_path / "s.json"]))
    record(VALUES, "NaN and ±1e30 SWAT in a restart", why, r)


def test_grdecl_with_a_byte_order_mark(folder):
    from geoshade.io import load

    (folder / "bom.grdecl").write_bytes(b"\xef\xbb\xbf" + (folder / "g.grdecl").read_bytes())
    (folder / "BOM.DATA").write_bytes(b"\xef\xbb\xbfRUNSPEC\nDIMENS\n 20 15 6 /\nGRID\n"
                                      b"INCLUDE\n 'g.grdecl' /\n")
    r = run(["geoshade", "info", "bom.grdecl"], folder, timeout=120)
    why = "" if r.rc == 0 and "20 × 15 × 6" in r.out else f"exit {r.rc}: {r.lines[-1:]}"
    if not why:
        ref = load(folder / "g.grdecl")
        for name in ("bom.grdecl", "BOM.DATA"):
            got = load(folder / name)
            same = np.array_equal(got.zcorn, ref.zcorn) and np.array_equal(got.coord, ref.coord)
            if name == "bom.grdecl":
                same = same and all(np.array_equal(got.properties[k], ref.properties[k],
                                                   equal_nan=True) for k in ref.properties)
            why = why or ("" if same else f"{name} reads other arrays than g.grdecl")
    record(VALUES, "GRDECL and deck starting with a UTF-8 BOM", why, r)


def test_levels_bounded(folder):
    before = snapshot(folder)
    r = run(["geoshade", "core", "ingest", "v.npy", "-o", "v.zarr", "--levels", "40"], folder,
            timeout=120)
    why = _clean(r, 2, "v.npy", "levels: expected 1..6", "got 40")
    why = why or ", ".join(changed(before, snapshot(folder)))
    record(VALUES, "core ingest --levels 40", why, r)


def test_kernel_bounded(folder):
    from geoshade.stacks import StacksOptions

    r = run(["geoshade", "stacks", "render", "lab.npy", "--kernel", "100000", "-o", "x.png"],
            folder, timeout=120, env={"GEOSHADE_GL": "off"})
    why = _clean(r, 2, "kernel", "0..15", "100000")
    limits = StacksOptions.declarations()["kernel"][0].limits   # (Opt, default)
    why = why or ("" if tuple(limits or ()) == (0, 15) else f"declared limits {limits!r}")
    record(VALUES, "stacks render --kernel 100000", why, r)


# --------------------------------------------------------------------------------------------
# 5. --scheduler at something that is no dask scheduler
# --------------------------------------------------------------------------------------------
def _listen(kind: str) -> tuple[int, threading.Event]:
    """A local port: ``http`` a web server, ``speaker`` a service that speaks first,
    ``silent`` one that accepts and says nothing. Returns its port and a stop event."""
    import http.server

    stop = threading.Event()
    if kind == "http":
        class Quiet(http.server.SimpleHTTPRequestHandler):
            def log_message(self, *a):
                pass

        srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Quiet)
        threading.Thread(target=srv.serve_forever, daemon=True).start()
        threading.Thread(target=lambda: (stop.wait(), srv.shutdown()), daemon=True).start()
        return srv.server_address[1], stop
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    s.listen(16)
    s.settimeout(0.2)
    held = []

    def serve():
        while not stop.is_set():
            try:
                c, _ = s.accept()
            except OSError:
                continue
            held.append(c)
            if kind == "speaker":
                c.sendall(b"220 smtp.example ESMTP ready\r\n")
        for c in held:
            c.close()
        s.close()

    threading.Thread(target=serve, daemon=True).start()
    return s.getsockname()[1], stop


@pytest.mark.parametrize("kind", ["http", "speaker", "silent", "ucx", "refused"])
def test_scheduler_that_is_not_one(folder, kind):
    stop = None
    if kind in ("http", "speaker", "silent"):
        port, stop = _listen(kind)
        address = f"tcp://127.0.0.1:{port}"
    else:
        address = "ucx://127.0.0.1:18767" if kind == "ucx" else "tcp://127.0.0.1:1"
    try:
        r = run(["geoshade", "core", "porosity", "v.npy", "--select", "0", "80", "-o", "p.png",
                 "--scheduler", address], folder, timeout=120)
    finally:
        if stop is not None:
            stop.set()
    needle = {"ucx": "needs ucx-py", "refused": "unreachable"}.get(kind, "not a dask scheduler")
    record(CLUSTER, f"--scheduler at {kind}", _clean(r, 2, address, needle), r)


def test_a_real_scheduler_still_connects(folder):
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=1, processes=False, protocol="tcp://",
                                       host="127.0.0.1", dashboard_address=None,
                                       silence_logs=50)
    try:
        r = run(["geoshade", "core", "porosity", "v.npy", "--select", "0", "80", "-o", "p.png",
                 "--scheduler", cluster.scheduler_address], folder, timeout=120)
    finally:
        cluster.close()
    a = np.load(folder / "v.npy")
    want = f"porosity {np.count_nonzero(a <= 80) / a.size:.4f}"
    why = "" if r.rc == 0 and want in r.out else f"exit {r.rc}: {r.out[:120]!r} {r.lines[-1:]}"
    record(CLUSTER, "--scheduler at a dask scheduler (the probe answered)", why, r)


def test_zz_counts():
    for cls in (CRASH, LIMITS, NAMES, VALUES, CLUSTER):
        if cls in RESULTS:
            print(summary(cls))
            assert all(ok for _, ok, _ in RESULTS[cls]), summary(cls)
