"""ECLIPSE cases as users have them (issue 14): formatted files (``.FEGRID .FINIT .FUNRST``),
non-unified restarts (``.X0001``, ``.F0001``), a case opened from any of its files.

Oracles: resfo's own formatted reader (record by record) and the binary case written from the
same arrays (grids, properties and every report step equal); the real OPM run of Reek converted
to formatted and split into non-unified files with resfo in ``tmp_path``.
"""

from __future__ import annotations

import json
import random
import re
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
import resfo

from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.grids import ecl_records as er
from geoshade.io.grids.ecl import LazyStep, case_files, is_case_file, load_case
from geoshade.io.grids.ecl_records import RecordError, scan
from tests.corruption import clean_failure, run_cli
from tests.io.test_corrupt_grids import (
    NSTEPS,
    _egrid_entries,
    _grid,
    _init_entries,
    _unrst_entries,
)

FMT, BIN = resfo.Format.FORMATTED, resfo.Format.UNFORMATTED


# --- writers -----------------------------------------------------------------------------------
def _steps(entries) -> list[tuple[int, list]]:
    """Unified restart entries -> [(SEQNUM, the step's other entries)]."""
    out: list[tuple[int, list]] = []
    for kw, arr in entries:
        if kw.strip() == "SEQNUM":
            out.append((int(np.asarray(arr)[0]), []))
        else:
            out[-1][1].append((kw, arr))
    return out


def _split(unrst_entries, folder: Path, stem: str, fmt=BIN, seqnum=False) -> list[Path]:
    """Non-unified files ``STEM.X0010`` (``.F0010`` formatted) from unified entries; ``seqnum``
    keeps each step's SEQNUM in its file (ECLIPSE and OPM write none there)."""
    files = []
    for seq, rest in _steps(unrst_entries):
        f = folder / f"{stem}.{'F' if fmt == FMT else 'X'}{seq:04d}"
        head = [("SEQNUM  ", np.array([seq], np.int32))] if seqnum else []
        resfo.write(f, head + rest, fmt)
        files.append(f)
    return files


def _entries(path: Path):
    return [(e.read_keyword(), e.read_array()) for e in resfo.lazy_read(str(path))]


def _synthetic(folder: Path, fmt=BIN, unified=True, g=None) -> Path:
    """CASE.EGRID/INIT/UNRST (formatted: .FEGRID/.FINIT/.FUNRST), or X/F files."""
    g = _grid() if g is None else g
    folder.mkdir(parents=True, exist_ok=True)
    f = "F" if fmt == FMT else ""
    resfo.write(folder / f"CASE.{f}EGRID", _egrid_entries(g), fmt)
    resfo.write(folder / f"CASE.{f}INIT", _init_entries(g), fmt)
    if unified:
        resfo.write(folder / f"CASE.{f}UNRST", _unrst_entries(g), fmt)
    else:
        _split(_unrst_entries(g), folder, "CASE", fmt)
    return folder / f"CASE.{f}EGRID"


def _same_case(a, b, steps: bool = True) -> None:
    """Two grids read from the same case: geometry, properties, steps, dates, report numbers."""
    assert a.dims == b.dims and a.units == b.units
    assert np.array_equal(a.zcorn, b.zcorn) and np.array_equal(a.coord, b.coord)
    assert np.array_equal(a.actnum, b.actnum) and np.array_equal(a.mapaxes, b.mapaxes)
    assert sorted(a.properties) == sorted(b.properties)
    for name, v in a.properties.items():
        assert v.dtype == b.properties[name].dtype, name
        assert np.array_equal(v, b.properties[name], equal_nan=True), name
    if steps:
        assert len(a.steps) == len(b.steps) > 0
        assert a.step_dates == b.step_dates
        assert a.meta["unrst_seqnum"] == b.meta["unrst_seqnum"]
        assert a.meta["step_keywords"] == b.meta["step_keywords"]
        for k, (sa, sb) in enumerate(zip(a.steps, b.steps, strict=True)):
            assert sorted(sa) == sorted(sb), k
            for name in sa:
                assert np.array_equal(sa[name], sb[name], equal_nan=True), (k, name)


