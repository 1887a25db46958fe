"""Issue 33 in the notebook: ``geoshade.show(case).workbench()`` (jupyter_rfb and ipywidgets,
driven through the widgets' values and ``handle_event`` as a page would drive them, no browser)
on the real OPM Flow run of Reek: the summary plot's one time cursor follows the step and a
click on the plot moves the step; a pick's table is resfo's reading of the cell and follows the
step, several picks are kept, a cell's history is plotted; ``w.state()`` / ``w.view_text()``
open the same picture pixel for pixel; the I/J/K and value range controls draw what a View
updated with the same options draws."""

from __future__ import annotations

import html
import json
import re

import numpy as np
import pytest

import geoshade
from geoshade.viewer.values import slider_value
from tests.viewer.reek_run import REEK, day, needs_reek, resfo_cell, x_of, y_mid

pytest.importorskip("jupyter_rfb", reason="geoshade.show needs jupyter_rfb (geoshade[viewer])")
pytest.importorskip("ipywidgets", reason="the workbench needs ipywidgets (with jupyter_rfb)")

SIZE = (200, 150)


def _ev(kind, **kw):  # what jupyter_rfb hands handle_event (old and new keys)
    return {"event_type": kind, "type": kind, "modifiers": (), "buttons": (), **kw}


@pytest.fixture
def bench(ctx):
    w = geoshade.show(str(REEK), size=SIZE, property="SWAT", step=5)
    box = w.workbench()
    assert box.children[0] is w and box.children[1] is w.panel.box
    yield w
    w.close()


def _click(frame, x, y):
    frame.handle_event(_ev("pointer_down", x=x, y=y, button=1, buttons=(1,)))


@needs_reek
def test_summary_cursor_follows_the_step_and_a_click_moves_it(bench):
    w, panel = bench, bench.panel
    dates = w.view.model.step_dates
    assert panel.timeline is not None and panel.summary_box.layout.display == "none"
    panel.controls["summary"].box.value = "FOPR, FPR"   # the vectors control
    assert w.view.options.summary == ("FOPR", "FPR")
    assert panel.summary_box.layout.display is None
    cur = panel.timeline.layout["cursor"]
    assert day(cur["date"]) == dates[5] and cur["report"] == 5
    frame = panel.plot.get_frame()
    assert frame.shape == (300, 640, 3) and (frame != 255).any()
    w.set(step=20)                                   # moving the step moves the cursor
    assert day(panel.timeline.layout["cursor"]["date"]) == dates[20]
    assert panel.goto.value == 20 and panel.controls["step"].widget.value == 20
    panel.controls["step"].widget.value = 25         # the step slider too
    assert w.view.options.step == 25
    assert panel.timeline.layout["cursor"]["report"] == 25
    # a click on the plot near the date of step 12: step 12 shown and said
    lay = panel.timeline.layout
    _click(panel.plot, x_of(lay, dates[12] + "T00:00:00") + 2, y_mid(lay))
    assert w.view.options.step == 12 and panel.controls["step"].widget.value == 12
    assert "step 12" in panel.status.value and "nearest report step" in panel.status.value
    assert day(panel.timeline.layout["cursor"]["date"]) == dates[12]
    w.get_frame()
    assert "report 12" in w.readout()
    # the frame shown at half its size on the page: a click's pixel is scaled back
    panel.plot.handle_event(_ev("resize", width=320, height=150, pixel_ratio=1.0))
    lay = panel.timeline.layout
    _click(panel.plot, (x_of(lay, dates[30] + "T00:00:00") + 2) / 2, y_mid(lay) / 2)
    assert w.view.options.step == 30
    # the show-step list moves it as well
    panel.goto.value = 3
    assert w.view.options.step == 3 and panel.timeline.layout["cursor"]["report"] == 3
    # a wrong vector: one line naming it, the plot as it was
    panel.controls["summary"].box.value = "FOPRX"
    assert "FOPRX" in panel.status.value and "\n" not in panel.status.value
    assert w.view.options.summary == ("FOPR", "FPR")


