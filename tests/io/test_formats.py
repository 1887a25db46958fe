"""The format table (issue 30): one row per kind of file, read by ``load``, ``info``, ingest, the
browser's file list and the output guard; a new format is one row and one reader."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from geoshade.errors import InputError, MissingExtraError
from geoshade.io import formats, load
from geoshade.io.formats import DOMAINS, FORMATS, Format, case_files, find
from geoshade.models import VoxelVolume
from geoshade.web.catalog import Catalog


def _one_name(fmt: Format) -> str:
    if fmt.suffixes:
        return "x" + fmt.suffixes[0]
    if fmt.patterns:
        return "x.X0001"
    return ""


def test_every_row_is_declared_once_and_complete():
    names = [f.name for f in FORMATS]
    assert len(names) == len(set(names))
    for f in FORMATS:
        assert f.domain in DOMAINS and f.title and f.reader
        assert f.suffixes or f.patterns or f.folder, f.name
        assert all(s == s.lower() and s.startswith(".") for s in f.suffixes)
        assert callable(formats.resolve(f.reader)), f.name


def test_a_suffix_belongs_to_one_row_unless_a_test_tells_them_apart():
    owners: dict[str, list[Format]] = {}
    for f in FORMATS:
        for s in f.suffixes:
            owners.setdefault(s, []).append(f)
    for s, rows in owners.items():
        assert len(rows) == 1 or all(r.test for r in rows[:-1]), (s, [r.name for r in rows])


@pytest.mark.parametrize("fmt", FORMATS, ids=lambda f: f.name)
def test_each_row_is_found_by_its_name(fmt):
    name = _one_name(fmt)
    if name:
        assert find(name, sniff=False) is fmt or fmt.name == "tiff"   # .tif: the DEM row first
        assert formats.listed(name)


def test_unknown_file_lists_every_kind(tmp_path):
    f = tmp_path / "notes.txt"
    f.write_text("x")
    with pytest.raises(InputError) as e:
        load(f)
    msg = str(e.value)
    assert msg.startswith(f"{f}: unknown file type '.txt'; expected one of: ")
    assert all(row.title in msg for row in FORMATS) and "\n" not in msg


def test_a_folder_where_the_kind_is_a_file_is_one_line(tmp_path):
    (tmp_path / "x.npy").mkdir()
    with pytest.raises(InputError, match=r"x\.npy: is a folder; expected a file \(NumPy array\)"):
        load(tmp_path / "x.npy")


def test_folder_rows(tmp_path):
    import tifffile

    slices = tmp_path / "slices"
    slices.mkdir()
    for k in range(3):
        tifffile.imwrite(slices / f"s{k:03d}.TIF", np.full((4, 5), k, np.uint8))
    (slices / ".hidden.zarray").write_text("{}")   # hidden: not a zarr marker
    assert find(slices).name == "tiff-folder"
    assert load(slices).shape_xyz == (5, 4, 3)
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(InputError, match="folder is not a known volume"):
        load(empty)


def test_a_new_format_is_one_row_and_one_reader(tmp_path):
    def read_txt(path, scale=1):
        return VoxelVolume(np.full((1, 1, 1), scale, np.uint8), name=path.name)

    formats.register(Format("gsvol", "test volume", "volume", read_txt, (".gsvol",),
                            ingest="core"))
    try:
        f = tmp_path / "x.gsvol"
        f.write_text("")
        assert int(load(f, scale=3).data[0, 0, 0]) == 3
        assert formats.listed(f) and formats.ingested_by(f, "core").name == "gsvol"
    finally:
        formats.unregister("gsvol")
    assert find(tmp_path / "x.gsvol") is None


def test_a_missing_extra_is_one_line_naming_it(tmp_path, monkeypatch):
    monkeypatch.setitem(formats.EXTRA_PACKAGES, "roff", "no_such_package_xyz")
    f = tmp_path / "g.roff"
    f.write_bytes(b"roff-bin\0")
    with pytest.raises(MissingExtraError) as e:
        load(f)
    assert str(e.value) == ("reading ROFF grid (RMS) needs no_such_package_xyz, which is not "
                            "installed: pip install 'geoshade[roff]'")


def test_case_files_travel_with_the_file(tmp_path):
    for n in ("C.EGRID", "C.INIT", "C.UNRST", "C.X0001", "C.SMSPEC", "D.INIT", "C.txt"):
        (tmp_path / n).write_bytes(b"")
    got = [p.name for p in case_files(tmp_path / "C.X0001")]
    assert got[0] == "C.X0001" and set(got) == {"C.X0001", "C.EGRID", "C.INIT", "C.UNRST",
                                                "C.SMSPEC", "C.txt"}
    raw = tmp_path / "core.raw"
    raw.write_bytes(b"\0" * 8)
    (tmp_path / "core.nhdr").write_text("NRRD0004\ndata file: core.raw\n\n")
    assert [p.name for p in case_files(raw)] == ["core.raw", "core.nhdr"]
    assert [p.name for p in case_files(tmp_path / "core.nhdr")] == ["core.nhdr", "core.raw"]
    for n in ("G.roff", "G--PORO.roff", "G--PERMX.roff", "H--PORO.roff"):
        (tmp_path / n).write_bytes(b"")
    assert [p.name for p in case_files(tmp_path / "G.roff")] == ["G.roff", "G--PERMX.roff",
                                                                 "G--PORO.roff"]
    assert case_files(None, tmp_path / "a.npy") == [tmp_path / "a.npy"]


def test_ingest_routes_come_from_the_table(tmp_path):
    for name, route in (("a.tif", "core"), ("a.raw", "core"), ("a.h5", "core"),
                        ("C.EGRID", "grid"), ("g.grdecl", "grid"), ("g.roff", "grid")):
        assert formats.ingested_by(name, route).ingest == route
    with pytest.raises(InputError, match=r"^C\.UNRST: an ECLIPSE/OPM case is ingested by "
                                         r"geoshade grid ingest, not geoshade core ingest$"):
        formats.ingested_by("C.UNRST", "core")
    with pytest.raises(InputError, match=r"^m\.nc: geoshade grid ingest does not take a GeoTOP "
                                         r"netCDF; it takes: GRDECL corner-point grid, "):
        formats.ingested_by("m.nc", "grid")


def test_core_ingest_refuses_a_grid_in_one_line(tmp_path):
    from geoshade.io.stores.ingest import ingest

    (tmp_path / "C.EGRID").write_bytes(b"")
    with pytest.raises(InputError, match="ingested by geoshade grid ingest"):
        ingest(tmp_path / "C.EGRID", tmp_path / "c.zarr")
    assert not (tmp_path / "c.zarr").exists()


def test_the_browser_lists_every_kind_load_reads_and_nothing_else(tmp_path):
    root = tmp_path / "data"
    root.mkdir()
    want = set()
    for f in FORMATS:
        name = _one_name(f)
        if name:
            (root / f"{f.name}{name[1:]}").write_bytes(b"")
            want.add(f"root/{f.name}{name[1:]}")
    store = root / "vol.zarr"
    (store / "0").mkdir(parents=True)
    (store / "zarr.json").write_text("{}")
    (store / "0" / "zarr.json").write_text("{}")   # inside a store: not listed
    slices = root / "scan"
    slices.mkdir()
    (slices / "s0.tif").write_bytes(b"")
    want |= {"root/vol.zarr", "root/scan"}
    for other in ("notes.txt", "model.vtk", "logs.parquet", "wells.csv", "a.gsgrid"):
        (root / other).write_bytes(b"")
    assert set(Catalog([], root=root).names()) == want


def test_info_reads_the_table(capsys, tmp_path):
    from geoshade.cli.main import main

    np.save(tmp_path / "v.npy", np.arange(24, dtype=np.uint8).reshape(2, 3, 4))
    assert main(["info", str(tmp_path / "v.npy"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["kind"] == "volume" and d["shape_xyz"] == [4, 3, 2]
    (tmp_path / "v.unknown").write_bytes(b"")
    assert main(["info", str(tmp_path / "v.unknown")]) == 2
    err = capsys.readouterr().err
    assert re.search(r"unknown file type '\.unknown'; expected one of: .*NumPy array", err)