# --- the formatted reader against resfo's ------------------------------------------------------
def test_formatted_records_equal_resfo(tmp_path):
    entries = [("INTEHEAD", np.arange(-5, 406, dtype=np.int32)),
               ("LOGIHEAD", np.array([True, False] * 60 + [True])),
               ("DOUBHEAD", np.linspace(-1e300, 1e-300, 229)),
               ("KEYS    ", np.array(["a", "bcd efgh", "x"] * 40)),
               ("LONGNAME", np.array(["abcdefghij", "x"])),  # C010
               ("STARTSOL", resfo.MESS),
               ("SWAT    ", np.linspace(-1, 1, 2500, dtype=np.float32) ** 3 * 1e6),
               ("EMPTY   ", np.zeros(0, np.int32)), ("ENDSOL  ", resfo.MESS)]
    f = tmp_path / "S.FUNRST"
    resfo.write(f, entries, FMT)
    ref = [(e.read_keyword().strip(), e.read_type().decode(), e.read_array())
           for e in resfo.lazy_read(str(f), FMT)]
    recs = list(scan(f))
    assert [(r.keyword, r.type, r.length) for r in recs] == [
        (k, t, 0 if t == "MESS" else len(a)) for k, t, a in ref]
    assert all(r.formatted for r in recs) and recs[-1].end == f.stat().st_size
    for (kw, t, a), r in zip(ref, recs, strict=True):
        got = r.read()
        if t == "MESS":
            assert got.size == 0
        elif a.dtype.kind == "U":  # strings come as bytes, as from a binary file
            assert got.dtype.kind == "S" and [s.decode() for s in got] == a.tolist(), kw
        else:
            assert got.dtype.kind == a.dtype.kind and np.array_equal(got, a), kw


def test_formatted_reader_is_fast_and_lazy(tmp_path, monkeypatch):
    """Scanning counts values without parsing them; blocks smaller than a record work."""
    g = _grid()
    f = tmp_path / "CASE.FUNRST"
    resfo.write(f, _unrst_entries(g), FMT)
    monkeypatch.setattr(er, "FORMATTED_BLOCK", 1000)  # headers and values cut by blocks
    small = [(r.keyword, r.length, r.start, r.data, r.end) for r in scan(f)]
    monkeypatch.undo()
    assert small == [(r.keyword, r.length, r.start, r.data, r.end) for r in scan(f)]
    swat = [r for r in scan(f) if r.keyword == "SWAT"]
    monkeypatch.setattr(er, "FORMATTED_BLOCK", 777)
    assert [np.array_equal(r.read(), a) for r, (kw, a) in
            zip(swat, [e for e in _unrst_entries(g) if e[0].strip() == "SWAT"], strict=True)] \
        == [True] * NSTEPS


def test_truncated_formatted_files_give_one_line(tmp_path):
    """Every cut of a formatted file: the complete records before it, then one line naming the
    file; never a wrong value (a cut number would still parse: the file must end a line)."""
    f = tmp_path / "S.FINIT"
    resfo.write(f, [("INTEHEAD", np.arange(411, dtype=np.int32)),
                    ("KEYS    ", np.array(["ab"] * 9)),
                    ("PORO    ", np.linspace(0, 0.3, 50, dtype=np.float32))], FMT)
    text = f.read_bytes()
    ref = [r.read() for r in scan(f)]
    cut_file = tmp_path / "C.FINIT"
    rng = random.Random(3)
    cuts = sorted({*range(1, 80), *range(len(text) - 80, len(text)),
                   *(rng.randrange(1, len(text)) for _ in range(150))})
    kinds = set()
    for cut in cuts:
        cut_file.write_bytes(text[:cut])
        got: list[np.ndarray] = []
        try:
            for r in scan(cut_file):
                got.append(r.read())
        except InputError as err:
            msg = str(err)
            assert "\n" not in msg and msg.startswith(str(cut_file)), msg
            kinds.add(re.sub(r"\d+", "N", msg[len(str(cut_file)) + 2:]))
        for a, b in zip(ref, got, strict=False):  # what was read is right
            assert np.array_equal(a, b), cut
    assert any("the file ends after N of its N values" in k for k in kinds), kinds
    assert any("ends inside a value, without a line end" in k for k in kinds), kinds
    assert any("ends inside the header" in k for k in kinds), kinds


