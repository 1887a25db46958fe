"""Acceptance: summary vectors of real OPM Flow runs (issue 33 item 1; the cursor of items 2, 6).

Cases: Reek (OPM Flow, METRIC, shared data), SPE1 (OPM Flow run at test time, FIELD units), the
same written formatted by resfo (FSMSPEC/FUNSMRY), SPE1 with hourly non-unified summary files
(S0001 …). Oracle: resfo's reading of the files -- each vector's PARAMS column found from
SMSPEC's KEYWORDS/WGNAMES/NUMS by this test, not by geoshade -- the CSV equal to 1e-5 relative
(equal in fact: float32 written to read back exactly), the units SMSPEC gives.
"""

from __future__ import annotations

import datetime
import json
import time

import numpy as np
import pytest

import geoshade
from geoshade.styles.summary_plot import SummaryPlot, step_at
from tests.acceptance import ecl_cases
from tests.acceptance.make_cases import SHARED, CaseUnavailableError

resfo = pytest.importorskip("resfo")
pd = pytest.importorskip("pandas")

REEK = SHARED / "reek_cornerpoint" / "opm_flow_run" / "2_R001_REEK-0"


@pytest.fixture(scope="module")
def reek():
    if not REEK.with_suffix(".SMSPEC").is_file():
        pytest.skip(f"{REEK}.SMSPEC is absent (see shared/data/README.md)")
    return REEK.with_suffix(".SMSPEC")


@pytest.fixture(scope="module")
def hourly():
    try:
        return ecl_cases.spe1_hourly()
    except CaseUnavailableError as err:
        pytest.skip(str(err))


def _oracle(spec, data_files, fmt=None):
    """resfo's SMSPEC arrays and the stacked PARAMS of ``data_files``."""
    kw = {} if fmt is None else {"fileformat": fmt}
    d = {k.strip(): a for k, a in resfo.read(spec, **kw)}
    names = d.get("WGNAMES", d.get("NAMES"))
    text = [[(x.decode() if isinstance(x, bytes) else x).strip() for x in d[k]]
            for k in ("KEYWORDS", "UNITS")] + [[(x.decode() if isinstance(x, bytes) else x)
                                                .strip() for x in names]]
    params = np.stack([a for f in data_files for k, a in resfo.read(f, **kw)
                       if k.strip() == "PARAMS"])
    return d, text, params


def _column(d, text, keyword, well=None, ijk=None) -> int:
    keywords, _, wg = text
    for i, k in enumerate(keywords):
        if k != keyword:
            continue
        if well is not None and wg[i] != well:
            continue
        if ijk is not None:
            nx, ny = int(d["DIMENS"][1]), int(d["DIMENS"][2])
            if int(d["NUMS"][i]) != ijk[0] + nx * (ijk[1] - 1) + nx * ny * (ijk[2] - 1):
                continue
        return i
    raise AssertionError(f"{keyword} {well} {ijk} not in the SMSPEC")


def _check_csv(csv, d, text, params, columns):
    df = pd.read_csv(csv)
    assert list(df.columns)[:2] == ["date", "days"]
    start = datetime.datetime(int(d["STARTDAT"][2]), int(d["STARTDAT"][1]),
                              int(d["STARTDAT"][0]))
    t = params[:, text[0].index("TIME")].astype(np.float64)
    want = [(start + datetime.timedelta(seconds=round(x * 86400))).isoformat() for x in t]
    assert df["date"].tolist() == want
    for name, idx in columns.items():
        got = df[name].to_numpy(np.float64)
        ref = params[:, idx].astype(np.float64)
        assert np.allclose(got, ref, rtol=1e-5, atol=0), name
        assert np.array_equal(got.astype(np.float32), params[:, idx]), name
    return df


def test_reek_csv_equals_resfo_and_the_plot_has_units(cli, reek, pictures, tmp_path):
    png, csv, stats = pictures / "summary_reek.png", tmp_path / "r.csv", tmp_path / "r.json"
    rc, _, err = cli("summary", reek.with_suffix(".UNRST"), "--vector", "FOPR", "--vector",
                       "FPR", "--vector", "WOPR:*", "--vector", "BPR:15,28,1", "-o", png,
                       "--csv", csv, "--stats", stats, "--cursor", "2001-06-01")
    assert rc == 0, err
    d, text, params = _oracle(reek, [reek.with_suffix(".UNSMRY")])
    wells = [w for k, w in zip(text[0], text[2], strict=True) if k == "WOPR" and
             w != ":+:+:+:+"]
    cols = {"FOPR": _column(d, text, "FOPR"), "FPR": _column(d, text, "FPR"),
            "BPR:15,28,1": _column(d, text, "BPR", ijk=(15, 28, 1))}
    cols.update({f"WOPR:{w}": _column(d, text, "WOPR", well=w) for w in wells})
    df = _check_csv(csv, d, text, params, cols)
    assert list(df.columns)[2:] == ["FOPR", "FPR", *[f"WOPR:{w}" for w in wells], "BPR:15,28,1"]
    assert len(df) == 42  # every ministep (38 report steps)
    s = json.loads(stats.read_text())
    units = {v["name"]: v["unit"] for v in s["vectors"]}
    assert units["FOPR"] == text[1][cols["FOPR"]] == "SM3/DAY" and units["FPR"] == "BARSA"
    assert [a["label"] for a in s["plot"]["axes"]] == ["SM3/DAY", "BARSA (dashed)"]
    assert s["plot"]["cursor"]["report_date"] == "2001-06-01T00:00:00"


