"""GRDECL files and decks streamed into a grid store (io/grdecl_stream): the store equals, array
for array and bit for bit, the one written from the in-memory read; damaged files give the
in-memory reader's one line and leave nothing behind; the source never parses more than a slab."""

from __future__ import annotations

import os
import re
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io.grids import grdecl, grdecl_stream
from geoshade.io.grids.deck import read_deck
from geoshade.io.grids.grdecl import read_grdecl
from geoshade.io.grids.grdecl_stream import GrdeclSource, read_span
from geoshade.io.grids.grdecl_writer import write_grdecl
from geoshade.io.stores.grid_store import ModelSource, ingest_grid, write_grid_store
from tests.corruption import clean_failure, run_cli
from tests.io.grid_store_support import interrupted_ingest

CHUNKS = (8, 5, 4)  # 23 × 17 × 9 cells: chunk borders not on the grid's, a short last slab


def _store(path) -> tuple[dict, dict]:
    """Every array (values and attributes) and the group attributes of a store."""
    import zarr

    root = zarr.open_group(str(path), mode="r")
    out = {}

    def walk(g, pre=""):
        for k, v in g.members():
            if isinstance(v, zarr.Group):
                walk(v, f"{pre}{k}/")
            else:
                out[pre + k] = (np.asarray(v[...]), dict(v.attrs), str(v.dtype))

    walk(root)
    return out, dict(root.attrs)


def _assert_same_store(a, b) -> None:
    (arrs_a, attrs_a), (arrs_b, attrs_b) = _store(a), _store(b)
    assert sorted(arrs_a) == sorted(arrs_b)  # (the order of the properties: in the attrs)
    for k, (va, ta, da) in arrs_a.items():
        vb, tb, db = arrs_b[k]
        assert da == db and va.shape == vb.shape, k
        assert va.tobytes() == vb.tobytes(), k  # bit for bit (NaN included)
        assert ta == tb, k  # chunk CRCs, summaries
    assert attrs_a == attrs_b


def _in_memory(src: Path, out: Path, reader=read_grdecl, chunks=CHUNKS):
    return write_grid_store(ModelSource(reader(src), str(src)), out, chunks,
                            input_label=str(src.resolve()))


def _assert_like_reader(store, grid) -> None:
    """The stored arrays equal the in-memory grid's (its dtypes, its values)."""
    arrs, _ = _store(store)
    assert arrs["zcorn"][0].tobytes() == np.asarray(grid.zcorn, np.float32).tobytes()
    assert np.array_equal(arrs["coord"][0], grid.coord)
    assert np.array_equal(arrs["actnum"][0], np.asarray(grid.actnum) != 0)
    for name, v in grid.properties.items():
        assert arrs[f"props/{name}"][0].tobytes() == np.ascontiguousarray(v).tobytes(), name


def _messy(text: str) -> str:
    """The same grid with comments everywhere, ``/`` followed by a comment, odd line breaks."""
    lines = text.splitlines()
    out = []
    for n, line in enumerate(lines):
        if line.strip() == "/":
            out.append("/ -- end of the record")
            continue
        toks = line.split()
        if n % 5 == 0 and len(toks) > 2 and toks[0][0] in "0123456789-." and \
                not line.startswith("--"):  # a comment between the values of a record
            out.append(" ".join(toks[:2]) + "  -- two values, then a comment")
            out.append("\t" + "\n   ".join(toks[2:]))
        else:
            out.append(line)
        if n % 11 == 3:
            out.append("-- a whole-line comment 1 2 3 / not a terminator")
    return "\n".join(out) + "\n"


@pytest.fixture(scope="module")
def grid():
    return synthetic_grid(23, 17, 9, seed=3)


@pytest.fixture
def small_pieces(monkeypatch):
    """Checkpoints every 37 values, 4 kB reads: checkpoints inside repeats and comments,
    tokens cut by buffer ends, in the scan and in the slabs."""
    monkeypatch.setattr(grdecl, "CHUNK_BYTES", 4096)
    monkeypatch.setattr(grdecl_stream, "CHECKPOINT_VALUES", 37)
    monkeypatch.setattr(grdecl_stream, "READ_BYTES", 4096)