def test_damaged_formatted_values_give_one_line(tmp_path):
    f = tmp_path / "S.FINIT"
    resfo.write(f, [("INTEHEAD", np.arange(411, dtype=np.int32)),
                    ("PORO    ", np.linspace(0, 0.3, 50, dtype=np.float32)),
                    ("ACTNUM  ", np.ones(20, np.int32))], FMT)
    text = f.read_text()
    cases = {
        "a letter in numbers": (text.replace("1.22448979E-02", "1.2244x979E-02"), "PORO",
                                "could not convert"),
        "a value too many": (text.replace("'ACTNUM  '          20", "'ACTNUM  '          19"),
                             "ACTNUM", "20 values where its header announces 19"),
        "a damaged header": (text.replace("'PORO    '          50 'REAL'",
                                          "'PORO    '          5x 'REAL'"), "",
                             "damaged record header at byte"),
        "an unknown type": (text.replace("'REAL'", "'RE4L'"), "PORO", "bad header"),
    }
    for what, (bad, kw, expect) in cases.items():
        assert bad != text, what
        f.write_text(bad)
        with pytest.raises(InputError) as ei:
            for r in scan(f):
                r.read()
        msg = str(ei.value)
        assert "\n" not in msg and msg.startswith(f"{f}: {kw}") and expect in msg, (what, msg)


# --- formatted cases ---------------------------------------------------------------------------
def test_formatted_case_equals_binary_from_any_file(tmp_path):
    binary = load(_synthetic(tmp_path / "b"))
    _synthetic(tmp_path / "f", FMT)
    for name in ("CASE.FEGRID", "CASE.FINIT", "CASE.FUNRST"):
        case = load(tmp_path / "f" / name)
        assert case.meta["format"] == "FEGRID"
        assert case.meta["restart"]["format"] == "formatted"
        _same_case(binary, case)
    lazy = load_case(tmp_path / "f" / "CASE.FINIT", eager_bytes=0)
    assert all(isinstance(s, LazyStep) for s in lazy.steps)
    _same_case(binary, lazy)


def test_a_formatted_restart_beside_a_binary_grid(tmp_path):
    """Mixed cases: the format of the file given comes first, the other is used when alone."""
    g = _grid()
    d = tmp_path / "m"
    _synthetic(d)
    (d / "CASE.UNRST").unlink()
    resfo.write(d / "CASE.FUNRST", _unrst_entries(g), FMT)
    case = load(d / "CASE.EGRID")
    assert case.meta["restart"]["files"] == [str(d / "CASE.FUNRST")]
    _same_case(load(_synthetic(tmp_path / "b")), case)
    resfo.write(d / "CASE.FINIT", _init_entries(g), FMT)
    assert case_files(d / "CASE.FUNRST").init == d / "CASE.FINIT"
    assert case_files(d / "CASE.EGRID").init == d / "CASE.INIT"


# --- non-unified restarts ----------------------------------------------------------------------
@pytest.mark.parametrize("fmt", [BIN, FMT], ids=["X", "F"])
def test_non_unified_equals_unified(tmp_path, fmt):
    unified = load(_synthetic(tmp_path / "u"))
    d = tmp_path / "n"
    _synthetic(d, unified=False)
    for f in d.glob("CASE.X*"):
        f.unlink()
    files = _split(_unrst_entries(_grid()), d, "CASE", fmt, seqnum=fmt == FMT)
    assert [f.name[-5:] for f in files] == [f"{'F' if fmt == FMT else 'X'}{10 * k:04d}"
                                           for k in range(NSTEPS)]
    for opened in (d / "CASE.EGRID", d / "CASE.INIT", files[1]):
        case = load(opened)
        _same_case(unified, case)
        assert case.meta["restart"]["kind"] == "non-unified"
        assert case.meta["restart"]["files"] == [str(f) for f in files]
        assert case.meta["unrst_seqnum"] == [0, 10, 20]  # the report numbers of the names
    lazy = load_case(files[0], eager_bytes=0)
    _same_case(unified, lazy)


