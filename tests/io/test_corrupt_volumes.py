"""Issue 12, volumes (classes 8 and 9): damaged copies of every volume format, special files and
sizes that do not fit.

For each format a seeded generator writes a small valid file; damaged copies of it (truncated at
several offsets, bytes flipped in the header and in compressed data, a file of zeros, an empty
file, another format under its suffix, a folder under its name, a FIFO) are run through the CLI
with commands that need no OpenGL (``geoshade info``, ``core porosity``, ``core ingest``,
``stacks convert``).  Every case must end in one of:

- a clean failure (:func:`tests.corruption.clean_failure`: exit code not 0 nor 70, one
  ``geoshade: error:`` line naming the file, no traceback, the input unchanged, nothing left);
- for damage that leaves a valid file (a truncated TIFF whose pixel data are intact, a flipped
  byte in an unused header field): exit 0 and — for truncations — the very description of the
  undamaged file (values, shape, spacing), so nothing is read wrong silently.

A FIFO runs in a subprocess with a timeout, so a hang fails the test instead of blocking it.
The zarr stores, the ingest lock and ``core verify`` are in ``test_corrupt_stores.py``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zlib

import numpy as np
import pytest
import tifffile

from tests.corruption import BUG_EXIT, Tally, file_hashes, listing, run_cli

SEED = 1212
TALLY = Tally("volume files")
ACCEPTED = Tally("volume files: the damage left a valid file (exit 0; truncations read exactly)")

RAW_HINTS = ("--shape", 12, 10, 8, "--dtype", "uint8")


def _volume(seed: int = SEED) -> np.ndarray:
    a = np.random.default_rng(seed).integers(1, 200, (8, 10, 12)).astype(np.uint8)
    a[:2] = 0
    return a


def _labels() -> np.ndarray:
    a = np.full((8, 10, 12), np.nan, np.float32)
    a[:6] = 2.0
    a[:3] = 1.0
    return a


# --- valid files, one writer per format ------------------------------------------------------
def _write_raw(p):
    _volume().tofile(p)


def _write_tif(p, **kw):
    tifffile.imwrite(p, _volume(), **kw)


def _write_npy(p):
    np.save(p, _volume())


def _write_npz(p):
    np.savez_compressed(p, data=_volume())


def _write_h5(p):
    import h5py

    with h5py.File(p, "w") as h:
        h.create_dataset("data", data=_volume(), compression="gzip")


def _write_nc(p):
    import xarray as xr

    a = _labels()
    nz, ny, nx = a.shape
    ds = xr.Dataset({"lithok": (("z", "y", "x"), a)},
                    coords={"x": 100.0 * np.arange(nx) + 50, "y": 100.0 * np.arange(ny) + 50,
                            "z": 0.5 * np.arange(nz) - 3.75})
    ds.to_netcdf(p, encoding={"lithok": {"zlib": True}})


def _write_stacks(p):
    from geoshade.io.layers.stackfile import write_stacks
    from geoshade.stacks import convert

    write_stacks(p, convert(_labels()))


#: name -> (file name, writer, extra CLI arguments, has checksums over its data)
FORMATS = {
    "raw": ("v.raw", _write_raw, RAW_HINTS, False),
    "tif": ("v.tif", _write_tif, (), False),
    "tif-zlib": ("v.tif", lambda p: _write_tif(p, compression="zlib"), (), True),
    "tif-imagej": ("v.tif", lambda p: _write_tif(p, imagej=True), (), False),
    "npy": ("v.npy", _write_npy, (), False),
    "npz": ("v.npz", _write_npz, (), True),
    "h5": ("v.h5", _write_h5, (), True),
    "nc": ("v.nc", _write_nc, (), True),
    "stacks": ("v.stacks.npz", _write_stacks, (), True),
}


@pytest.fixture(scope="module")
def valid(tmp_path_factory):
    """Each format's valid file and the ``geoshade info --json`` description of it."""
    root = tmp_path_factory.mktemp("valid")
    out = {}
    for name, (fname, write, args, _) in FORMATS.items():
        d = root / name
        d.mkdir()
        write(d / fname)
        out[name] = (d / fname, _describe(d / fname, args))
    return out


def _describe(path, args) -> dict:
    from geoshade.io import load
    from geoshade.io.describe import describe

    hints = {"shape": (12, 10, 8), "dtype": "uint8"} if args else {}
    d = describe(load(path, **hints))
    d.pop("source", None)
    return json.loads(json.dumps(d))


def _damaged(tmp_path, src, data: bytes, tag: str):
    d = tmp_path / tag
    d.mkdir()
    p = d / src.name
    p.write_bytes(data)
    return p