@pytest.mark.parametrize("variant", ["plain", "messy", "no-actnum", "include"])
def test_streamed_store_equals_the_in_memory_one(grid, tmp_path, small_pieces, variant):
    f = write_grdecl(grid, tmp_path / "g.grdecl")
    text = f.read_text()
    assert re.search(r"\b\d+\*\S+", text)  # the writer's N*value runs are in the text
    if variant == "messy":
        f.write_text(_messy(text))
    elif variant == "no-actnum":
        f.write_text(re.sub(r"\nACTNUM\n[^/]*/\n", "\n", text))
    elif variant == "include":
        zc = re.search(r"\nZCORN\n[^/]*/\n", text)
        assert zc is not None
        (tmp_path / "sub").mkdir()
        (tmp_path / "sub" / "z.inc").write_text(zc.group(0))
        f.write_text(text.replace(zc.group(0), "\nINCLUDE\n 'sub/z.inc' /\n"))
    ref = read_grdecl(f)
    assert (variant == "no-actnum") == bool(np.all(ref.actnum))
    rep = ingest_grid(f, tmp_path / "s.zarr", chunks=CHUNKS)
    assert not rep.notes and rep.slabs == 3
    _assert_same_store(rep.path, _in_memory(f, tmp_path / "m.zarr").path)
    _assert_like_reader(rep.path, ref)


def test_integer_properties_repeats_and_redefinition(tmp_path):
    g = synthetic_grid(6, 5, 4, seed=1)
    f = write_grdecl(g, tmp_path / "g.grdecl")
    n = 6 * 5 * 4
    f.write_text(f.read_text() + f"PORO\n {n}*0.125 /\nSATNUM\n {n // 2}*2 {n - n // 2}*7 /\n"
                 "MYNUM\n 3*1 /\nFOO\n 1 2 3 /\n")
    src = GrdeclSource(f)
    assert src.properties["SATNUM"] == np.int32 and src.properties["FIPNUM"] == np.int32
    assert "MYNUM" not in src.properties and "FOO" not in src.properties  # not cell arrays
    ref = read_grdecl(f)
    assert list(src.properties) == list(ref.properties)
    rep = ingest_grid(f, tmp_path / "s.zarr", chunks=(4, 4, 3))
    _assert_same_store(rep.path, _in_memory(f, tmp_path / "m.zarr", chunks=(4, 4, 3)).path)
    _assert_like_reader(rep.path, ref)
    assert np.all(ref.properties["PORO"] == np.float32(0.125))  # the later PORO wins


def test_read_span_any_range_equals_the_reader(grid, tmp_path, small_pieces):
    f = write_grdecl(grid, tmp_path / "g.grdecl")
    f.write_text(_messy(f.read_text()))
    src, ref = GrdeclSource(f), read_grdecl(f)
    flat = {"ZCORN": np.asarray(ref.zcorn).ravel(order="F"),
            "COORD": np.asarray(ref.coord).transpose(1, 0, 2).ravel(),
            "ACTNUM": np.asarray(ref.actnum).ravel(order="F"),
            "FIPNUM": ref.properties["FIPNUM"].ravel(order="F")}
    rng = np.random.default_rng(0)
    for kw, want in flat.items():
        span = src.spans.get(kw) or src.cells[kw].base
        assert span.index.size > 5  # many checkpoints
        for _ in range(20):
            q0, q1 = np.sort(rng.integers(0, want.size + 1, 2))
            got = read_span(span, q0, q1)
            assert got.dtype == want.dtype and got.tobytes() == want[q0:q1].tobytes(), kw


