"""Issue 33 items 2 and 5, the pieces every viewer shares: per-property range sliders
(``ranges``: the same cells as the typed filter saying it), I/J/K range sliders (``slice``), the
section control on a grid (a plane across x, y or z), and the summary plot with one time cursor
(:class:`geoshade.viewer.timeline.Timeline`, ``render --summary``) on a real OPM Flow run."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

import geoshade
from geoshade.cli.main import main
from geoshade.compute.grid.filters import Ranges
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io.grids.summary import read_summary
from geoshade.viewer.controls import controls, to_options
from geoshade.viewer.timeline import Timeline
from geoshade.viewer.values import control_values

pytestmark = pytest.mark.gl
SIZE = (200, 150)


def _reek(shared_data):
    f = shared_data / "reek_cornerpoint" / "opm_flow_run" / "2_R001_REEK-0.EGRID"
    if not f.exists():
        pytest.skip(f"{f} is absent (see shared/data/README.md)")
    return f


def _specs(view) -> dict:
    return {c["name"]: c for g in controls(view) for c in g["controls"]}


# --- ranges -------------------------------------------------------------------------------------
def test_ranges_draw_the_cells_the_filter_names(ctx):
    g = synthetic_grid(12, 10, 4, seed=1)
    poro = np.asarray(g.properties["PORO"])
    lo, hi = (float(x) for x in np.quantile(poro, [0.3, 0.7]))
    with geoshade.view(g, size=SIZE, ranges={"poro": (lo, hi)}, ctx=ctx) as v:
        a, sa = v.draw()
    with geoshade.view(g, size=SIZE, filter=f"PORO >= {lo!r} and PORO <= {hi!r}", ctx=ctx) as v:
        b, sb = v.draw()
    assert np.array_equal(a, b)
    want = int((np.asarray(g.active, bool) & (poro >= lo) & (poro <= hi)).sum())
    assert sa["shown_cells"] == sb["shown_cells"] == want
    assert sa["ranges"] == {"poro": [lo, hi]}


def test_ranges_and_the_filter_both_hold(ctx):
    g = synthetic_grid(12, 10, 4, seed=1)
    with geoshade.view(g, size=(800, 600), ranges="PORO=0.15:", filter="PERMX > 50",
                       annotations=True, ctx=ctx) as v:
        _, st = v.draw()
    act = np.asarray(g.active, bool)
    want = act & (np.asarray(g.properties["PORO"]) >= 0.15) & \
        (np.asarray(g.properties["PERMX"]) > 50)
    assert st["shown_cells"] == int(want.sum())
    title = "\n".join(t["text"] for t in st["annotations"]["title"])
    assert "PERMX > 50 · PORO ≥ 0.15" in title, title


@pytest.mark.parametrize("value, msg", [
    ("XX=1:2", r"^range XX=1:2: unknown property 'XX'; available: "),
    ("PORO=0.3:0.1", r"^range PORO=0.3:0.1: LO 0.3 is above HI 0.1$"),
    ("PORO:0.1", r"^range 'PORO:0.1': expected NAME=LO:HI"),
    ("PORO=a:1", r"^range PORO=a:1: 'a' is not a finite number$"),
])
def test_bad_ranges_are_one_line(value, msg):
    g = synthetic_grid(4, 3, 2)
    with pytest.raises(InputError, match=msg):
        geoshade.view(g, ranges=value, ctx=object())


def test_range_sliders_and_ijk_sliders_change_what_render_draws(ctx):
    """The controls' values (what a slider sends) through ``to_options`` draw what opening
    with the option draws; the controls show the option's value back."""
    g = synthetic_grid(12, 10, 4, seed=1)
    with geoshade.view(g, size=SIZE, ctx=ctx) as v:
        spec = _specs(v)
        assert spec["slice"]["type"] == "ijk" and spec["slice"]["dims"] == [12, 10, 4]
        items = {n: (lo, hi) for n, lo, hi in spec["ranges"]["items"]}
        act = np.asarray(g.active, bool)
        poro = np.asarray(g.properties["PORO"])[act]
        assert items["PORO"] == (float(poro.min()), float(poro.max()))
        v.update(**to_options("slice", [[0, 12], [2, 7], [1, 4]], v))
        v.update(**to_options("ranges", {"PORO": [0.15, 0.25]}, v))
        got, _ = v.draw()
        shown = control_values(controls(v), v.settings())
        assert shown["slice"] == [[0, 12], [2, 7], [1, 4]]
        assert shown["ranges"] == {"PORO": [0.15, 0.25]}
    with geoshade.view(g, size=SIZE, slice="j=2:7,k=1:4", ranges="PORO=0.15:0.25",
                       ctx=ctx) as v:
        want, _ = v.draw()
    assert np.array_equal(got, want)