_expect_clean_failure = TALLY.clean_failure


def _fail_or_exact(capsys, path, args, expected: dict, watch) -> str:
    """``geoshade info --json`` on a damaged copy: a clean failure, or (the damage left a valid
    file) exit 0 with exactly the undamaged file's description."""
    argv = ["info", path, "--json", *args]
    before = file_hashes([path])
    rc, out, err = run_cli(capsys, argv)
    if rc == 0:
        got = json.loads(out)
        got.pop("source", None)
        got.pop("threshold", None)  # info's suggested thresholds: not part of describe()
        got.pop("plan", None)       # the memory plan names the file and its size
        ok = got == expected and "Traceback" not in err and file_hashes([path]) == before
        TALLY(ok)
        ACCEPTED(ok)
        assert ok, f"{path}: read without error but differs from the undamaged file: {got}"
        return "accepted"
    return _expect_clean_failure(capsys, argv, [path], watch)


def _fail_or_accept(capsys, path, args, watch) -> str:
    """A clean failure, or exit 0 without a traceback (a flipped header byte may leave a valid
    file that says something else)."""
    argv = ["info", path, "--json", *args]
    before = file_hashes([path])
    rc, _out, err = run_cli(capsys, argv)
    if rc == 0:
        ok = "Traceback" not in err and file_hashes([path]) == before
        TALLY(ok)
        ACCEPTED(ok)
        assert ok, err
        return "accepted"
    assert rc != BUG_EXIT, err
    return _expect_clean_failure(capsys, argv, [path], watch)