def test_deck_with_includes_is_streamed(tmp_path):
    g = synthetic_grid(9, 7, 5, seed=2)
    write_grdecl(g, tmp_path / "grid.grdecl")
    (tmp_path / "C.DATA").write_text(
        "RUNSPEC\nDIMENS\n 9 7 5 /\nFIELD\nGRID\nINCLUDE\n 'grid.grdecl' /\nPROPS\n"
        "SCHEDULE\nWELSPECS\n 'W1' 'G' 2 3 1* OIL /\n/\nCOMPDAT\n 'W1' 2* 2 4 OPEN /\n/\n"
        "END\n")
    deck = tmp_path / "C.DATA"
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = ingest_grid(deck, tmp_path / "s.zarr", chunks=(4, 4, 2))
        ref = _in_memory(deck, tmp_path / "m.zarr", reader=read_deck, chunks=(4, 4, 2))
    assert not rep.notes
    _assert_same_store(rep.path, ref.path)
    _, attrs = _store(rep.path)
    assert attrs["meta"]["format"] == "DATA deck" and attrs["units"] == "METRES"  # GRIDUNIT


EDITS = """
BOX
 2 5 1 3 2 6 /
PORO
 {box_poro} /
SATNUM
 {box_sat} /
ENDBOX
EQUALS
 'NTG' 0.5 1 4 1 6 1 3 /
 'MULTZ' 0.25 3 9 2 4 4 8 /
 'ACTNUM' 0 1 2 1 2 1 9 /
 'FIPNUM' 7.9 5 6 5 6 5 6 /
/
MULTIPLY
 'PERMX' 0.3 /
 'PORO' 2 4 11 3 7 3 5 /
 'FIPNUM' 0.5 1 11 1 3 1 9 /
/
ADD
 'PERMX' 10 2 3 2 3 2 9 /
/
MINVALUE
 'PORO' 0.05 /
/
MAXVALUE
 'PERMX' 900 /
/
COPY
 'PERMX' 'PERMY' /
 'FIPNUM' 'EQLNUM' 1 11 1 8 3 7 /
 'PORO' 'PORO' /
/
MULTIPLY
 'PERMX' 2 /
 'NOSUCH' 2 /
/
BOX
 1 3 1 3 1 3 /
EQUALS
 'PERMZ' 1 /
/
ENDBOX
"""


def test_edit_keywords_and_box_properties_are_streamed(tmp_path, small_pieces):
    """BOX'd properties and EQUALS / MULTIPLY / ADD / MINVALUE / MAXVALUE / COPY (ACTNUM, new
    arrays with their defaults, integer arrays, COPY of an array edited later, a later BOX as the
    default box) give the in-memory reader's arrays, slab by slab across box borders."""
    g = synthetic_grid(11, 8, 9, seed=6)
    f = write_grdecl(g, tmp_path / "g.grdecl")
    n = 4 * 3 * 5
    f.write_text(f.read_text() + EDITS.format(box_poro=" ".join(f"{v:.3f}" for v in
                                                                  np.linspace(0, 1, n)),
                                              box_sat=f"{n // 2}*3 {n - n // 2}*4"))
    with pytest.warns(UserWarning, match="NOSUCH is not defined"):
        src = GrdeclSource(f)
    assert {"PERMY", "EQLNUM", "MULTZ", "SATNUM", "PERMZ"} <= set(src.properties)
    with pytest.warns(UserWarning, match="NOSUCH is not defined"):
        ref = read_grdecl(f)
        rep = ingest_grid(f, tmp_path / "s.zarr", chunks=(4, 3, 2))
        mem = _in_memory(f, tmp_path / "m.zarr", chunks=(4, 3, 2))
    assert not rep.notes
    _assert_same_store(rep.path, mem.path)
    _assert_like_reader(rep.path, ref)
    assert not np.asarray(ref.actnum)[0, 0].any()  # the edits did something
    assert np.isnan(ref.properties["SATNUM"]).sum() == 0 and (ref.properties["SATNUM"] == 3).any()


def test_block_centred_geometry_is_read_in_memory(tmp_path):
    (tmp_path / "b.grdecl").write_text("DIMENS\n 3 2 2 /\nDX\n 12*10 /\nDY\n 12*20 /\n"
                                       "DZ\n 12*5 /\nTOPS\n 6*1000 /\nPORO\n 12*0.2 /\n")
    f = tmp_path / "b.grdecl"
    rep = ingest_grid(f, tmp_path / "s.zarr", chunks=CHUNKS)
    assert rep.notes and "DX (block-centred geometry)" in rep.notes[0]
    assert "in memory" in rep.notes[0]
    _assert_same_store(rep.path, _in_memory(f, tmp_path / "m.zarr").path)


