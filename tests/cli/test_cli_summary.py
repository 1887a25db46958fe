"""``geoshade summary CASE`` end to end (issue 33 item 1): the list, the plot, the CSV and the
stats of a small case written through resfo; bad input is one line and leaves no file."""

from __future__ import annotations

import json

import numpy as np
import pytest
import resfo
from PIL import Image

from geoshade.io.grids.summary import write_summary
from tests.corruption import clean_failure, run_cli

ENTRIES = [("TIME", "", 0, "DAYS"), ("FOPR", "", 0, "STB/DAY"), ("FPR", "", 0, "PSIA"),
           ("WOPR", "PROD", 0, "STB/DAY"), ("WOPR", "P2", 0, "STB/DAY"),
           ("WBHP", "PROD", 0, "PSIA"), ("BPR", "", 2 + 2 * 1 + 6 * 1, "PSIA"),
           ("FWCT", "", 0, "")]


@pytest.fixture
def case(tmp_path):
    """A FIELD-units case: 30 ministeps in 10 report steps, hourly at first."""
    n = 30
    rng = np.random.default_rng(1)
    p = (rng.random((n, len(ENTRIES))) * 1000).astype(np.float32)
    p[:, 0] = np.concatenate([np.arange(1, 11) / 24.0, 1 + np.arange(1, 21) * 10.0])
    write_summary(tmp_path / "CASE.SMSPEC", ENTRIES, p, start=(1, 1, 2015), dims=(2, 3, 2),
                  reports=np.repeat(np.arange(1, 11), 3), unit_system=2)
    (tmp_path / "CASE.DATA").write_text("RUNSPEC\n")
    return tmp_path / "CASE.SMSPEC", p


def test_list_names_units_and_kinds(capsys, case):
    spec, _ = case
    rc, out, err = run_cli(capsys, ["summary", spec.with_suffix(".DATA"), "--list"])
    assert rc == 0, err
    lines = out.splitlines()
    assert lines[0] == "CASE.SMSPEC + CASE.UNSMRY: 8 of 8 vectors, FIELD units"
    rows = [ln.split() for ln in lines[1:]]
    assert ["WBHP:PROD", "PSIA", "well"] in rows and ["BPR:2,2,2", "PSIA", "block"] in rows
    assert ["FWCT", "-", "field"] in rows
    rc, out, _ = run_cli(capsys, ["summary", spec, "--list", "--vector", "WOPR:*"])
    assert [ln.split()[0] for ln in out.splitlines()[1:]] == ["WOPR:PROD", "WOPR:P2"]


def test_plot_csv_and_stats(capsys, case, tmp_path):
    spec, _ = case
    png, csv, stats = tmp_path / "plot.png", tmp_path / "out.csv", tmp_path / "s.json"
    rc, out, err = run_cli(capsys, ["summary", spec.with_suffix(".DATA"), "--vector", "FOPR",
                                    "--vector", "WBHP:PROD", "--vector", "WOPR:*", "-o", png,
                                    "--csv", csv, "--stats", stats, "--cursor", "R5",
                                    "--size", "640x400"])
    assert rc == 0, err
    assert "4 vectors (FOPR, WBHP:PROD, WOPR:PROD, WOPR:P2), 30 ministeps in 10 report " \
           "steps" in out
    assert Image.open(png).size == (640, 400)
    import pandas as pd

    df = pd.read_csv(csv)
    assert list(df.columns) == ["date", "days", "FOPR", "WBHP:PROD", "WOPR:PROD", "WOPR:P2"]
    ref = np.stack([a for k, a in resfo.read(spec.with_suffix(".UNSMRY"))
                    if k.strip() == "PARAMS"])
    for col, idx in (("FOPR", 1), ("WBHP:PROD", 5), ("WOPR:PROD", 3), ("WOPR:P2", 4)):
        assert np.array_equal(df[col].to_numpy(np.float32), ref[:, idx]), col
    assert df["date"].iloc[0] == "2015-01-01T01:00:00" and df["date"].iloc[9] == \
        "2015-01-01T10:00:00"
    s = json.loads(stats.read_text())
    assert s["unit_system"] == "FIELD" and s["ministeps"] == 30 and s["report_steps"] == 10
    by = {v["name"]: v for v in s["vectors"]}
    assert by["WBHP:PROD"]["unit"] == "PSIA" and by["FOPR"]["max"] == float(ref[:, 1].max())
    plot = s["plot"]
    assert [a["unit"] for a in plot["axes"]] == ["STB/DAY", "PSIA"]
    # report 5 ends at ministep 15 (index 14)
    assert plot["cursor"]["report"] == 5
    assert plot["cursor"]["date"] == df["date"].iloc[14]


def test_bad_inputs_are_one_line_and_leave_nothing(capsys, case, tmp_path):
    spec, _ = case
    inputs = [spec, spec.with_suffix(".UNSMRY")]
    png = tmp_path / "x.png"
    line = clean_failure(capsys, ["summary", spec, "--vector", "WOPT:PROD", "-o", png],
                         inputs=inputs, watch=[tmp_path], expect="nearest: WOPR:PROD")
    assert "WOPT:PROD" in line
    clean_failure(capsys, ["summary", spec, "-o", png], inputs=inputs, watch=[tmp_path],
                  names="--vector", expect="--vector FOPR")
    clean_failure(capsys, ["summary", spec, "--vector", "FOPR", "--csv", png], inputs=inputs,
                  watch=[tmp_path], names="--csv", expect=".csv")
    clean_failure(capsys, ["summary", spec, "--vector", "FOPR", "-o", png, "--cursor", "R99"],
                  inputs=inputs, watch=[tmp_path], names="--cursor")
    clean_failure(capsys, ["summary", spec, "--vector", "FOPR", "--csv", tmp_path / "a.csv",
                           "--cursor", "R2"], inputs=inputs, watch=[tmp_path],
                  names="--cursor", expect="give -o")
    clean_failure(capsys, ["summary", spec], inputs=inputs, watch=[tmp_path],
                  names="nothing to do")
    clean_failure(capsys, ["summary", tmp_path / "NONE.EGRID", "--list"], watch=[tmp_path],
                  names="NONE.EGRID", expect="no such file")
    (tmp_path / "OTHER.EGRID").write_bytes(b"")
    clean_failure(capsys, ["summary", tmp_path / "OTHER.EGRID", "--list"], watch=[tmp_path],
                  names="OTHER.EGRID", expect="no summary of case OTHER")
    # the summary data damaged after the check of the outputs: no output is left behind
    data = spec.with_suffix(".UNSMRY")
    data.write_bytes(data.read_bytes()[:-30])
    clean_failure(capsys, ["summary", spec, "--vector", "FOPR", "-o", png, "--csv",
                           tmp_path / "a.csv"], inputs=inputs, watch=[tmp_path],
                  names="CASE.UNSMRY", expect="truncated")
