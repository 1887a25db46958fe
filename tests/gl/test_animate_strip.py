"""Issue 33 item 6: time-lapse pictures with the summary cursor strip: ``grid animate`` (new)
and ``iso animate`` draw every step asked for, each frame the picture with the case's summary
curves under it, the cursor at the frame's date (the strip equals SummaryPlot's picture at that
date, pixel for pixel), on one colour scale over the steps."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import geoshade
from geoshade.cli.main import main
from geoshade.render.animate import STRIP_HEIGHT, summary_strip, with_strip
from geoshade.styles.summary_plot import SummaryPlot

pytestmark = pytest.mark.gl
REEK = Path("/work/shared/data/reek_cornerpoint/opm_flow_run/2_R001_REEK-0.EGRID")
need_reek = pytest.mark.skipif(not REEK.exists(), reason="the Reek OPM Flow run is absent")


@need_reek
def test_the_strip_is_the_summary_plot_at_the_frames_date():
    g = geoshade.load(REEK)
    dates, reports = list(g.step_dates), list(g.meta["unrst_seqnum"])
    strip = summary_strip(REEK, ["FOPR"], 480, dates, reports)
    plot = SummaryPlot(geoshade.load(REEK, as_="summary"), ["FOPR"], size=(480, STRIP_HEIGHT),
                       report_dates=dates, reports=reports)
    for k in (0, 12, 36):
        assert np.array_equal(strip(k), plot.draw(dates[k]))
    frame = np.zeros((100, 480, 4), np.uint8)
    out = with_strip(frame, strip, 12)
    assert out.shape == (100 + STRIP_HEIGHT, 480, 4) and np.array_equal(out[:100], frame)


@need_reek
def test_grid_and_iso_animate_with_the_strip(tmp_path, capsys):
    from PIL import Image

    stats = tmp_path / "g.json"
    rc = main(["grid", "animate", str(REEK), "--property", "SWAT", "--steps", "0", "R12",
               "2003-01-01", "--summary", "FOPR", "--size", "320x240", "-o",
               str(tmp_path / "g.gif"), "--stats", str(stats)])
    assert rc == 0, capsys.readouterr().err
    st = json.loads(stats.read_text())
    assert st["frames"] == 3 and st["steps"] == [0, 12, 36] and st["strip_height"] == STRIP_HEIGHT
    assert (st["width"], st["height"]) == (320, 240 + STRIP_HEIGHT)
    g = geoshade.load(REEK)
    swat = np.concatenate([np.asarray(g.steps[k]["SWAT"])[np.asarray(g.active, bool)]
                           for k in (0, 12, 36)])
    assert st["color_range"] == pytest.approx([float(swat.min()), float(swat.max())],
                                              rel=1e-6)   # one scale for every frame
    gif = Image.open(tmp_path / "g.gif")
    assert gif.n_frames == 3 and gif.size == (320, 240 + STRIP_HEIGHT)
    rc = main(["iso", "animate", str(REEK), "--keyword", "SWAT", "--level", "0.5", "--steps",
               "10", "36", "--summary", "FWPR", "--size", "320x240", "-o",
               str(tmp_path / "i.gif")])
    assert rc == 0, capsys.readouterr().err
    assert Image.open(tmp_path / "i.gif").size == (320, 240 + STRIP_HEIGHT)


def test_a_static_property_or_an_unknown_vector_is_one_line(tmp_path, capsys):
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.errors import InputError

    g = synthetic_grid(6, 5, 3)
    with pytest.raises(InputError, match="does not change with the report step"):
        geoshade.grid.animate(g, tmp_path / "a.gif", property="PORO")
    if REEK.exists():
        rc = main(["grid", "animate", str(REEK), "--property", "SWAT", "--summary", "NOSUCH",
                   "-o", str(tmp_path / "b.gif")])
        err = capsys.readouterr().err
        assert rc == 2 and "NOSUCH" in err and err.count("\n") == 1
        assert not (tmp_path / "b.gif").exists()
