"""Summary files (issue 33): SMSPEC + UNSMRY, formatted, non-unified, from any file of a case,
into a SummaryTable; every value against resfo's reading of the same files."""

from __future__ import annotations

import datetime
import itertools
import json

import numpy as np
import pytest
import resfo

import geoshade
from geoshade.errors import InputError
from geoshade.io.grids.ecl_records import scan
from geoshade.io.grids.summary import (
    csv_text,
    read_spec,
    read_summary,
    summary_files,
    vector_of,
    write_summary,
)
from geoshade.models.summary_vectors import SummaryTable, SummaryVector, match_vectors

#: one entry of each kind (keyword, WGNAMES, NUMS, unit) on a 4 x 3 x 2 grid
ENTRIES = [("TIME", "", 0, "DAYS"), ("YEARS", "", 0, "YEARS"), ("FOPR", "", 0, "SM3/DAY"),
           ("FPR", "", 0, "BARSA"), ("WOPR", "P1", 0, "SM3/DAY"), ("WOPR", "P2", 0, "SM3/DAY"),
           ("WOPR", ":+:+:+:+", 0, "SM3/DAY"), ("WBHP", "P1", 0, "BARSA"),
           ("GOPR", "FIELD", 0, "SM3/DAY"), ("RPR", "", 2, "BARSA"),
           ("ROFT", "", 1 + 32768 * 13, "SM3"), ("BPR", "", 1 + 4 * 3 * 1 + 4 + 2, "BARSA"),
           ("COPR", "P1", 5, "SM3/DAY"), ("SOFR", "P1", 3, "SM3/DAY"), ("AAQR", "", 1, "SM3/DAY"),
           ("NPR", "NODE", 0, "BARSA"), ("BPR", "", 0, "BARSA"), ("FWCT", "", 0, "")]
KEYS = ["TIME", "YEARS", "FOPR", "FPR", "WOPR:P1", "WOPR:P2", "WBHP:P1", "GOPR:FIELD", "RPR:2",
        "ROFT:1-3", "BPR:3,2,2", "COPR:P1:1,2,1", "SOFR:P1:3", "AAQR:1", "NPR:NODE", "FWCT"]
DIMS = (4, 3, 2)


def _params(n: int = 7, m: int = len(ENTRIES)) -> np.ndarray:
    rng = np.random.default_rng(5)
    p = rng.random((n, m)).astype(np.float32) * 1000
    p[:, 0] = np.array([0.5, 1, 10, 31, 59.25, 90, 120], np.float32)[:n]
    return p


def _case(folder, name="C", formatted=False, reports=(1, 1, 2, 3, 3, 4, 5), **kw):
    spec = folder / f"{name}.{'F' if formatted else ''}SMSPEC"
    write_summary(spec, ENTRIES, _params(), dims=DIMS, reports=reports, formatted=formatted,
                  start=(15, 3, 2001), **kw)
    return spec


def _resfo_params(path, fmt=resfo.Format.UNFORMATTED) -> np.ndarray:
    return np.stack([a for k, a in resfo.read(path, fileformat=fmt) if k.strip() == "PARAMS"])


@pytest.mark.parametrize("formatted", [False, True], ids=["binary", "formatted"])
def test_every_value_equals_resfo(tmp_path, formatted):
    spec = _case(tmp_path, formatted=formatted)
    fmt = resfo.Format.FORMATTED if formatted else resfo.Format.UNFORMATTED
    ref = _resfo_params(spec.with_suffix(".FUNSMRY" if formatted else ".UNSMRY"), fmt)
    t = read_summary(spec)
    assert list(t.keys) == KEYS
    for v in t.vectors:
        assert np.array_equal(t[v.key], ref[:, v.index]), v.key
    assert t.values.dtype == np.float32 and t.nsteps == len(ref)
    assert t.start == datetime.datetime(2001, 3, 15)
    assert t.report.tolist() == [1, 1, 2, 3, 3, 4, 5] and t.report_index().tolist() == [1, 2, 4,
                                                                                          5, 6]
    assert t.meta["skipped"] == 2 and t.unit_system == "METRIC"
    assert t.meta["format"] == ("formatted" if formatted else "unformatted")