def _inside(img) -> list[tuple[int, int]]:
    """Pixels of the picture that show the model, from its middle outwards."""
    ys, xs = np.nonzero(~(img[..., :3] >= 250).all(axis=-1))
    order = np.argsort((xs - img.shape[1] / 2) ** 2 + (ys - img.shape[0] / 2) ** 2)
    return [(int(xs[k]), int(ys[k])) for k in order[:: max(1, len(order) // 45)]]


def _table(panel) -> dict[str, tuple[str, str]]:
    """The pick table as the notebook shows it: {property: (value, unit)}."""
    rows = re.findall(r"<tr><td>(.*?)</td><td[^>]*>(.*?)</td><td>(.*?)</td></tr>",
                      panel.table.value)
    return {html.unescape(n): (html.unescape(v), html.unescape(u)) for n, v, u in rows}


@needs_reek
def test_picks_table_is_resfos_and_follows_the_step(bench):
    w, panel = bench, bench.panel
    g = w.view.model
    picked = []
    for x, y in _inside(w.get_frame()):   # left clicks on the picture, as a page sends them
        w.handle_event(_ev("pointer_down", x=x, y=y, button=1, buttons=(1,)))
        w.handle_event(_ev("pointer_up", x=x, y=y, button=1))
        if w.picked is not None and w.picked.index[:3] not in picked:
            picked.append(w.picked.index[:3])
        if len(picked) == 2:
            break
    p = panel.picks
    assert p.cells == picked and len(panel.pick_list.options) == 2
    assert panel.pick_list.value == 1   # the last pick is the chosen one
    for step in (5, 30):
        want = resfo_cell(picked[1], step, g.dims, g.active)
        got = _table(panel)
        assert {"PORO", "PERMX", "PORV", "PRESSURE", "SWAT", "SGAS"} <= set(got)
        for name, v in want.items():
            if name in got:
                assert float(got[name][0]) == pytest.approx(v, rel=1e-5, abs=1e-6), name
        assert got["PRESSURE"][1] == "bar" and got["SWAT"][1] == "fraction"
        assert f"at {g.step_dates[step]}" in panel.table.value
        assert panel.history_plot.value[:8] == b"\x89PNG\r\n\x1a\n"   # the history, shown
        w.set(step=30)
    assert p.history_name == "SWAT" and panel.history.value == "SWAT"   # the shown property
    panel.history.value = "PRESSURE"
    hist = p.history()
    assert hist["name"] == "PRESSURE" and hist["cell"] == tuple(picked[1])
    assert len(hist["values"]) == 37
    panel.pick_list.value = 0          # choose the first pick: its table
    assert f"I={picked[0][0] + 1} J={picked[0][1] + 1}" in panel.table.value
    panel.remove.click()
    assert p.cells == [picked[1]] and len(panel.pick_list.options) == 1
    panel.clear.click()
    assert p.cells == [] and "no cell picked" in panel.table.value


@needs_reek
def test_state_and_view_text_draw_the_same_picture(bench):
    w, panel = bench, bench.panel
    w.handle_event(_ev("pointer_down", x=60, y=60, button=1, buttons=(1,)))   # turn it
    w.handle_event(_ev("pointer_move", x=110, y=75, button=1, buttons=(1,)))
    w.handle_event(_ev("pointer_up", x=110, y=75, button=1))
    lo, hi = panel.controls["color_range"].boxes
    lo.value, hi.value = "0.2", "0.8"                # the colour range typed
    panel.controls["colormap"].widget.value = "turbo"
    shown = w.get_frame()
    state = w.state()
    assert state["step"] == 5 and state["colormap"] == "turbo" and "camera" in state
    assert state["color_range"] == [0.2, 0.8]
    doc = json.loads(w.view_text())
    assert doc["file"] == str(REEK.resolve()) and doc["part"] == "grid"
    assert doc["state"] == json.loads(json.dumps(state))
    again = geoshade.show(doc["file"], **doc["state"])   # its size too
    try:
        assert np.array_equal(again.get_frame(), shown)   # pixel for pixel
    finally:
        again.close()
    with geoshade.view(geoshade.load(REEK), **state) as v:
        want, _ = v.draw()
    assert np.array_equal(want[..., :3], shown[..., :3])


@needs_reek
def test_ijk_and_range_controls_draw_what_update_draws(bench):
    w, panel = bench, bench.panel
    ctl, g = panel.controls, bench.view.model
    opened = w.state()
    ctl["slice"].sliders[0].value = (5, 30)          # I 5 to 30, 1-based: i = 4:30
    ctl["slice"].sliders[2].value = (3, 10)
    assert w.view.options.slice == (slice(4, 30), slice(0, 64), slice(2, 10)) or \
        w.view.options.slice == (slice(4, 30), slice(None, None), slice(2, 10))
    ctl["ranges"].set_range("PORO", 0.2, None)        # PORO >= 0.2, as typed
    assert "PORO" in w.view.options.ranges.text()
    shown = w.get_frame()
    act = np.asarray(g.active, bool)
    poro = np.asarray(g.properties["PORO"], float)
    cut = np.zeros_like(act)
    cut[4:30, :, 2:10] = True
    assert w.stats["shown_cells"] == int(np.count_nonzero(act & cut & (poro >= 0.2)))
    with geoshade.view(geoshade.load(REEK), **opened) as v:   # as opened, then updated
        v.update(slice="i=4:30,k=2:10", ranges="PORO=0.2:")
        want, stats = v.draw()
    assert stats["shown_cells"] == w.stats["shown_cells"]
    assert np.array_equal(want[..., :3], shown[..., :3])
    # the range slider's upper end at 90 %: PORO <= that value as well
    rng = ctl["ranges"].slider
    rng.value = (rng.value[0], 900)
    lo_, hi_ = next(item[1:] for item in ctl["ranges"].spec["items"] if item[0] == "PORO")
    top = slider_value(lo_, hi_, 900, 1000)
    assert w.view.options.ranges.text() == f"PORO=0.2:{top:g}"
    w.get_frame()
    n = int(np.count_nonzero(act & cut & (poro >= 0.2) & (poro <= top)))
    assert w.stats["shown_cells"] == n
    # the section: the clip plane across x of the model's box
    ctl["section"].widget.children[1].value = True
    assert w.view.options.plane is not None and panel.section[0] == "x"
    w.get_frame()
    assert 0 < w.stats["shown_cells"] < n


@needs_reek
def test_an_isosurface_of_the_case_has_the_summary_plot_too(ctx):
    """An isosurface's field (a FieldSeries: ``times``, no ``step_dates``) has the plot and
    the show-step list named by report and date; no picks table (not a grid)."""
    w = geoshade.show(str(REEK), kind="iso", size=SIZE, keyword="SWAT", level=0.5, step=5,
                      summary=["FOPR"])
    try:
        w.workbench()
        panel = w.panel
        dates = geoshade.load(REEK).step_dates
        assert panel.picks is None and panel.timeline.layout["cursor"]["report"] == 5
        assert panel.goto.options[3] == (f"step 3 (report 3, {dates[3]})", 3)
        panel.goto.value = 3
        assert w.view.options.step == 3 and panel.timeline.layout["cursor"]["report"] == 3
        assert panel.status.value == f"showing step 3 (report 3, {dates[3]})"
    finally:
        w.close()


@pytest.mark.parametrize("kind", ["core", "grid", "iso", "stacks"])
def test_every_part_has_the_panel_of_its_controls(ctx, kind):
    """The side panel of every part's demo: one notebook widget per control the View has
    (each control type made once), showing the View's values changes none of them, and a
    change typed in a text box is the View's option."""
    from geoshade.viewer.controls import controls
    from geoshade.viewer.views import demo_views

    _cls, model, settings = demo_views()[kind]
    w = geoshade.show(model, kind=kind, size=(96, 72), **settings)
    try:
        w.workbench()
        panel = w.panel
        names = {c["name"] for g in controls(w.view) for c in g["controls"]}
        assert set(panel.controls) == names and all(c.widget is not None
                                                    for c in panel.controls.values())
        before = w.view.settings()
        panel.sync()
        after = w.view.settings()
        assert after.keys() == before.keys() and all(
            np.array_equal(after[k], before[k]) if isinstance(before[k], np.ndarray)
            else after[k] == before[k] for k in before)
        assert (panel.picks is not None) == (kind == "grid") and panel.timeline is None
        if kind == "stacks":   # coloured by its materials: no colour map
            assert "colormap" not in panel.controls and "materials" in panel.controls
            return
        panel.controls["colormap"].widget.value = "magma"
        assert w.state().get("colormap") == "magma" and panel.status.value == ""
        panel.controls["colormap"].widget.value = "no-such-map"   # one line, kept as it was
        assert panel.status.value.startswith("error: ") and "\n" not in panel.status.value
        assert w.state().get("colormap") == "magma"
    finally:
        w.close()