# --- truncation, zeros, empty ----------------------------------------------------------------
@pytest.mark.parametrize("fmt", list(FORMATS))
def test_truncated_copies_fail_cleanly_or_read_exactly(fmt, valid, tmp_path, capsys):
    src, expected = valid[fmt]
    args = FORMATS[fmt][2]
    data = src.read_bytes()
    n = len(data)
    rng = np.random.default_rng(SEED + len(fmt))
    cuts = sorted({1, 8, 64, n // 4, n // 2, n - 16, n - 1, *rng.integers(1, n, 4).tolist()})
    for cut in (c for c in cuts if 0 < c < n):
        p = _damaged(tmp_path, src, data[:cut], f"cut{cut}")
        _fail_or_exact(capsys, p, args, expected, [tmp_path])


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_empty_and_zero_files_fail_cleanly(fmt, valid, tmp_path, capsys):
    src, _ = valid[fmt]
    args = FORMATS[fmt][2]
    p = _damaged(tmp_path, src, b"", "empty")
    _expect_clean_failure(capsys, ["info", p, *args], [p], [tmp_path])
    if fmt != "raw":  # zeros of the right size are a valid raw file
        z = _damaged(tmp_path, src, bytes(src.stat().st_size), "zeros")
        _expect_clean_failure(capsys, ["info", z, *args], [z], [tmp_path])


# --- flipped bytes ---------------------------------------------------------------------------
def _data_ranges(fmt, path) -> list[tuple[int, int]]:
    """Every byte range holding pixel/array data (the rest is header and metadata)."""
    if fmt.startswith("tif"):
        with tifffile.TiffFile(path) as tf:
            return [(int(o), int(o + c)) for page in tf.pages
                    for o, c in zip(page.dataoffsets, page.databytecounts, strict=True)]
    if fmt == "npy":
        return [(128, path.stat().st_size)]
    if fmt in ("npz", "stacks"):
        import zipfile

        with zipfile.ZipFile(path) as z:
            out = []
            for info in z.infolist():
                start = info.header_offset + 30 + len(info.filename.encode()) + len(info.extra)
                out.append((start + 128, start + info.compress_size))  # keep the npy header
            return out
    if fmt in ("h5", "nc"):
        import h5py

        with h5py.File(path, "r") as h:
            d = h["data" if fmt == "h5" else "lithok"]
            infos = [d.id.get_chunk_info(i) for i in range(d.id.get_num_chunks())]
            return [(int(i.byte_offset), int(i.byte_offset + i.size)) for i in infos]
    raise AssertionError(fmt)


@pytest.mark.parametrize("fmt", [f for f in FORMATS if f != "raw"])  # raw files have no header
def test_flipped_header_bytes_never_crash(fmt, valid, tmp_path, capsys):
    src, _ = valid[fmt]
    args = FORMATS[fmt][2]
    data = src.read_bytes()
    ranges = _data_ranges(fmt, src)
    header = [i for i in range(len(data)) if not any(lo <= i < hi for lo, hi in ranges)]
    rng = np.random.default_rng(SEED + 7 * len(fmt))
    for k, pos in enumerate(sorted(set(rng.choice(header, 8).tolist()))):
        b = bytearray(data)
        b[pos] ^= 0xFF
        p = _damaged(tmp_path, src, bytes(b), f"hdr{k}")
        _fail_or_accept(capsys, p, args, [tmp_path])


def _data_region(fmt, path) -> tuple[int, int]:
    """(start, stop) of the compressed data of a file (what a checksum or codec guards)."""
    if fmt.startswith("tif"):
        with tifffile.TiffFile(path) as tf:
            page = tf.pages[3]
            return int(page.dataoffsets[0]), int(page.dataoffsets[0] + page.databytecounts[0])
    if fmt in ("npz", "stacks"):
        import zipfile

        with zipfile.ZipFile(path) as z:
            info = max(z.infolist(), key=lambda i: i.compress_size)
        start = info.header_offset + 30 + len(info.filename.encode()) + len(info.extra)
        return start, start + info.compress_size
    if fmt in ("h5", "nc"):
        import h5py

        with h5py.File(path, "r") as h:
            d = h["data" if fmt == "h5" else "lithok"]
            info = d.id.get_chunk_info(0)
            return int(info.byte_offset), int(info.byte_offset + info.size)
    raise AssertionError(fmt)


@pytest.mark.parametrize("fmt", [f for f, v in FORMATS.items() if v[3]])
def test_flipped_compressed_data_fails_cleanly(fmt, valid, tmp_path, capsys):
    """Where a codec or a checksum guards the data (deflate's Adler-32, zip's CRC-32), damage
    to it is an error naming the file, never other values."""
    src, _ = valid[fmt]
    data = src.read_bytes()
    lo, hi = _data_region(fmt, src)
    rng = np.random.default_rng(SEED + 11 * len(fmt))
    for k, pos in enumerate(sorted(set(rng.integers(lo + 2, hi - 4, 3).tolist()))):
        b = bytearray(data)
        b[pos] ^= 0x5A
        p = _damaged(tmp_path, src, bytes(b), f"data{k}")
        argv = ["info", p] if fmt != "stacks" else ["stacks", "convert", p, "-o", p.parent /
                                                     "m2.stacks.npz"]
        line = _expect_clean_failure(capsys, argv, [p], [tmp_path])
        assert "Traceback" not in line


# --- another format under the suffix, a folder under the name --------------------------------
@pytest.mark.parametrize("fmt,other", [("tif", "npy"), ("npy", "tif"), ("npz", "tif"),
                                        ("h5", "tif"), ("nc", "npy"), ("stacks", "npy"),
                                        ("npy", "h5"), ("tif", "nc")])
def test_another_format_under_the_suffix(fmt, other, valid, tmp_path, capsys):
    src, _ = valid[fmt]
    p = _damaged(tmp_path, src, valid[other][0].read_bytes(), "other")
    _expect_clean_failure(capsys, ["info", p], [p], [tmp_path])


@pytest.mark.parametrize("name", ["x.npy", "x.tif", "x.h5", "x.nc", "x.raw", "x.npz",
                                  "x.stacks.npz"])
def test_folder_where_a_file_is_expected(name, tmp_path, capsys):
    d = tmp_path / name
    d.mkdir()
    (d / "inside.bin").write_bytes(b"x")
    args = RAW_HINTS if name.endswith(".raw") else ()
    line = _expect_clean_failure(capsys, ["info", d, *args], [d], [tmp_path], names=name)
    assert "is a folder" in line


def test_file_where_a_folder_is_expected(tmp_path, capsys):
    f = tmp_path / "x.zarr"
    f.write_bytes(b"not a folder")
    line = _expect_clean_failure(capsys, ["info", f], [f], [tmp_path])
    assert "is a file; expected a zarr store" in line


def test_special_entries_in_a_folder_of_slices(tmp_path, capsys):
    d = tmp_path / "slices"
    d.mkdir()
    for z in range(3):
        tifffile.imwrite(d / f"s_{z}.tif", _volume()[z])
    (d / "s_3.tif").mkdir()  # a folder named like a slice is refused, not skipped
    line = _expect_clean_failure(capsys, ["info", d], [d], [tmp_path], names="s_3.tif")
    assert "is a folder" in line


# --- TIFF: a truncated stack, a corrupt strip, no library log lines ---------------------------
def test_truncated_tiff_stack_says_truncated_not_single_image(tmp_path, capsys):
    src = tmp_path / "stack.tif"
    tifffile.imwrite(src, _volume(), compression="zlib")
    data = src.read_bytes()
    p = _damaged(tmp_path, src, data[: len(data) // 3], "cut")
    for argv in (["info", p], ["core", "porosity", p, "--select", 0, 80, "-o",
                               tmp_path / "p.png"]):
        line = _expect_clean_failure(capsys, argv, [p], [tmp_path])
        assert "single 2D image" not in line and ("truncated" in line or "damaged" in line)


def test_corrupt_compressed_strip_is_one_line_also_lazily(tmp_path, capsys):
    from geoshade.errors import InputError
    from geoshade.io.volumes.tiff import read_tiff

    src = tmp_path / "stack.tif"
    tifffile.imwrite(src, _volume(), compression="zlib")
    lo, _ = _data_region("tif-zlib", src)
    b = bytearray(src.read_bytes())
    b[lo + 2] ^= 0xFF
    p = _damaged(tmp_path, src, bytes(b), "strip")
    _expect_clean_failure(capsys, ["core", "porosity", p, "--select", 0, 80, "-o",
                                   tmp_path / "p.png"], [p], [tmp_path])
    vol = read_tiff(p, lazy=True)  # the error comes when the strip is read
    with pytest.raises(InputError, match=r"strip/stack\.tif: damaged TIFF image data"):
        np.asarray(vol.data)
    TALLY(True)


# --- sizes: headers that claim more than the file holds, memory ------------------------------
def _npy_with_shape(path, shape, data=b""):
    header = {"descr": "|u1", "fortran_order": False, "shape": tuple(shape)}
    with open(path, "wb") as fh:
        np.lib.format.write_array_header_1_0(fh, header)
        fh.write(data)


@pytest.mark.parametrize("shape", [(8, 10, 13), (100000, 100000, 100000), (2**40, 2**40, 8)])
def test_npy_header_claiming_more_than_the_file(shape, tmp_path, capsys):
    p = tmp_path / "big.npy"
    _npy_with_shape(p, shape, _volume().tobytes())
    line = _expect_clean_failure(capsys, ["info", p], [p], [tmp_path])
    assert "header says shape" in line and "holds 960 bytes" in line


def test_npz_member_claiming_more_than_it_holds(tmp_path, capsys):
    import zipfile

    p = tmp_path / "big.npz"
    m = tmp_path / "member.npy"
    _npy_with_shape(m, (100000, 100000, 100000), b"\0" * 100)
    with zipfile.ZipFile(p, "w") as z:
        z.write(m, "data.npy")
    m.unlink()
    line = _expect_clean_failure(capsys, ["info", p], [p], [tmp_path])
    assert "member 'data.npy'" in line and "header says shape" in line


def test_stacks_member_claiming_more_than_it_holds(valid, tmp_path, capsys):
    import zipfile

    src, _ = valid["stacks"]
    p = tmp_path / "m.stacks.npz"
    big = tmp_path / "codes.npy"
    _npy_with_shape(big, (2**40,), b"\0" * 64)
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(p, "w") as zout:
        for info in zin.infolist():
            if info.filename == "codes.npy":
                zout.write(big, "codes.npy")
            else:
                zout.writestr(info, zin.read(info))
    big.unlink()
    line = _expect_clean_failure(capsys, ["stacks", "convert", p, "-o", tmp_path / "o.stacks.npz"],
                                 [p], [tmp_path])
    assert "codes.npy" in line


@pytest.mark.parametrize("args,expect", [
    (("--shape", 100000, 100000, 100000, "--dtype", "uint16"), "expects 2000000000000000"),
    (("--shape", 12, 10, 8, "--dtype", "uint8", "--offset", 5000), "past the end of the file"),
    (("--shape", 12, 10, 8, "--dtype", "uint8", "--offset", 960), "past the end of the file"),
    (("--shape", 12, 10, 8, "--dtype", "uint8", "--offset", -4), "offset: expected"),
])
def test_raw_sizes_and_offsets(args, expect, tmp_path, capsys):
    p = tmp_path / "v.raw"
    _write_raw(p)
    line = _expect_clean_failure(capsys, ["core", "ingest", p, "-o", tmp_path / "o.zarr", *args],
                                 [p], [tmp_path])
    assert expect in line


def test_memory_is_checked_before_whole_reads(valid, tmp_path, capsys, monkeypatch):
    """Readers that load a whole array compare its size with the available memory first and
    say both numbers (exit code 6)."""
    import geoshade.io.paths as paths

    monkeypatch.setattr(paths, "mem_available", lambda: 500)
    for fmt in ("npz", "tif-zlib", "nc"):  # (an uncompressed TIFF is memory-mapped)
        src, _ = valid[fmt]
        line = _expect_clean_failure(capsys, ["info", src], [src], [src.parent])
        assert "of memory and 500 B are available (MemAvailable)" in line, line
    f = tmp_path / "v.raw"
    _write_raw(f)
    line = _expect_clean_failure(capsys, ["core", "ingest", f, "-o", tmp_path / "o.zarr",
                                          *RAW_HINTS], [f], [tmp_path])
    assert "slab(s) of 8×10×12 uint8" in line and "500 B are available" in line
    rc, _, _ = run_cli(capsys, ["info", f, *RAW_HINTS])  # a memory map needs no such memory
    assert rc == 0


def test_mem_available_reads_proc_meminfo():
    from geoshade.io.paths import mem_available

    n = mem_available()
    if os.path.exists("/proc/meminfo"):
        assert n is not None and n > 0


# --- FIFOs: refused before opening, in a subprocess so that a hang fails the test -------------
_RUNNER = r"""
import contextlib, io, json, sys
from geoshade.cli.main import main
results = []
for argv in json.loads(sys.argv[1]):
    print("CASE", argv, flush=True)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            rc = main(argv)
        except SystemExit as exc:
            rc = exc.code
    results.append({"argv": argv, "rc": rc, "err": err.getvalue()})
print("RESULT " + json.dumps(results), flush=True)
"""


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
def test_fifos_are_refused_without_hanging(valid, tmp_path):
    cases, names = [], []
    for name in ("v.tif", "v.npy", "v.npz", "v.h5", "v.nc", "v.raw", "m.stacks.npz"):
        f = tmp_path / name
        os.mkfifo(f)
        extra = list(map(str, RAW_HINTS)) if name.endswith(".raw") else []
        cases.append(["info", str(f), *extra])
        names.append(name)
    cases.append(["core", "porosity", str(tmp_path / "v.tif"), "--select", "0", "80", "-o",
                  str(tmp_path / "p.png")])
    names.append("v.tif")
    cases.append(["core", "ingest", str(tmp_path / "v.npy"), "-o", str(tmp_path / "o.zarr")])
    names.append("v.npy")
    cases.append(["stacks", "convert", str(tmp_path / "v.nc"), "-o",
                  str(tmp_path / "o.stacks.npz")])
    names.append("v.nc")
    slices = tmp_path / "slices"  # a FIFO among the slices of a folder
    slices.mkdir()
    for z in range(2):
        tifffile.imwrite(slices / f"s_{z}.tif", _volume()[z])
    os.mkfifo(slices / "s_2.tif")
    cases.append(["info", str(slices)])
    names.append("s_2.tif")
    store = tmp_path / "fifo.zarr"  # a FIFO in place of a chunk of a store
    from geoshade.io.stores.ingest import ingest

    raw = tmp_path / "src" / "v.raw"
    raw.parent.mkdir()
    _write_raw(raw)
    ingest(raw, store, chunks=(4, 10, 12), levels=1, shape=(12, 10, 8), dtype="uint8")
    chunk = store / "0" / "c" / "1" / "0" / "0"
    chunk.unlink()
    os.mkfifo(chunk)
    cases.append(["info", str(store)])
    names.append("fifo.zarr")
    seen = listing([tmp_path])
    proc = subprocess.run([sys.executable, "-c", _RUNNER, json.dumps(cases)], capture_output=True,
                          text=True, timeout=120, cwd=tmp_path)
    last = [ln for ln in proc.stdout.splitlines() if ln.startswith("CASE")][-1:]
    result = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")]
    assert result, f"no result (a hang or a crash after {last}): {proc.stderr[-2000:]}"
    for res, name in zip(json.loads(result[0][7:]), names, strict=True):
        err = res["err"]
        lines = [ln for ln in err.splitlines() if ln.strip()]
        ok = (res["rc"] not in (0, BUG_EXIT) and "Traceback" not in err and len(lines) == 1
              and lines[0].startswith("geoshade: error:") and name in lines[0])
        TALLY(ok)
        assert ok, res
        assert "FIFO" in lines[0] or "not a regular file" in lines[0], lines[0]
    assert listing([tmp_path]) == seen


def test_one_line_names_zlib_errors():
    from geoshade.io.paths import one_line

    try:
        zlib.decompress(b"garbage")
    except zlib.error as err:
        assert one_line(err).startswith("zlib.error: Error -3")


def test_zz_report():
    print(TALLY)
    print(ACCEPTED)
    assert TALLY.clean == TALLY.tried