def test_unified_preferred_and_said(tmp_path):
    d = tmp_path / "both"
    _synthetic(d)
    files = _split(_unrst_entries(_grid()), d, "CASE")
    case = load(d / "CASE.EGRID")
    r = case.meta["restart"]
    assert r["kind"] == "unified" and r["files"] == [str(d / "CASE.UNRST")]
    assert r["unused"] == [str(f) for f in files]
    assert r["summary"] == ("CASE.UNRST (unified, unformatted); not used: CASE.X0000 … "
                            "CASE.X0020 (3 files)")
    given = load(files[0])  # the restart file given is the one used
    assert given.meta["restart"]["kind"] == "non-unified"
    assert given.meta["restart"]["unused"] == [str(d / "CASE.UNRST")]
    _same_case(case, given)


def test_steps_stay_lazy(tmp_path, monkeypatch):
    """Opening a case reads no cell array of a restart; a step's array is read on access."""
    d = tmp_path / "n"
    _synthetic(d, unified=False)
    _synthetic(tmp_path / "f", FMT)
    reads: list[str] = []
    real = er.Record.read

    def counted(self, kinds=None):
        reads.append(f"{self.path.suffix} {self.keyword}")
        return real(self, kinds)

    monkeypatch.setattr(er.Record, "read", counted)
    for path in (d / "CASE.X0010", tmp_path / "f" / "CASE.FUNRST"):
        reads.clear()
        case = load_case(path, eager_bytes=0)
        restart = [r for r in reads if r.split()[0] not in (".EGRID", ".INIT", ".FEGRID",
                                                              ".FINIT")]
        assert {r.split()[1] for r in restart} <= {"INTEHEAD", "SEQNUM"}, restart
        reads.clear()
        assert case.steps[2]["SWAT"].shape == case.dims
        assert len(reads) == 1 and reads[0].endswith("SWAT"), reads


def test_damaged_non_unified_files(capsys, tmp_path):
    g = _grid()
    d = tmp_path / "n"
    egrid = _synthetic(d, unified=False)
    last, middle = d / "CASE.X0020", d / "CASE.X0010"
    good = {f: f.read_bytes() for f in (last, middle)}
    # a killed run: the last file cut inside SWAT -> the steps before and one warning
    last.write_bytes(good[last][: len(good[last]) - 100])
    with pytest.warns(UserWarning, match=r"CASE.X0020: report step 2 \(CASE.X0020\) is "
                                         r"incomplete \(the file ends inside SWAT\); read the "
                                         r"2 complete report steps before it"):
        case = load(egrid)
    assert len(case.steps) == 2 and case.meta["unrst_seqnum"] == [0, 10]
    last.write_bytes(good[last])
    # the same damage before the last file: one line naming it, exit code of bad input
    middle.write_bytes(good[middle][: len(good[middle]) - 100])
    line = clean_failure(capsys, ["info", egrid], inputs=[d], watch=[d], names="CASE.X0010",
                         expect="report step 1 (CASE.X0010) is incomplete (the file ends "
                                "inside SWAT); a restart file of the case is damaged")
    assert line.startswith("geoshade: error:")
    for _what, damage, expect in (
            ("empty", lambda p: p.write_bytes(b""), "the file is empty"),
            ("formatted under X",
             lambda p: resfo.write(p, _steps(_unrst_entries(g))[1][1], FMT),
             "a formatted (text) ECLIPSE file under the binary name .X0010; expected the "
             "unformatted (binary) file a simulator writes (a formatted one is named .F0010)"),
            ("a cut at a record boundary",
             lambda p: resfo.write(p, _steps(_unrst_entries(g))[1][1][:4]),
             "it lacks PRESSURE, SWAT, ENDSOL that step 0 has; the file ends after STARTSOL"),
            ("a SEQNUM of another report", lambda p: resfo.write(
                p, [("SEQNUM  ", np.array([11], np.int32)), *_steps(_unrst_entries(g))[1][1]]),
             "SEQNUM: report 11 in a file named for report 10")):
        damage(middle)
        clean_failure(capsys, ["info", egrid], inputs=[d], watch=[d], names="CASE.X0010",
                      expect=expect)
        middle.write_bytes(good[middle])
    rc, out, err = run_cli(capsys, ["info", "--json", egrid])
    assert rc == 0 and json.loads(out)["steps"] == NSTEPS, err