def test_records_of_several_blocks_and_a_damaged_block_marker(tmp_path):
    m = 2345  # PARAMS in three blocks of 1000 values
    entries = [("TIME", "", 0, "DAYS")] + [("WOPR", f"W{i}", 0, "SM3/DAY") for i in range(m - 1)]
    p = np.random.default_rng(2).random((9, m)).astype(np.float32)
    p[:, 0] = np.arange(1, 10)
    write_summary(tmp_path / "M.SMSPEC", entries, p, reports=[1, 1, 2, 2, 2, 3, 4, 4, 5])
    ref = _resfo_params(tmp_path / "M.UNSMRY")
    t = read_summary(tmp_path / "M.SMSPEC", ["WOPR:W2343", "WOPR:W0", "WOPR:W999", "WOPR:W1000"])
    assert np.array_equal(t.values, ref[:, [2344, 1, 1000, 1001]])
    assert t.report.tolist() == [1, 1, 2, 2, 2, 3, 4, 4, 5] and t.ministep.tolist() == \
        list(range(1, 10))
    assert np.array_equal(read_summary(tmp_path / "M.SMSPEC").values, ref)
    params = [r for r in scan(tmp_path / "M.UNSMRY") if r.keyword == "PARAMS"]
    raw = bytearray((tmp_path / "M.UNSMRY").read_bytes())
    at = params[4].start + 24 + 4008  # the second block's first marker of ministep 5
    raw[at:at + 4] = (77).to_bytes(4, "big")
    (tmp_path / "M.UNSMRY").write_bytes(bytes(raw))
    with pytest.raises(InputError, match=rf"M\.UNSMRY: PARAMS: damaged record at byte "
                                         rf"{params[4].start} \(a block marker at byte {at} "
                                         r"reads 77, not its block's size 4000\)"):
        read_summary(tmp_path / "M.SMSPEC", ["WOPR:W1500"])


def test_names_kinds_and_units_as_eclipse_names_them(tmp_path):
    spec = read_spec(_case(tmp_path))
    by = {v.key: v for v in spec.vectors}
    assert by["BPR:3,2,2"].ijk == (3, 2, 2) and by["BPR:3,2,2"].kind == "block"
    assert by["COPR:P1:1,2,1"].kind == "connection" and by["COPR:P1:1,2,1"].name == "P1"
    assert [by[k].kind for k in ("FOPR", "WOPR:P1", "GOPR:FIELD", "RPR:2", "ROFT:1-3",
                                 "SOFR:P1:3", "AAQR:1", "NPR:NODE", "TIME")] == [
        "field", "well", "group", "region", "region-flow", "segment", "aquifer", "network",
        "misc"]
    assert by["WBHP:P1"].unit == "BARSA" and by["FWCT"].unit_label() == "dimensionless"
    # local-grid vectors name their grid
    assert vector_of("LBPR", "", 0, DIMS, "LGR1", (1, 2, 3))[0] == "LBPR:LGR1:1,2,3"
    assert vector_of("LWBHP", "W", 0, DIMS, "LGR1", (0, 0, 0))[0] == "LWBHP:LGR1:W"
    assert vector_of("WNEWTON", "", 0, DIMS)[1] == "misc"


def test_any_file_of_the_case_finds_the_summary(tmp_path):
    spec = _case(tmp_path)
    for name in ("C.DATA", "C.EGRID", "C.UNRST", "C.X0003", "C.INIT"):
        (tmp_path / name).write_bytes(b"")
        assert summary_files(tmp_path / name).spec == spec
        assert geoshade.load(tmp_path / name, as_="summary").keys == tuple(KEYS)
    assert summary_files(tmp_path / "C.UNSMRY").data == [tmp_path / "C.UNSMRY"]
    # a formatted file of the case prefers the formatted summary
    _case(tmp_path, formatted=True)
    (tmp_path / "C.FEGRID").write_bytes(b"")
    assert summary_files(tmp_path / "C.FEGRID").spec.name == "C.FSMSPEC"
    assert summary_files(tmp_path / "C.EGRID").spec.name == "C.SMSPEC"