def test_section_control_on_a_grid(ctx):
    g = synthetic_grid(12, 10, 4, seed=1)
    with geoshade.view(g, size=SIZE, ctx=ctx) as v:
        assert _specs(v)["section"]["type"] == "section"
        v.update(**to_options("plane", ["x", 0.5, False], v))
        got, st = v.draw()
        plane = v.options.plane
    with geoshade.view(g, size=SIZE, plane=plane, ctx=ctx) as v:
        want, _ = v.draw()
    assert np.array_equal(got, want)
    # keeps the western half: cells whose centre x is below the middle of the box
    assert plane.normal == (-1.0, 0.0, 0.0)
    assert 0 < st["shown_cells"] < int(np.asarray(g.active).sum())


def test_ranges_state_reopens_the_picture(ctx):
    g = synthetic_grid(12, 10, 4, seed=1)
    with geoshade.view(g, size=SIZE, ranges={"PORO": (0.12, 0.2)}, ctx=ctx) as v:
        a, _ = v.draw()
        state = v.state()
    assert state["ranges"] == "PORO=0.12:0.2"
    with geoshade.view(g, ctx=ctx, **json.loads(json.dumps(state))) as v:
        b, _ = v.draw()
    assert np.array_equal(a, b)
    assert Ranges.parse(state["ranges"]) == Ranges.parse({"PORO": [0.12, 0.2]})


# --- the summary plot and its cursor -------------------------------------------------------------
def test_timeline_cursor_follows_the_step_and_a_click_moves_it(shared_data, ctx, tmp_path):
    f = _reek(shared_data)
    g = geoshade.load(f)
    with geoshade.view(g, size=SIZE, property="SWAT", summary=["FOPR", "FPR"], ctx=ctx) as v:
        assert _specs(v)["summary"]["type"] == "vectors"
        assert {"FOPR", "FPR", "WBHP:OP_1"} <= set(_specs(v)["summary"]["choices"])
        tl = Timeline(v)
        assert tl.available
        img = tl.image((640, 300))
        assert img.shape == (300, 640, 4)
        Image.fromarray(img).save(tmp_path / "timeline.png")
        last = tl.layout["cursor"]
        assert last["date"][:10] == g.step_dates[-1] and last["report"] == 37
        for step in (0, 16):
            v.update(step=step)
            tl.image((640, 300))
            assert tl.layout["cursor"]["date"][:10] == g.step_dates[step]
        # a click left of the middle of 2001-05-01 and 2001-06-01 goes to 2001-05-01
        x16 = tl.layout["cursor"]["x_px"]
        at = tl.click(x16 + 3, 150)
        assert at.index == 16 and at.date[:10] == "2001-05-01"
        assert "nearest report step with restart data" in at.text
        assert tl.click(2, 2) is None          # outside the panels: nothing
    # the curves are the file's: FOPR's maximum as resfo reads it is on the axis
    t = read_summary(f, ["FOPR"])
    assert tl.layout["axes"][0]["ylim"][1] >= float(np.max(t.values[:, 0]))


def test_timeline_refuses_in_one_line_where_there_is_no_summary(ctx):
    g = synthetic_grid(6, 5, 3)
    with geoshade.view(g, size=SIZE, ctx=ctx) as v:
        tl = Timeline(v)
        assert not tl.available and "was not read from a case's files" in tl.why_not()
        assert "summary" not in _specs(v)
        assert tl.image() is None
    with pytest.raises(InputError, match=r"^summary: synthetic .* has no summary$"):
        geoshade.view(g, summary="FOPR", ctx=object())


def test_render_draws_the_strip_under_the_picture(shared_data, tmp_path, capsys):
    f = _reek(shared_data)
    out, stats = tmp_path / "a.png", tmp_path / "a.json"
    rc = main(["grid", "render", str(f), "--property", "SWAT", "--step", "2001-05-01",
               "--summary", "FOPR", "--summary", "WOPR:*", "--size", "800x450", "-o", str(out),
               "--stats", str(stats)])
    assert rc == 0
    img = np.asarray(Image.open(out))
    st = json.loads(stats.read_text())
    assert img.shape[:2] == (450 + 200, 800)
    assert st["summary"] == {"vectors": ["FOPR", "WOPR:*"], "strip_height": 200}
    rc = main(["grid", "render", str(f), "--summary", "FOPX", "-o", str(tmp_path / "b.png")])
    err = capsys.readouterr().err.strip()
    assert rc != 0 and err.endswith("no summary vector FOPX; nearest: FOPT, FOPR, FOPP, FOIP, "
                                    "FOPTS")
    assert not (tmp_path / "b.png").exists()