def test_truncated_formatted_restart_keeps_complete_steps(tmp_path):
    """A cut FUNRST (a killed run) gives the steps wholly before the cut, as a cut UNRST does."""
    d = tmp_path / "f"
    _synthetic(d, FMT)
    f = d / "CASE.FUNRST"
    text = f.read_bytes()
    ends = [m.end() for m in re.finditer(rb"'ENDSOL  '\s+0 'MESS'", text)]
    ref = load(d / "CASE.FEGRID")
    rng = random.Random(5)
    for cut in sorted({*(rng.randrange(ends[0] - 50, len(text)) for _ in range(40)),
                       *(e + dd for e in ends[:-1] for dd in (-1, 0, 1, 2, 30))}):
        f.write_bytes(text[:cut])
        complete = sum(e <= cut for e in ends)
        rest = text[ends[complete - 1]:cut].strip() if complete else b"x"
        if not complete:
            with pytest.raises(InputError, match="no complete report step"):
                load_case(d / "CASE.FEGRID")
            continue
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            case = load_case(d / "CASE.FEGRID")
        assert len(case.steps) == complete, cut
        assert bool(seen) == bool(rest), (cut, [str(w.message) for w in seen])
        for k in range(complete):
            assert np.array_equal(case.steps[k]["SWAT"], ref.steps[k]["SWAT"], equal_nan=True)


# --- any file of a case ------------------------------------------------------------------------
def test_info_accepts_any_file_of_a_case(capsys, tmp_path):
    _synthetic(tmp_path / "b")
    _split(_unrst_entries(_grid()), tmp_path / "b", "CASE")
    _synthetic(tmp_path / "f", FMT)
    _split(_unrst_entries(_grid()), tmp_path / "f", "CASE", FMT)
    (tmp_path / "b" / "CASE.SMSPEC").write_bytes(b"")
    names = {"b": ["CASE.EGRID", "CASE.INIT", "CASE.UNRST", "CASE.X0010", "CASE.SMSPEC"],
             "f": ["CASE.FEGRID", "CASE.FINIT", "CASE.FUNRST", "CASE.F0020"]}
    for folder, files in names.items():
        for name in files:
            rc, out, err = run_cli(capsys, ["info", "--json", tmp_path / folder / name])
            assert rc == 0, err
            d = json.loads(out)
            assert d["steps"] == NSTEPS and d["dims"] == list(_grid().dims), name
            assert {"PORO", "PERMX", "FIPNUM", "PORV"} <= set(d["properties"])
    assert [is_case_file(n) for n in ("A.x0001", "A.f9999", "A.X001", "A.Y0001")] == \
        [True, True, False, False]


def test_a_case_file_without_its_grid_is_one_line(capsys, tmp_path):
    d = tmp_path / "nogrid"
    _synthetic(d)
    (d / "CASE.EGRID").unlink()
    clean_failure(capsys, ["info", d / "CASE.UNRST"], inputs=[d], watch=[d], names="CASE.UNRST",
                  expect=f"no grid of case CASE beside it (looked for CASE.EGRID, "
                         f"CASE.FEGRID and CASE.GRID in {d}); an ECLIPSE/OPM case is opened "
                         "with its EGRID (or old GRID)")
    f = tmp_path / "f"
    _synthetic(f, FMT)
    (f / "CASE.FINIT").unlink()
    case = load(f / "CASE.FUNRST")  # no INIT: the geometry and the steps, and what is missing
    assert case.steps and not case.properties
    assert case.meta["notes"] == ["no INIT beside the grid: CASE.FINIT would add its properties"]


# --- the real OPM run of Reek ------------------------------------------------------------------
@pytest.fixture(scope="module")
def reek(shared_data) -> Path:
    d = shared_data / "reek_cornerpoint" / "opm_flow_run"
    if not (d / "2_R001_REEK-0.UNRST").is_file():
        pytest.skip("Reek OPM run is absent")
    return d / "2_R001_REEK-0"