def test_spe1_field_units_and_a_formatted_copy(cli, spe1, pictures, tmp_path):
    spec = spe1.with_suffix(".SMSPEC")
    args = ["--vector", "FOPR", "--vector", "WBHP:*", "--vector", "WGOR:PROD", "--vector",
            "BPR:10,10,3"]
    csv, stats = tmp_path / "b.csv", tmp_path / "b.json"
    rc, _, err = cli("summary", spe1.with_suffix(".DATA"), *args, "-o",
                     pictures / "summary_spe1_field.png", "--csv", csv, "--stats", stats)
    assert rc == 0, err
    d, text, params = _oracle(spec, [spe1.with_suffix(".UNSMRY")])
    cols = {"FOPR": _column(d, text, "FOPR"), "WBHP:INJ": _column(d, text, "WBHP", "INJ"),
            "WBHP:PROD": _column(d, text, "WBHP", "PROD"),
            "WGOR:PROD": _column(d, text, "WGOR", "PROD"),
            "BPR:10,10,3": _column(d, text, "BPR", ijk=(10, 10, 3))}
    _check_csv(csv, d, text, params, cols)
    s = json.loads(stats.read_text())
    assert s["unit_system"] == "FIELD"
    assert {v["name"]: v["unit"] for v in s["vectors"]} == {
        "FOPR": "STB/DAY", "WBHP:INJ": "PSIA", "WBHP:PROD": "PSIA", "WGOR:PROD": "MSCF/STB",
        "BPR:10,10,3": "PSIA"}
    assert [a["unit"] for a in s["plot"]["axes"]] == ["STB/DAY", "PSIA", "MSCF/STB"]
    # the same run written formatted by resfo: the same CSV, and resfo's formatted reading
    fmt = resfo.Format.FORMATTED
    resfo.write(tmp_path / "SPE1F.FSMSPEC", list(resfo.read(spec)), fileformat=fmt)
    resfo.write(tmp_path / "SPE1F.FUNSMRY", list(resfo.read(spe1.with_suffix(".UNSMRY"))),
                fileformat=fmt)
    fcsv = tmp_path / "f.csv"
    rc, _, err = cli("summary", tmp_path / "SPE1F.FUNSMRY", *args, "--csv", fcsv)
    assert rc == 0, err
    assert fcsv.read_text() == csv.read_text()
    fd, ftext, fparams = _oracle(tmp_path / "SPE1F.FSMSPEC", [tmp_path / "SPE1F.FUNSMRY"], fmt)
    _check_csv(fcsv, fd, ftext, fparams, cols)


def test_hourly_non_unified_summary_keeps_the_hour(cli, hourly, tmp_path):
    csv = tmp_path / "h.csv"
    rc, _, err = cli("summary", hourly.with_suffix(".X0003"), "--vector", "FOPR", "--vector",
                     "WBHP:PROD", "--csv", csv)
    assert rc == 0, err
    files = sorted(hourly.parent.glob("HOURLY.S[0-9][0-9][0-9][0-9]"))
    d, text, params = _oracle(hourly.with_suffix(".SMSPEC"), files)
    df = _check_csv(csv, d, text, params, {"FOPR": _column(d, text, "FOPR"),
                                           "WBHP:PROD": _column(d, text, "WBHP", "PROD")})
    assert df["date"].tolist()[:3] == ["2015-01-01T01:00:00", "2015-01-01T02:00:00",
                                       "2015-01-01T03:00:00"]


def test_the_api_table_and_the_cursor_following_the_restart_steps(reek, pictures):
    table = geoshade.load(reek.with_suffix(".EGRID"), as_="summary",
                          vectors=["FOPR", "FWPR", "FPR"])
    df = table.to_pandas()
    assert df.attrs["units"]["FPR"] == "BARSA" and len(df) == 42
    assert df.index[0] == pd.Timestamp("2000-01-02") and df["days"].iloc[0] == 1.0
    grid = geoshade.load(reek.with_suffix(".EGRID"))  # the steps a 3D view shows
    reports = grid.meta["unrst_seqnum"]
    plot = SummaryPlot(table, size=(800, 300), report_dates=grid.step_dates, reports=reports)
    top, bottom = plot.layout["axes"][0]["bbox"][1], plot.layout["axes"][0]["bbox"][3]
    t0 = time.perf_counter()
    for k, date in enumerate(grid.step_dates):
        plot.draw(date)  # the viewer moved to step k: the cursor follows
        cur = plot.layout["cursor"]
        assert cur["report"] == reports[k] and cur["report_date"].startswith(date)
        # a click where the cursor is gives that step back
        got = step_at(grid, plot.date_at(cur["x_px"], (top + bottom) / 2))
        assert got.index == k or grid.step_dates[got.index] == date
    ms = (time.perf_counter() - t0) / len(grid.step_dates) * 1000
    print(f"summary cursor: {ms:.1f} ms per step change and click (800x300, "
          f"{len(grid.step_dates)} steps)")
    from PIL import Image

    Image.fromarray(plot.draw(grid.step_dates[20])).save(pictures / "summary_reek_cursor.png")
    # a click between two restart steps goes to the nearest one and says so
    s = step_at(grid, "2001-06-20")
    assert grid.step_dates[s.index] == "2001-07-01" and "nearest report step" in s.text
