"""The summary plot and its time cursor (issue 33 items 2 and 6, the toolkit-free half): units on
the axes, the cursor drawn where its date is, moving it redraws only the cursor, a click's date
maps to the nearest report step with restart data."""

from __future__ import annotations

import datetime

import matplotlib.colors as mcolors
import matplotlib.dates as mdates
import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.models.summary_vectors import SummaryTable, SummaryVector
from geoshade.styles.summary_plot import CURSOR_COLOR, SummaryPlot, step_at, summary_plot

START = datetime.datetime(2010, 1, 1)
UNITS = {"FOPR": "STB/DAY", "FWPR": "STB/DAY", "FPR": "PSIA", "FWCT": "", "FGOR": "MSCF/STB"}


def _table(n: int = 48) -> SummaryTable:
    days = np.arange(1, n + 1) * 30.0
    t = np.linspace(0, 1, n)
    cols = [1000 * (1 - t), 300 * t, 4000 - 1000 * t, t * 0.9, 1 + t]
    vecs = [SummaryVector(k, k, "field", u) for k, u in UNITS.items()]
    return SummaryTable(days, np.stack(cols, 1).astype(np.float32), vecs, START,
                        report=np.arange(1, n + 1))


def _cursor_columns(img: np.ndarray) -> np.ndarray:
    """The columns holding pixels of the cursor's colour."""
    rgb = np.array(mcolors.to_rgb(CURSOR_COLOR)) * 255
    hit = np.all(np.abs(img[..., :3].astype(int) - rgb) < 12, axis=-1)
    return np.flatnonzero(hit.sum(0) > img.shape[0] // 4)


def test_one_axis_per_unit_with_units_on_the_axes():
    p = SummaryPlot(_table(), ["FOPR", "FWPR", "FPR"], size=(800, 450))
    axes = p.layout["axes"]
    assert [(a["unit"], a["side"], a["vectors"]) for a in axes] == [
        ("STB/DAY", "left", ["FOPR", "FWPR"]), ("PSIA", "right", ["FPR"])]
    assert axes[0]["label"] == "STB/DAY" and axes[1]["label"] == "PSIA (dashed)"
    assert p.layout["legend"][0]["texts"] == ["FOPR [STB/DAY]", "FWPR [STB/DAY]", "FPR [PSIA]"]
    assert p.layout["xlim"][0] == "2010-01-01T00:00:00"
    lo, hi = axes[1]["ylim"]
    assert lo <= 3000 and hi >= 4000
    # three units or more: one panel each, stacked, the dimensionless one named so
    q = SummaryPlot(_table(), ["FOPR", "FPR", "FWCT", "FGOR"], size=(800, 600))
    assert [a["unit"] for a in q.layout["axes"]] == ["STB/DAY", "PSIA", "dimensionless",
                                                      "MSCF/STB"]
    tops = [a["bbox"][1] for a in q.layout["axes"]]
    assert tops == sorted(tops) and all(a["side"] == "left" for a in q.layout["axes"])


def test_the_cursor_is_drawn_at_its_date_and_moving_it_redraws_only_it():
    table = _table()
    p = SummaryPlot(table, ["FOPR", "FPR"], size=(800, 450))
    bare = p.draw()
    assert _cursor_columns(bare).size == 0 and "cursor" not in p.layout
    a = p.draw("2011-06-15")
    cols = _cursor_columns(a)
    assert cols.size and abs(cols.mean() - p.layout["cursor"]["x_px"]) <= 1.5
    # the markers go to the nearest report step (every 30 days here)
    dates = table.dates
    nearest = int(np.argmin(np.abs(dates - np.datetime64("2011-06-15"))))
    assert p.layout["cursor"]["report"] == nearest + 1
    assert p.layout["cursor"]["report_date"] == str(dates[nearest])
    b = p.draw("2012-11-01")
    assert _cursor_columns(b).mean() > cols.mean()
    assert np.array_equal(p.draw("2011-06-15"), a)  # the kept picture is not drawn over
    assert np.array_equal(p.draw(), bare)
    changed = np.any(a != bare, axis=-1)
    assert changed.mean() < 0.05  # the cursor, its label and the markers only


def test_a_click_maps_to_a_date_and_to_the_nearest_step_with_restart_data():
    table = _table()
    p = SummaryPlot(table, ["FOPR"], size=(800, 450))
    p.draw("2011-03-02")
    x = p.layout["cursor"]["x_px"]
    top, bottom = p.layout["axes"][0]["bbox"][1], p.layout["axes"][0]["bbox"][3]
    when = p.date_at(x, (top + bottom) / 2)
    assert abs((when - datetime.datetime(2011, 3, 2)).total_seconds()) < 86400 * 2
    assert p.date_at(2, 2) is None  # outside the panels
    restart = ["2010-01-01", "", "2011-01-01", "2011-07-01"]
    s = step_at(None, when, restart, [0, 5, 12, 18])
    assert (s.index, s.report, s.exact) == (2, 12, False)
    assert s.text.endswith("step 2 (report 12, 2011-01-01), the nearest report step with "
                           "restart data")
    assert step_at(None, "2011-07-01", restart).exact
    # a matplotlib date number (a click event's xdata) is a date too
    assert step_at(None, mdates.date2num(datetime.datetime(2011, 6, 1)), restart).index == 3


def test_step_at_reads_a_grid_or_a_table():
    class Grid:
        def __init__(self):
            self.step_dates = ["2010-01-01", "2010-02-01", "2010-03-01"]
            self.meta = {"unrst_seqnum": [0, 1, 3]}

    s = step_at(Grid(), "2010-02-25")
    assert (s.index, s.report, s.date) == (2, 3, "2010-03-01T00:00:00")
    t = step_at(_table(), "2010-03-03")
    assert (t.report, t.date) == (2, "2010-03-02T00:00:00")
    with pytest.raises(InputError, match="no report step with a date"):
        step_at(None, "2010-01-01", ["", ""])
    with pytest.raises(InputError, match="is not a date"):
        step_at(Grid(), "tomorrow")


def test_a_strip_and_its_limits():
    img, layout = summary_plot(_table(), ["FOPR", "FPR"], at="2011-01-01", size=(960, 180))
    assert img.shape == (180, 960, 4) and layout["title"] == ""
    with pytest.raises(InputError, match=r"4 units .* need 70 pixels of height each"):
        SummaryPlot(_table(), ["FOPR", "FPR", "FWCT", "FGOR"], size=(960, 180))
    with pytest.raises(InputError, match="too small"):
        SummaryPlot(_table(), ["FOPR"], size=(100, 50))
    with pytest.raises(InputError, match="no summary vector FOPT"):
        SummaryPlot(_table(), ["FOPT"])
