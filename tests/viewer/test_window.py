"""The real viewer window under Qt's offscreen platform: open each kind of data, change a
control (found by its name, ``panel.controls[name]``, as the browser's), check the picture and
the read-out, take a screenshot."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.voxels.synthetic import synthetic_core

pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")


def _open(win, model, kind=None, **settings):
    win.open(model, kind, None, settings)
    win.wait_idle()
    assert not win.errors, win.errors
    assert win.session is not None and win.session.image is not None
    return win.active


def _picture(win):
    win.wait_idle()
    return win.session.image.copy()


def _type(box, text):
    """Type ``text`` into a text box and press Enter."""
    box.setText(text)
    box.returnPressed.emit()


def _demo(kind):
    from geoshade.viewer.views import demo_views

    demos = demo_views()
    return demos[kind][1], demos[kind][2]


def test_core_range_box_method_and_porosity(window):
    from geoshade.viewer.qt import from_qimage

    vol = synthetic_core(32, seed=5)
    lo, hi = vol.meta["pore_range"]
    entry = _open(window, vol, select=(lo, hi), porosity="z")
    panel, a = entry.panel, np.asarray(vol.data)
    ctl = panel.controls
    img0, text0 = _picture(window), window.readout.text()
    assert f"{np.count_nonzero((a >= lo) & (a <= hi)):,} voxels selected" in text0
    # the frame widget shows the picture the View drew (scaled to the widget)
    shown = from_qimage(window.frame.grab().toImage())
    assert shown.shape[:2] == img0.shape[:2]

    new_hi = hi - 3000
    ctl["select"].fields[1].setText(f"{new_hi:g}")  # as a user typing into the box
    ctl["select"].fields[1].returnPressed.emit()
    img1 = _picture(window)
    assert not np.array_equal(img0, img1)
    want = int(np.count_nonzero((a >= lo) & (a <= new_hi)))
    assert f"{want:,} voxels selected" in window.readout.text()
    assert entry.session.view.porosity.porosity == pytest.approx(want / a.size)
    assert panel.histogram.hi == new_hi   # the selection drawn on the histogram
    assert ctl["box"].texts() == ["0", "0", "0", "32", "32", "32"]

    ctl["box"].set_values([0, 0, 0, 16, 32, 32])  # box x size 32 -> 16
    img2 = _picture(window)
    st = entry.session.stats
    assert st["box"] == [0, 0, 0, 16, 32, 32]
    assert st["voxels_selected"] == int(np.count_nonzero((a[:, :, :16] >= lo)
                                                         & (a[:, :, :16] <= new_hi)))
    assert not np.array_equal(img1, img2)
    line = panel.figure.axes[0].lines[0]
    assert np.allclose(line.get_xdata(), entry.session.view.porosity.profile)

    ctl["method"].choose("cubes")
    _picture(window)
    assert entry.session.stats["method"] == "cubes"
    assert window.readout.text().startswith(f"{entry.session.stats['frame_ms']:.1f} ms/frame")
    assert ctl["occlusion"].currentText() == "auto" and "occlusion" not in entry.session.stats
    img3 = _picture(window)
    ctl["occlusion"].choose(True)   # creases darken: the picture changes, only darker
    img4 = _picture(window)
    assert entry.session.stats["occlusion"]["strength"] == 0.7
    assert not np.array_equal(img3, img4) and (img4[..., :3] <= img3[..., :3]).all()


def test_mouse_keys_and_screenshot(window, tmp_path, monkeypatch):
    from PySide6.QtCore import QPoint, Qt
    from PySide6.QtTest import QTest

    from geoshade.io.output import write_png  # noqa: F401  (the writer the viewer uses)

    _open(window, synthetic_core(24, seed=1))
    f = window.frame
    img0 = _picture(window)
    az0 = window.session.camera.azimuth
    QTest.mousePress(f, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, QPoint(50, 50))
    QTest.mouseMove(f, QPoint(90, 60))
    QTest.mouseRelease(f, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier,
                       QPoint(90, 60))
    img1 = _picture(window)
    assert window.session.camera.azimuth != az0
    assert not np.array_equal(img0, img1)
    QTest.keyClick(f, Qt.Key.Key_T)
    assert window.session.camera.elevation == 90.0
    img2 = _picture(window)
    assert not np.array_equal(img1, img2)
    QTest.keyClick(f, Qt.Key.Key_Plus)
    assert not np.array_equal(img2, _picture(window))
    QTest.keyClick(f, Qt.Key.Key_O)
    assert window.session.camera.ortho and window.active.panel.controls["ortho"].isChecked()
    monkeypatch.chdir(tmp_path)
    QTest.keyClick(f, Qt.Key.Key_S)
    shots = list(tmp_path.glob("geoshade-core-*.png"))
    assert len(shots) == 1 and window.last_screenshot.name == shots[0].name
    from PIL import Image

    assert np.array_equal(np.asarray(Image.open(shots[0])), _picture(window))
    QTest.keyClick(f, Qt.Key.Key_H)
    assert f.show_help


def test_grid_controls(window):
    grid, settings = _demo("grid")
    entry = _open(window, grid, "grid", **settings)
    ctl = entry.panel.controls
    img0, t0 = _picture(window), window.readout.text()
    assert t0.split(" · ")[2].startswith("PORO") and "2 wells" in t0
    ctl["property"].choose("PERMX")
    img1 = _picture(window)
    assert not np.array_equal(img0, img1) and "PERMX" in window.readout.text()
    _type(ctl["expression"], "log10(PERMX)")   # colour by an expression: listed once applied
    assert not np.array_equal(img1, _picture(window))
    assert entry.session.stats["property"] == "log10(PERMX)"
    assert ctl["property"].currentText() == "log10(PERMX)"
    assert "SWAT" in grid.property_names() and len(grid.steps) > 2
    ctl["property"].choose("SWAT")
    img_s0 = _picture(window)
    ctl["step"].slider.setValue(2)  # a report-step property: the step slider changes colours
    img_s2 = _picture(window)
    assert entry.session.stats["step"] == 2 and "SWAT step 2" in window.readout.text()
    assert ctl["step"].label.text().startswith("step 2 (")
    assert not np.array_equal(img_s0, img_s2)
    assert ctl["slice"].value() == [[0, 24], [0, 18], [0, 8]]   # the whole grid
    ctl["slice"].set_range("K", 1, 3)   # the I/J/K range control: layers 1 to 3 (1-based)
    img2 = _picture(window)
    st = entry.session.stats
    want = int(np.count_nonzero(grid.active[:, :, :3]))
    assert st["shown_cells"] == want and f"{want:,} of" in window.readout.text()
    assert ctl["slice"].value() == [[0, 24], [0, 18], [0, 3]]
    assert entry.session.view.options.slice[2] == slice(0, 3)
    assert not np.array_equal(img_s2, img2)
    _type(ctl["filter"], "PORO > 0.2")
    _picture(window)
    poro = np.asarray(grid.properties["PORO"])
    assert entry.session.stats["shown_cells"] == int(
        np.count_nonzero(grid.active[:, :, :3] & (poro[:, :, :3] > 0.2)))
    ctl["wells"].setChecked(False)
    img3 = _picture(window)
    assert "wells" not in window.readout.text()
    ctl["edges"].choose("none")
    assert not np.array_equal(img3, _picture(window))
    ctl["faults"].choose("highlight")
    _picture(window)
    assert entry.session.stats["faults"] == "highlight"
    _type(ctl["exaggeration"], "2")
    _picture(window)
    assert entry.session.stats["exaggeration"] == 2.0 and ctl["exaggeration"].text() == "2"
    _type(ctl["filter"], "NOSUCH > 1")
    window.wait_idle()
    assert window.errors and "NOSUCH" in window.errors[-1]
    assert ctl["filter"].text() == "PORO > 0.2"   # the filter still drawn


def test_iso_level_step_play_colour(window):
    field, settings = _demo("iso")
    entry = _open(window, field, "iso", **settings)
    ctl = entry.panel.controls
    step = ctl["step"]
    img0 = _picture(window)
    step.slider.setValue(7)
    img1 = _picture(window)
    assert entry.session.stats["step"] == 7 and "step 7 of 8" in window.readout.text()
    assert not np.array_equal(img0, img1)
    _type(ctl["level"], "0.3")
    img2 = _picture(window)
    assert entry.session.stats["level"] == pytest.approx(0.3)
    assert not np.array_equal(img1, img2)
    step.play.setChecked(True)
    assert step.timer.isActive() and step.play.text() == "⏸ pause"
    step.advance()  # what the play timer does
    _picture(window)
    assert entry.session.stats["step"] == 0 and step.slider.value() == 0  # 7 + 1 wraps round
    step.play.setChecked(False)
    assert not step.timer.isActive()
    step.slider.setValue(7)
    img2 = _picture(window)
    assert entry.session.stats["color_by"] == "PRESSURE"
    ctl["color_by"].choose(None)
    img3 = _picture(window)
    assert entry.session.stats["color_by"] is None and ctl["color_by"].currentText() == "(none)"
    assert entry.session.stats["triangles"] > 0 and not np.array_equal(img2, img3)
    assert entry.session.stats["caps"] is False
    ctl["caps"].setChecked(True)   # closed at inactive cells (the demo field has none)
    _picture(window)
    assert entry.session.stats["caps"] is True


def test_stacks_materials_section_boreholes_drape(window):
    model, settings = _demo("stacks")
    entry = _open(window, model, "stacks", **settings)
    ctl = entry.panel.controls
    mats, section = ctl["materials"], ctl["section"]
    img0 = _picture(window)
    code = next(iter(mats.visible))
    mats.visible[code].setChecked(False)
    img1 = _picture(window)
    assert entry.session.stats["hidden"] == [code]
    assert "1 hidden" in window.readout.text()
    assert not np.array_equal(img0, img1)
    other = list(mats.opacity)[1]
    mats.opacity[other].setValue(40)
    _picture(window)
    assert entry.session.view.options.opacity == {other: 0.4}
    assert not mats.visible[code].isChecked() and mats.opacity[other].value() == 40
    section.on.setChecked(True)
    img2 = _picture(window)
    assert entry.session.stats["section"] is not None
    assert not np.array_equal(img1, img2)
    section.position.setValue(30)   # the cut moves, the controls keep what was set
    img2b = _picture(window)
    assert not np.array_equal(img2, img2b)
    assert section.on.isChecked() and section.position.value() == 30
    ctl["boreholes"].setChecked(True)
    img3 = _picture(window)
    assert entry.session.stats["boreholes_only"]
    assert not np.array_equal(img2b, img3)
    ctl["boreholes"].setChecked(False)
    section.on.setChecked(False)
    _picture(window)
    assert entry.session.view.options.plane is None
    drape = ctl["drape"]
    drape.setChecked(not drape.isChecked())
    img4 = _picture(window)
    assert entry.session.stats["drape"] == drape.isChecked()
    drape.setChecked(not drape.isChecked())   # the picture it opened with, again
    _picture(window)
    assert entry.session.stats["drape"] == drape.isChecked()
    ctl["legend"].setChecked(False)
    assert not np.array_equal(img4, _picture(window))


def test_worker_keeps_only_the_newest_job(qapp):
    import threading
    import time

    from geoshade.render.view import Job
    from geoshade.viewer.qt import TaskRunner

    runner, applied, done, gate = TaskRunner(), [], [], threading.Event()

    def compute(_progress, k):
        gate.wait(10)  # the first job is still running when the others arrive
        return k * 10

    for k in range(5):
        runner.submit(Job("sel", "work", lambda p, k=k: compute(p, k), applied.append),
                      then=lambda: done.append(1))
    gate.set()

    t_end = time.monotonic() + 20
    while runner.busy() and time.monotonic() < t_end:
        qapp.processEvents()
        time.sleep(0.002)
    qapp.processEvents()
    assert applied == [40] and done == [1]
    runner.shutdown()


def test_a_job_done_before_submit_returns_is_applied_from_the_event_loop(qapp, monkeypatch):
    """A job that finishes before ``submit`` has attached its callback (the done-callback then
    runs on the GUI thread at once) is still applied from the event loop, never inside
    ``submit``: a window that draws right after ``add_view`` shows the preview first."""
    import concurrent.futures

    from geoshade.render.view import Job
    from geoshade.viewer.qt import TaskRunner

    runner, applied = TaskRunner(), []

    def run_now(fn):   # the worker thread was faster than submit
        f = concurrent.futures.Future()
        f.set_result(fn())
        return f

    monkeypatch.setattr(runner._pool, "submit", run_now)
    runner.submit(Job("k", "work", lambda p: 7, applied.append))
    assert applied == [] and runner.busy()
    qapp.processEvents()
    assert applied == [7] and not runner.busy()
    runner.shutdown()


def test_open_errors_are_one_line(window, tmp_path):
    window.open(tmp_path / "missing.raw")
    window.wait_idle()
    assert window.errors == [f"{tmp_path / 'missing.raw'}: no such file"]


def test_long_work_shows_progress_and_keeps_the_window_alive(window, qapp):
    import threading
    import time

    from PySide6.QtCore import QTimer

    from geoshade.render.view import Job

    gate, ticks = threading.Event(), []

    def slow(progress):  # what building bit maps of a big box looks like to the window
        progress(1, 4)
        gate.wait(20)
        return "maps"

    QTimer.singleShot(5, lambda: ticks.append(1))
    window.runner.submit(Job("slow", "building bit maps", slow, lambda r: None))
    assert window.progress.isVisible() and window.progress.format().startswith("building")
    t_end = time.monotonic() + 10
    while (not ticks or window.progress.maximum() != 4) and time.monotonic() < t_end:
        qapp.processEvents()  # the GUI thread is free while the worker computes
        time.sleep(0.002)
    assert ticks and window.progress.maximum() == 4 and window.progress.value() == 1
    assert window.runner.busy() and not window.idle()
    gate.set()
    window.wait_idle()
    assert not window.progress.isVisible()

    _open(window, synthetic_core(24, seed=9))
    pair = window.active.panel.controls["select"]
    lo = float(pair.texts()[0]) + 1000
    pair.fields[0].setText(f"{lo:g}")
    pair.fields[0].returnPressed.emit()
    assert window.runner.busy()   # the maps are rebuilt on the worker
    window.wait_idle()
    assert window.session.stats["select"][0] == lo and float(pair.texts()[0]) == lo


@pytest.mark.parametrize("kind", ["grid", "iso", "core"])
def test_colour_controls_in_every_panel(window, kind):
    """Colour map (listed or typed), fixed range and scale from the panel reach the View and
    the colour bar."""
    model, settings = _demo(kind)
    entry = _open(window, model, kind, **settings)
    ctl = entry.panel.controls
    img0 = _picture(window)
    ctl["colormap"].choose("magma")
    img1 = _picture(window)
    assert entry.session.view.options.color.colormap == "magma" and not np.array_equal(img0, img1)
    ctl["colormap"].setEditText("RdYlBu")   # any matplotlib name, typed
    ctl["colormap"].lineEdit().returnPressed.emit()
    _picture(window)
    assert entry.session.view.options.color.colormap == "RdYlBu"
    lo, hi = entry.session.stats["color_range"]   # shown as the automatic range's hint
    assert ctl["color_range"].texts() == ["", ""]
    assert ctl["color_range"].fields[1].placeholderText() == f"auto {hi:.6g}"
    ctl["color_range"].set_values([lo, lo + 2 * (hi - lo)])
    _picture(window)
    st = entry.session.stats
    assert st["annotations"]["colorbar"]["hi"] == pytest.approx(lo + 2 * (hi - lo))
    ctl["color_range"].set_values([None, None])   # automatic again
    _picture(window)
    assert entry.session.view.options.color.range is None
    if "log" in ctl:
        ctl["log"].choose(False)
        _picture(window)
        assert entry.session.view.options.color.log is False


@pytest.mark.parametrize("kind", ["core", "grid", "iso", "stacks"])
def test_side_panel_is_not_clipped(window, kind):
    """The right-hand panel fits its side: no part of it is hidden behind a sideways scroll
    bar (it was: the core panel needed 543 px in a 300 px side)."""
    model, settings = _demo(kind)
    entry = _open(window, model, kind, **settings)
    side = window.side
    assert not side.horizontalScrollBar().isVisible()
    assert entry.panel.width() >= entry.panel.sizeHint().width()
    assert side.viewport().width() >= entry.panel.sizeHint().width()
