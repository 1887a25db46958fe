"""Issue 33 item 3: ``--diff STEP`` draws PROPERTY(step) − PROPERTY(STEP) on the active cells on
a diverging colour map centred on 0; ``value_range`` is numpy's over the active cells, the title
names both steps, a static property refuses in one line; the same in render, view and Python."""

from __future__ import annotations

import json

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError

pytestmark = pytest.mark.gl


def _numpy_diff(g, step, diff):
    d = np.asarray(g.steps[step]["SWAT"], np.float64) - np.asarray(g.steps[diff]["SWAT"],
                                                                     np.float64)
    return d[np.asarray(g.active, bool)]


def test_value_range_colour_range_and_title(ctx):
    g = synthetic_grid(24, 18, 8, seed=3)
    with geoshade.view(g, property="SWAT", step=-1, diff="2000-01-01", size=(640, 480),
                       annotations=True, ctx=ctx) as v:
        _, st = v.draw()
    d = _numpy_diff(g, 3, 0)
    assert st["value_range"] == pytest.approx([float(d.min()), float(d.max())], abs=0)
    m = max(abs(d.min()), abs(d.max()))
    assert st["color_range"] == pytest.approx([-m, m])          # symmetric, centred on 0
    assert st["colormap"] == "RdBu_r" and st["log"] is False and st["categories"] is None
    assert st["diff"] == {"step": 3, "from": 0, "dates": ["2000-04-01", "2000-01-01"]}
    title = "\n".join(t["text"] for t in st["annotations"]["title"])
    assert "SWAT change, 2000-04-01 − 2000-01-01" in title, title
    assert st["annotations"]["colorbar"]["label"].startswith("ΔSWAT")


def test_the_difference_drawn_is_the_change(ctx):
    """The picture of the difference equals the picture of the change given as a property of
    its own (the same values, the same range and colour map)."""
    g = synthetic_grid(16, 12, 6, seed=5)
    change = (np.asarray(g.steps[2]["SWAT"], np.float64)
              - np.asarray(g.steps[1]["SWAT"], np.float64))
    g2 = synthetic_grid(16, 12, 6, seed=5)
    g2.properties["DSWAT"] = change
    m = float(np.abs(change[np.asarray(g.active, bool)]).max())
    common = dict(size=(200, 150), annotations=False, ctx=ctx, exaggeration=1)
    with geoshade.view(g, property="SWAT", step=2, diff=1, **common) as a:
        img_a, st = a.draw()
    with geoshade.view(g2, property="DSWAT", colormap="RdBu_r", color_range=(-m, m),
                       **common) as b:
        img_b, _ = b.draw()
    assert st["color_range"] == pytest.approx([-m, m])
    assert np.array_equal(img_a, img_b)


def test_a_static_property_or_no_steps_refuse_in_one_line():
    g = synthetic_grid(6, 5, 3)
    with pytest.raises(InputError, match=r"^diff: PORO does not change with the report step"):
        geoshade.view(g, property="PORO", diff=0)
    g.steps = []
    with pytest.raises(InputError, match=r"^diff: .* has no report steps"):
        geoshade.view(g, property="PORO", diff=0)


def test_render_and_view_take_diff(tmp_path, capsys):
    """``grid render --diff`` on an ECLIPSE case (EGRID + INIT + UNRST) writes the stats; the
    viewer's screenshot with the same flags is the same picture."""
    from PIL import Image

    from geoshade.cli.main import main
    from tests.grid_cases import grid_cases

    pytest.importorskip("PySide6")
    paths = grid_cases().write_case(tmp_path / "case", 8, 6, 3, steps=3)
    flags = ["--property", "SWAT", "--diff", "0", "--size", "320x240"]
    out, stats = tmp_path / "d.png", tmp_path / "d.json"
    assert main(["grid", "render", str(paths["EGRID"]), *flags, "--frames", "1", "-o", str(out),
                 "--stats", str(stats)]) == 0, capsys.readouterr().err
    st = json.loads(stats.read_text())
    g = geoshade.load(paths["EGRID"])
    d = (np.asarray(g.steps[-1]["SWAT"], np.float64)
         - np.asarray(g.steps[0]["SWAT"], np.float64))[np.asarray(g.active, bool)]
    assert st["value_range"] == pytest.approx([float(d.min()), float(d.max())])
    shot = tmp_path / "v.png"
    assert main(["view", str(paths["EGRID"]), *flags, "--screenshot", str(shot)]) == 0
    assert np.array_equal(np.asarray(Image.open(shot).convert("RGBA"))[..., :3],
                          np.asarray(Image.open(out).convert("RGBA"))[..., :3])
    rc = main(["grid", "render", str(paths["EGRID"]), "--property", "PORO", "--diff", "0",
               "-o", str(tmp_path / "x.png")])
    err = capsys.readouterr().err
    assert rc == 2 and "does not change with the report step" in err and err.count("\n") == 1


REEK = "/work/shared/data/reek_cornerpoint/opm_flow_run/2_R001_REEK-0"


@pytest.mark.skipif(not __import__("pathlib").Path(REEK + ".UNRST").exists(),
                    reason="the Reek OPM Flow run (shared data) is absent")
def test_real_case_value_range_is_numpys_over_resfos_arrays(ctx):
    """Reek's SWAT change between 2000-01-01 and the last report, against resfo's SWAT
    records (active cells in file order)."""
    import resfo

    swat = [np.asarray(v, np.float64) for k, v in resfo.read(REEK + ".UNRST")
            if k.strip() == "SWAT"]
    d = swat[-1] - swat[0]
    g = geoshade.load(REEK + ".EGRID")
    with geoshade.view(g, property="SWAT", diff="2000-01-01", size=(320, 240), ctx=ctx) as v:
        _, st = v.draw()
    assert st["diff"]["from"] == 0 and st["diff"]["step"] == len(swat) - 1
    assert st["value_range"] == pytest.approx([float(d.min()), float(d.max())], rel=1e-6)