def test_the_reek_deck_is_streamed_as_read_in_memory(tmp_path, shared_data):
    """A real deck (INCLUDEs of grid, faults, properties; MULTIPLY PERMZ; sections; wells)."""
    import warnings

    deck = shared_data / "reek_cornerpoint" / "model" / "2_R001_REEK-0.DATA"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = ingest_grid(deck, tmp_path / "s.zarr", chunks=(16, 16, 4))
        mem = _in_memory(deck, tmp_path / "m.zarr", reader=read_deck, chunks=(16, 16, 4))
    assert not rep.notes and rep.dims == (40, 64, 14)
    _assert_same_store(rep.path, mem.path)


def test_streamed_ingest_resumes(grid, tmp_path, monkeypatch):
    f = write_grdecl(grid, tmp_path / "g.grdecl")
    out = tmp_path / "r.zarr"
    interrupted_ingest(monkeypatch, f, out, chunks=CHUNKS)
    assert not out.exists() and (tmp_path / "r.zarr.partial").is_dir()
    reads: list = []
    monkeypatch.setattr(grdecl_stream, "_on_read", lambda kw, q0, q1: reads.append((kw, q0)))
    rep = ingest_grid(f, out, chunks=CHUNKS)
    assert rep.resumed and rep.slabs_skipped == 2 and rep.slabs_written == 1
    nx, ny, _ = grid.dims
    assert ("ZCORN", 8 * nx * ny * 8) in reads and all(q0 >= nx * ny * 8 for kw, q0 in reads
                                                        if kw not in ("ZCORN", "COORD"))
    _assert_same_store(rep.path, _in_memory(f, tmp_path / "m.zarr").path)


def _damage(text: str, how: str) -> str:
    if how == "short":  # ZCORN short of values
        return re.sub(r"(\nZCORN\n[^/]*?)\s+\S+\s*/", r"\1 /", text, count=1)
    if how == "truncated":  # the file ends inside PORO
        return text[:text.index("\nPORO\n") + 400]
    if how == "bad-number":
        return re.sub(r"(\nPERMX\n\s*\S+\s+)\S+", r"\g<1>1.2.3", text, count=1)
    if how == "nan-depth":
        return re.sub(r"(\nZCORN\n\s*\S+\s+)\S+", r"\g<1>nan", text, count=1)
    if how == "no-zcorn":
        return re.sub(r"\nZCORN\n[^/]*/\n", "\n", text)
    raise AssertionError(how)