@pytest.fixture(scope="module")
def reek_binary(reek):
    return load(reek.with_suffix(".EGRID"))


@pytest.fixture(scope="module")
def reek_formatted(tmp_path_factory, reek) -> Path:
    """Reek's EGRID, INIT and UNRST written formatted by resfo (``R.FEGRID`` ...), once: the
    tests read them, never change them."""
    d = tmp_path_factory.mktemp("reek_formatted")
    for ext in ("EGRID", "INIT", "UNRST"):
        resfo.write(d / f"R.F{ext}", _entries(reek.with_suffix(f".{ext}")), FMT)
    return d


@pytest.mark.data
def test_reek_formatted_equals_binary(reek_formatted, reek_binary):
    tmp_path = reek_formatted
    case = load(tmp_path / "R.FUNRST")
    assert len(case.steps) == 37 and case.nactive == 35817
    _same_case(reek_binary, case)
    lazy = load_case(tmp_path / "R.FEGRID", eager_bytes=0)
    for k in (0, 17, 36):
        for name in ("SWAT", "PRESSURE", "SGAS"):
            assert np.array_equal(lazy.steps[k][name], reek_binary.steps[k][name],
                                  equal_nan=True)


@pytest.mark.data
def test_reek_non_unified_equals_unified(tmp_path, reek, reek_binary):
    shutil.copy(reek.with_suffix(".EGRID"), tmp_path / "R.EGRID")
    shutil.copy(reek.with_suffix(".INIT"), tmp_path / "R.INIT")
    files = _split(_entries(reek.with_suffix(".UNRST")), tmp_path, "R")
    assert len(files) == 37 and files[-1].name == "R.X0037"  # OPM skipped report 36
    case = load(files[5])
    _same_case(reek_binary, case)
    assert case.meta["unrst_seqnum"] == [*range(36), 37]
    assert case.meta["restart"]["summary"] == ("R.X0000 … R.X0037 (37 files) (non-unified, "
                                               "unformatted)")


@pytest.mark.data
def test_reek_formatted_restart_is_not_read_whole(tmp_path, reek, reek_formatted, reek_binary):
    """Records are parsed only when used: opening indexes, one step reads one array."""
    shutil.copy(reek_formatted / "R.FUNRST", tmp_path / "R.FUNRST")
    shutil.copy(reek.with_suffix(".EGRID"), tmp_path / "R.EGRID")
    shutil.copy(reek.with_suffix(".INIT"), tmp_path / "R.INIT")
    case = load_case(tmp_path / "R.FUNRST", eager_bytes=0)
    index = case.meta["unrst"]
    assert len(index) == 37 and index.keywords == ["PRESSURE", "SGAS", "SWAT"]
    assert "_cache" not in index.__dict__
    assert np.array_equal(case.steps[36]["SWAT"], reek_binary.steps[36]["SWAT"], equal_nan=True)
    assert list(index.__dict__["_cache"]) == [(36, "SWAT")]


def test_record_errors_keep_their_kind(tmp_path):
    """A formatted record's damage is a RecordError (the UNRST index keeps the steps before)."""
    f = tmp_path / "S.FUNRST"
    resfo.write(f, [("SEQNUM  ", np.array([1], np.int32))], FMT)
    f.write_text(f.read_text().replace("1\n", "1 2\n"))
    with pytest.raises(RecordError):
        list(scan(f))


def test_fields_over_time_from_any_file_of_a_case(tmp_path):
    """``load_field`` (``iso render``) opens a formatted or non-unified case from any of its
    files, with the same steps as the binary unified one."""
    from geoshade.io.fields import load_field

    ref = load_field(_synthetic(tmp_path / "b"), keyword="SWAT")
    _synthetic(tmp_path / "f", FMT)
    _synthetic(tmp_path / "x", unified=False)
    for path in (tmp_path / "f" / "CASE.FEGRID", tmp_path / "f" / "CASE.FUNRST",
                 tmp_path / "x" / "CASE.X0010", tmp_path / "x" / "CASE.INIT"):
        f = load_field(path, keyword="swat")
        assert f.nsteps == ref.nsteps, path
        for k in range(ref.nsteps):
            np.testing.assert_array_equal(f.step(k), ref.step(k))