def test_a_lone_summary_loads_and_is_described_as_a_summary(tmp_path, capsys):
    spec = _case(tmp_path)
    t = geoshade.load(spec)
    assert isinstance(t, SummaryTable) and t.nsteps == 7
    assert geoshade.load(spec, as_="summary", vectors=["WOPR:*"]).keys == ("WOPR:P1", "WOPR:P2")
    from geoshade.cli.main import main

    assert main(["info", "--json", str(spec)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert (d["kind"], d["ministeps"], d["units"]) == ("summary", 7, "METRIC")
    assert d["vectors"] == ("16 (misc 2, field 3, well 3, group 1, region 1, region-flow 1, "
                            "block 1, connection 1, segment 1, aquifer 1, network 1)")


@pytest.mark.parametrize("formatted", [False, True], ids=["S0001", "A0001"])
def test_non_unified_summary_files(tmp_path, formatted):
    spec = _case(tmp_path, formatted=formatted)
    unified = read_summary(spec)
    data = spec.with_suffix(".FUNSMRY" if formatted else ".UNSMRY")
    fmt = resfo.Format.FORMATTED if formatted else resfo.Format.UNFORMATTED
    records = list(resfo.read(data, fileformat=fmt))
    data.unlink()
    starts = [i for i, (k, _) in enumerate(records) if k.strip() == "SEQHDR"] + [len(records)]
    letter = "A" if formatted else "S"
    for n, (a, b) in enumerate(itertools.pairwise(starts), 1):
        resfo.write(tmp_path / f"C.{letter}{n:04d}", records[a:b], fileformat=fmt)
    split = read_summary(tmp_path / f"C.{letter}0002")  # any file of the case
    assert np.array_equal(split.values, unified.values)
    assert np.array_equal(split.report, unified.report)
    assert len(split.meta["files"]) == 1 + 5


def test_hours_kept_and_lab_times_in_hours(tmp_path):
    p = _params()
    p[:, 0] = np.arange(1, 8) * 6  # hours
    entries = [("TIME", "", 0, "HOURS"), *ENTRIES[1:]]
    write_summary(tmp_path / "L.SMSPEC", entries, p, dims=DIMS, unit_system=3)
    t = read_summary(tmp_path / "L.SMSPEC", ["FPR"])
    assert t.iso_dates()[:3] == ["2000-01-01T06:00:00", "2000-01-01T12:00:00",
                                 "2000-01-01T18:00:00"]
    assert t.days[3] == 1.0 and t.unit_system == "LAB"


def test_time_from_day_month_year_without_time(tmp_path):
    entries = [("DAY", "", 0, ""), ("MONTH", "", 0, ""), ("YEAR", "", 0, ""), ("FPR", "", 0, "")]
    write_summary(tmp_path / "D.SMSPEC", entries,
                  np.array([[2, 1, 2000, 5], [1, 3, 2000, 6]], np.float32))
    t = read_summary(tmp_path / "D.SMSPEC", ["FPR"])
    assert t.days.tolist() == [1.0, 60.0] and t.iso_dates()[1] == "2000-03-01T00:00:00"


def test_unknown_vector_is_one_line_with_the_nearest_names(tmp_path):
    spec = _case(tmp_path)
    with pytest.raises(InputError) as e:
        read_summary(spec, ["WOPT:P1"])
    msg = str(e.value)
    assert msg.startswith(f"{spec}: no summary vector WOPT:P1; nearest: WOPR:P1")
    assert "\n" not in msg
    with pytest.raises(InputError, match=r"no summary vector matches QQ\*; 16 vectors"):
        read_summary(spec, ["QQ*"])
    assert match_vectors(KEYS, ["wopr:p2", "BPR:*", "F*"]) == ["WOPR:P2", "BPR:3,2,2", "FOPR",
                                                               "FPR", "FWCT"]


def test_damaged_and_incomplete_files_are_one_line(tmp_path):
    spec = _case(tmp_path)
    data = spec.with_suffix(".UNSMRY")
    whole = data.read_bytes()
    data.write_bytes(whole[: len(whole) - 40])
    with pytest.raises(InputError, match=r"C\.UNSMRY: PARAMS: .*truncated"):
        read_summary(spec)
    data.write_bytes(b"")
    with pytest.raises(InputError, match="the file is empty"):
        read_summary(spec)
    data.unlink()
    with pytest.raises(InputError, match=r"no summary data beside it \(looked for C\.UNSMRY"):
        read_summary(spec)
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "Z.EGRID").write_bytes(b"")
    with pytest.raises(InputError, match="no summary of case Z beside it"):
        read_summary(tmp_path / "other" / "Z.EGRID")
    # PARAMS shorter than the SMSPEC says; no TIME; a spec without KEYWORDS; time going back
    write_summary(tmp_path / "S.SMSPEC", ENTRIES, _params())
    resfo.write(tmp_path / "S.UNSMRY", [("SEQHDR  ", np.array([1], np.int32)),
                                        ("PARAMS  ", np.zeros(3, np.float32))])
    with pytest.raises(InputError, match=r"PARAMS of ministep 0: 3 values; expected 18"):
        read_summary(tmp_path / "S.SMSPEC")
    write_summary(tmp_path / "N.SMSPEC", ENTRIES[2:], _params()[:, 2:])
    with pytest.raises(InputError, match="TIME: not among the vectors"):
        read_summary(tmp_path / "N.SMSPEC")
    recs = [r for r in resfo.read(tmp_path / "S.SMSPEC") if r[0].strip() != "KEYWORDS"]
    resfo.write(tmp_path / "S.SMSPEC", recs)
    with pytest.raises(InputError, match="KEYWORDS: not found; expected an SMSPEC file"):
        read_summary(tmp_path / "S.SMSPEC")
    back = _params()
    back[3, 0] = 0.1
    write_summary(tmp_path / "B.SMSPEC", ENTRIES, back)
    with pytest.raises(InputError, match="ministep 3: the time goes backwards"):
        read_summary(tmp_path / "B.SMSPEC")


def test_csv_reads_back_exactly_with_pandas(tmp_path):
    pd = pytest.importorskip("pandas")
    t = read_summary(_case(tmp_path))
    path = tmp_path / "out.csv"
    path.write_text(csv_text(t))
    df = pd.read_csv(path)
    assert list(df.columns) == ["date", "days", *KEYS]
    assert df["date"].tolist() == t.iso_dates()
    for k in KEYS:
        assert np.array_equal(df[k].to_numpy(np.float32), t[k]), k
    assert np.array_equal(df["days"].to_numpy(), t.days)


def test_to_pandas_and_to_xarray(tmp_path):
    pytest.importorskip("pandas")
    pytest.importorskip("xarray")
    t = read_summary(_case(tmp_path), ["FOPR", "WBHP:P1", "BPR:*"])
    df = t.to_pandas()
    assert list(df.columns) == ["days", "FOPR", "WBHP:P1", "BPR:3,2,2"]
    assert df.index.name == "time" and str(df.index[0]) == "2001-03-15 12:00:00"
    assert df.attrs["units"]["WBHP:P1"] == "BARSA" and df.attrs["kinds"]["BPR:3,2,2"] == "block"
    assert np.array_equal(df["FOPR"].to_numpy(), t["FOPR"])
    ds = t.to_xarray()
    assert ds["FOPR"].attrs["units"] == "SM3/DAY" and ds["report"].values.tolist() == \
        t.report.tolist()
    assert np.array_equal(ds["days"].values, t.days)


def test_the_model_checks_its_contract():
    v = [SummaryVector("FPR", "FPR", "field")]
    start = datetime.datetime(2000, 1, 1)
    with pytest.raises(InputError, match=r"values: expected shape \(n, m\) = \(2, 1\)"):
        SummaryTable([1.0, 2.0], np.zeros((2, 2), np.float32), v, start)
    with pytest.raises(InputError, match="never decrease"):
        SummaryTable([2.0, 1.0], np.zeros((2, 1), np.float32), v, start)
    with pytest.raises(InputError, match="FPR repeated"):
        SummaryTable([1.0], np.zeros((1, 2), np.float32), v * 2, start)
    with pytest.raises(InputError, match=r"report: expected shape \(1,\)"):
        SummaryTable([1.0], np.zeros((1, 1), np.float32), v, start, report=[1, 2])
    t = SummaryTable([1.0], np.zeros((1, 1), np.float32), v, start)
    assert "FPR" in t and "fpr" in t and "WOPR" not in t
    assert "SummaryTable" in repr(t) and "1 in 1 report steps" in repr(t)