@pytest.mark.parametrize("how", ["short", "truncated", "bad-number", "nan-depth", "no-zcorn"])
def test_damaged_file_is_the_readers_one_line_and_leaves_nothing(grid, tmp_path, how):
    f = write_grdecl(grid, tmp_path / "g.grdecl")
    f.write_text(_damage(f.read_text(), how))
    with pytest.raises(InputError) as want:
        read_grdecl(f)
    with pytest.raises(InputError) as got:
        ingest_grid(f, tmp_path / "s.zarr", chunks=CHUNKS)
    assert str(got.value) == str(want.value)
    assert "\n" not in str(got.value) and str(f) in str(got.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.grdecl"]


def test_cli_ingest_and_a_damaged_file(grid, tmp_path, capsys):
    f = write_grdecl(grid, tmp_path / "g.grdecl")
    rc, out, _ = run_cli(capsys, ["grid", "ingest", str(f), "-o", str(tmp_path / "g.zarr"),
                                  "--chunks", "8", "5", "4"])
    assert rc == 0 and "3 of 3 slabs written" in out
    bad = tmp_path / "bad" / "b.grdecl"
    bad.parent.mkdir()
    bad.write_text(_damage(f.read_text(), "bad-number"))
    line = clean_failure(capsys, ["grid", "ingest", str(bad), "-o",
                                  str(bad.parent / "b.zarr")], inputs=[bad],
                         watch=[bad.parent], expect="PERMX: non-numeric token '1.2.3'")
    assert "b.grdecl" in line


def test_the_source_parses_at_most_a_slab_at_once(tmp_path, monkeypatch):
    """Memory: the ingest parses at most one slab's values of one array at a time (COORD once),
    and a slab read holds the slab plus a few read pieces (traced), never the whole array."""
    g = synthetic_grid(60, 50, 80, seed=5, steps=0)
    f = write_grdecl(g, tmp_path / "g.grdecl")
    nx, ny, nz = g.dims
    ck, piece = 4, 64 << 10
    monkeypatch.setattr(grdecl_stream, "READ_BYTES", piece)
    reads: list = []
    monkeypatch.setattr(grdecl_stream, "_on_read", lambda kw, q0, q1: reads.append((kw, q1 - q0)))
    src = GrdeclSource(f)
    rep = write_grid_store(src, tmp_path / "s.zarr", (32, 32, ck), input_label=str(f))
    per = {"ZCORN": 8 * nx * ny * ck, "COORD": 6 * (nx + 1) * (ny + 1)}
    assert all(n <= per.get(kw, nx * ny * ck) for kw, n in reads)
    assert [kw for kw, _ in reads].count("ZCORN") == rep.slabs == nz // ck
    assert [kw for kw, _ in reads].count("COORD") == 1
    whole_zcorn = 4 * 8 * nx * ny * nz
    tracemalloc.start()
    try:
        for k0 in range(0, nz, ck):
            tracemalloc.reset_peak()
            before = tracemalloc.get_traced_memory()[0]
            z = src.zcorn(k0, k0 + ck)
            peak = tracemalloc.get_traced_memory()[1] - before
            assert peak <= z.nbytes + 3 * piece + 8 * grdecl_stream.SKIP_VALUES + (64 << 10) \
                < whole_zcorn / 4, peak
            del z
    finally:
        tracemalloc.stop()


def test_a_file_changed_during_the_ingest_is_one_line_and_no_store(grid, tmp_path):
    f = write_grdecl(grid, tmp_path / "g.grdecl")
    src = GrdeclSource(f)
    text = f.read_text()
    st = f.stat()
    f.write_text(text.replace("ZCORN\n", "ZCORN\n 1 2 3 /\n", 1))  # values moved
    with pytest.raises(InputError, match=r"g\.grdecl: COORD: the file changed while it was being "
                                         "ingested") as err:
        write_grid_store(src, tmp_path / "s.zarr", CHUNKS)
    assert "\n" not in str(err.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.grdecl"]
    # the same size and time (the stamp cannot tell): the values are not where they were
    f.write_text(text.replace("\n0 ", "\n1 ", 1).replace("ZCORN\n", "ZCORN\n 1 2 3 /\n", 1)
                 [:len(text)])
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert f.stat().st_size == st.st_size
    with pytest.raises(InputError, match=r"ZCORN: the file changed while it was being ingested"):
        write_grid_store(src, tmp_path / "s.zarr", CHUNKS)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.grdecl"]


def test_progress_and_an_existing_store_before_the_scan(grid, tmp_path, monkeypatch):
    f = write_grdecl(grid, tmp_path / "g.grdecl")
    calls: list = []
    rep = ingest_grid(f, tmp_path / "s.zarr", chunks=CHUNKS,
                      progress=lambda d, t: calls.append((d, t)))
    scan = [c for c in calls if c[1] == 1000]
    assert scan and scan[-1] == (1000, 1000) and scan == sorted(scan)  # the scan, in per mille
    assert calls[len(scan):] == [(s, 3) for s in range(1, 4)]  # then the slabs

    def no_scan(*a, **k):
        raise AssertionError("scanned although the store exists")

    monkeypatch.setattr(grdecl_stream, "GrdeclSource", no_scan)
    with pytest.raises(InputError, match="already exists"):
        ingest_grid(f, rep.path, chunks=CHUNKS)
