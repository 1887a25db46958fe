"""Issue 33 in the desktop viewer (Qt offscreen), on the real OPM Flow run of Reek: the summary
plot's one time cursor follows the step and a click on the plot moves the step; a pick's table
is resfo's reading of the cell, several picks are kept, the history plot follows the step;
*Copy view* / *Open view* show the same picture pixel for pixel; the I/J/K, range and section
controls cut what numpy says."""

from __future__ import annotations

import json

import numpy as np
import pytest

import geoshade
from tests.viewer.reek_run import REEK, day, needs_reek, resfo_cell, x_of, y_mid

pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")


def _open(win, source, kind=None, **settings):
    win.open(source, kind, None, settings)
    win.wait_idle(300)
    assert not win.errors, win.errors
    return win.active


def _type(box, text):
    box.setText(text)
    box.returnPressed.emit()


def _inside(img) -> list[tuple[int, int]]:
    """Pixels of the picture that show the model, from its middle outwards."""
    ys, xs = np.nonzero(~(img[..., :3] >= 250).all(axis=-1))
    order = np.argsort((xs - img.shape[1] / 2) ** 2 + (ys - img.shape[0] / 2) ** 2)
    return [(int(xs[k]), int(ys[k])) for k in order[:: max(1, len(order) // 45)]]


@needs_reek
def test_summary_cursor_follows_the_step_and_a_click_moves_it(window):
    from PySide6.QtCore import QPoint, Qt
    from PySide6.QtTest import QTest

    entry = _open(window, str(REEK), property="SWAT", step=5)
    dates = entry.session.view.model.step_dates
    tl = entry.timeline
    assert tl is not None and window.summary_dock.isHidden()   # no vector chosen yet
    ctl = entry.panel.controls
    before, camera = window.frame.size(), entry.session.camera
    _type(ctl["summary"], "FOPR, FPR")          # the vectors control (completes over 459)
    window.wait_idle()
    assert entry.session.view.options.summary == ("FOPR", "FPR")
    assert not window.summary_dock.isHidden() and tl.showing
    # the dock that appeared grew the window: the 3D view kept its size and its camera
    assert window.frame.size() == before and entry.session.camera is camera
    cur = tl.timeline.layout["cursor"]
    assert day(cur["date"]) == dates[5] and cur["report"] == 5
    ctl["step"].slider.setValue(20)              # moving the step moves the cursor
    window.wait_idle()
    cur = tl.timeline.layout["cursor"]
    assert day(cur["date"]) == dates[20] and cur["report"] == 20
    # a click on the plot near the date of step 12 shows step 12 and says so
    lay = tl.timeline.layout
    x = x_of(lay, dates[12] + "T00:00:00") + 2
    QTest.mouseClick(tl.plot, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier,
                     QPoint(round(x), round(y_mid(lay))))
    window.wait_idle()
    assert entry.session.view.options.step == 12 and ctl["step"].slider.value() == 12
    assert "step 12" in window.message.text() and "nearest report step" in window.message.text()
    assert day(tl.timeline.layout["cursor"]["date"]) == dates[12]
    assert "report 12" in window.readout.text()
    # a wrong vector: one line naming it, the plot as it was
    _type(ctl["summary"], "FOPRX")
    window.wait_idle()
    assert window.errors and "FOPRX" in window.errors[-1] and "\n" not in window.errors[-1]
    assert entry.session.view.options.summary == ("FOPR", "FPR")
    img = tl.plot.pixmap().toImage()
    assert img.width() >= 480 and img.height() == 260


@needs_reek
def test_picks_table_is_resfos_and_follows_the_step(window):
    entry = _open(window, str(REEK), property="SWAT", step=5)
    s, g = entry.session, entry.session.view.model
    assert window.picks_dock.isHidden()
    picked = []
    for n in range(40):   # the picture's pixels of the model (the first pick opens the dock)
        x, y = _inside(s.image)[n]
        s.press(x, y)
        window.pointer_released(x, y)
        window.wait_idle()
        if s.picked is not None and s.picked.index[:3] not in picked:
            picked.append(s.picked.index[:3])
        if len(picked) == 2:
            break
    panel = entry.picks
    assert not window.picks_dock.isHidden()
    assert panel.picks.cells == picked and panel.list.count() == 2
    assert panel.list.currentRow() == 1   # the last pick is the chosen one

    def table():
        return {panel.table.item(r, 0).text(): (panel.table.item(r, 1).text(),
                                                panel.table.item(r, 2).text())
                for r in range(panel.table.rowCount())}

    for step in (5, 30):
        want = resfo_cell(picked[1], step, g.dims, g.active)
        got = table()
        assert {"PORO", "PERMX", "PORV", "PRESSURE", "SWAT", "SGAS"} <= set(got)
        for name, v in want.items():
            if name in got:
                assert float(got[name][0]) == pytest.approx(v, rel=1e-5, abs=1e-6), name
        assert got["PRESSURE"][1] == "bar" and got["SWAT"][1] == "fraction"
        assert f"at {g.step_dates[step]}" in panel.caption.text()
        # the history plot: its cursor at the shown step
        assert panel.plot.pixmap() is not None and not panel.plot.pixmap().isNull()
        entry.panel.controls["step"].slider.setValue(30)
        window.wait_idle()
    assert panel.picks.history_name == "SWAT"
    panel.history.setCurrentText("PRESSURE")
    hist = panel.picks.history()
    i, j, k = picked[1]
    assert hist["name"] == "PRESSURE" and hist["cell"] == (i, j, k) and len(hist["values"]) == 37
    panel.list.setCurrentRow(0)     # choose the first pick: its table
    assert f"I={picked[0][0] + 1} J={picked[0][1] + 1}" in panel.caption.text()
    panel.remove.click()
    assert panel.picks.cells == [picked[1]] and panel.list.count() == 1
    panel.clear.click()
    assert panel.picks.cells == [] and panel.table.rowCount() == 0


@needs_reek
def test_copy_view_and_open_view_draw_the_same_picture(window, tmp_path):
    from geoshade.viewer.qt import from_qimage

    entry = _open(window, str(REEK), property="SWAT", step=7)
    s = entry.session
    s.orbit(40, 12)
    s.zoom(1)
    window.request_draw()
    entry.panel.controls["color_range"].set_values([0.2, 0.8])
    entry.panel.controls["colormap"].setEditText("turbo")
    entry.panel.controls["colormap"].lineEdit().returnPressed.emit()
    window.wait_idle()
    text = window.copy_view()
    from PySide6.QtWidgets import QApplication

    assert QApplication.clipboard().text() == text
    doc = json.loads(text)
    assert doc["file"] == str(REEK.resolve()) and doc["part"] == "grid"
    state = doc["state"]
    assert state["step"] == 7 and state["colormap"] == "turbo" and "camera" in state
    assert window.open_view()          # from the clipboard: a second data set
    window.wait_idle(300)
    assert not window.errors, window.errors
    assert len(window.entries) == 2 and window.active.title.endswith("(shared view)")
    shown = from_qimage(window.frame.grab().toImage())
    with geoshade.view(geoshade.load(REEK), **state) as v:
        want, _ = v.draw()
    assert shown.shape == want.shape
    assert np.array_equal(shown[..., :3], want[..., :3])   # pixel for pixel
    assert np.array_equal(window.session.image, want)
    # a file holding the view opens it too; a wrong text is one line
    (tmp_path / "view.json").write_text(text)
    assert window.open_view(path=tmp_path / "view.json")
    window.wait_idle(300)
    assert len(window.entries) == 3 and not window.errors
    assert not window.open_view("{not json")
    assert window.errors[-1].startswith("view: not JSON")
    assert not window.open_view(json.dumps({"geoshade_view": 1, "file": "/no/such.EGRID",
                                            "state": {}}))
    assert "does not exist" in window.errors[-1]


def test_range_and_section_controls_on_a_grid(window):
    from geoshade.viewer.views import demo_views

    _cls, grid, settings = demo_views()["grid"]
    entry = _open(window, grid, "grid", **settings)
    ctl, view = entry.panel.controls, entry.session.view
    poro, act = np.asarray(grid.properties["PORO"]), np.asarray(grid.active, bool)
    ctl["ranges"].set_range("PORO", 0.2, None)   # PORO >= 0.2, as typed into the min box
    window.wait_idle()
    assert entry.session.stats["shown_cells"] == int(np.count_nonzero(act & (poro >= 0.2)))
    assert ctl["ranges"].value() == {"PORO": [0.2, None]}
    assert "PORO from 0.2" in ctl["ranges"].narrowed.text()
    lo, hi = ctl["ranges"].extent["PORO"]
    ctl["ranges"].sliders[1].setValue(500)       # the max slider halfway: PORO <= mid
    window.wait_idle()
    mid = lo + (hi - lo) / 2
    n = int(np.count_nonzero(act & (poro >= 0.2) & (poro <= mid + 1e-9 * abs(mid))))
    assert entry.session.stats["shown_cells"] == n
    ctl["ranges"].clear.click()
    window.wait_idle()
    assert view.options.ranges is None
    assert entry.session.stats["shown_cells"] == int(act.sum())
    ctl["section"].on.setChecked(True)           # the clip plane from the panel, on a grid
    window.wait_idle()
    assert view.options.plane is not None and entry.panel.section[0] == "x"
    assert 0 < entry.session.stats["shown_cells"] < int(act.sum())


@needs_reek
def test_ijk_and_range_controls_draw_what_update_draws(window):
    """The I/J/K and value range controls of the panel: the picture and the cells of a View
    updated with the same options (``slice``, ``ranges``) as text, the cells numpy's."""
    from geoshade.viewer.qt import from_qimage

    entry = _open(window, str(REEK), property="SWAT", step=5)
    ctl, s = entry.panel.controls, entry.session
    g = s.view.model
    opened = s.view.state(s.camera.with_aspect(s.size[0] / s.size[1]))
    ctl["slice"].set_range("I", 5, 30)       # 1-based, both shown: i = 4:30
    ctl["slice"].set_range("K", 3, 10)
    ctl["ranges"].set_range("PORO", 0.2, None)
    window.wait_idle()
    assert s.view.options.ranges is not None and ctl["slice"].value()[0] == [4, 30]
    act = np.asarray(g.active, bool)
    poro = np.asarray(g.properties["PORO"], float)   # (ni, nj, nk) as resfo's INIT
    cut = np.zeros_like(act)
    cut[4:30, :, 2:10] = True
    assert s.stats["shown_cells"] == int(np.count_nonzero(act & cut & (poro >= 0.2)))
    shown = from_qimage(window.frame.grab().toImage())
    with geoshade.view(geoshade.load(REEK), **opened) as v:   # as opened, then updated
        v.update(slice="i=4:30,k=2:10", ranges="PORO=0.2:")
        want, stats = v.draw()
    assert stats["shown_cells"] == s.stats["shown_cells"]
    assert np.array_equal(shown[..., :3], want[..., :3])
