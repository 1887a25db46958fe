"""Picking in the viewers: a left click without drag picks, a drag still turns the model.

The session's pointer logic is tested without any display; then once through the Qt frame
widget (offscreen platform) and once through the notebook widget's events.
"""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.viewer.session import CLICK_SLOP, Session
from geoshade.viewer.views import open_view

SIZE = (96, 72)


@pytest.fixture
def session(ctx):
    vol = synthetic_core(20, seed=2)
    s = Session(open_view(vol, size=SIZE, select=vol.meta["pore_range"]), size=SIZE)
    s.draw()
    yield s
    s.view.release()


def _inside(s) -> tuple[int, int]:
    """A pixel of the picture that shows the model."""
    img = s.image
    ys, xs = np.nonzero(~(img[..., :3] == 255).all(axis=-1))
    k = int(np.argmin((xs - img.shape[1] / 2) ** 2 + (ys - img.shape[0] / 2) ** 2))
    return int(xs[k]), int(ys[k])


def test_a_click_picks_what_the_picture_shows(session):
    s = session
    x, y = _inside(s)
    cam = s.camera
    s.press(x, y)
    assert not s.move(x + CLICK_SLOP, y - 1)  # within the slop: no turn
    assert s.release(x + 1, y) == "click"
    assert s.camera is cam  # the camera did not move
    want = s.view.pick(x, y)
    assert s.picked is not None and s.picked.index == want.index
    assert s.pick_text == want.text() and "voxel x=" in s.pick_text


def test_a_drag_turns_and_does_not_pick(session):
    s = session
    x, y = _inside(s)
    az = s.camera.azimuth
    s.press(x, y)
    assert s.move(x + 30, y + 5)
    assert s.camera.azimuth != az
    assert s.release(x + 30, y + 5) == "drag"
    assert s.picked is None and s.pick_text == ""
    # a right button pans; a right click does not pick
    target = s.camera.target.copy()
    s.press(x, y, "right")
    assert s.move(x + 20, y)
    assert s.release(x + 20, y) == "drag" and not np.allclose(s.camera.target, target)
    s.press(x, y, "right")
    assert s.release(x, y) == "" and s.picked is None


def test_a_click_on_the_background_says_nothing_is_there(session):
    s = session
    s.press(0, 0)
    assert s.release(0, 0) == "click"
    assert s.picked is None and s.pick_text.startswith("nothing at pixel 0,0")


def test_a_click_picks_through_the_picture_scale(session):
    """Pointer pixels are scaled to picture pixels (a widget showing the picture larger)."""
    s = session
    x, y = _inside(s)
    s.press(2 * x, 2 * y)
    assert s.release(2 * x, 2 * y, scale=(0.5, 0.5)) == "click"
    assert s.picked.index == s.view.pick(x, y).index


def test_qt_click_shows_the_pick_in_the_status_bar(window):
    pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")
    from PySide6.QtCore import QPoint, Qt
    from PySide6.QtTest import QTest

    vol = synthetic_core(20, seed=2)
    window.open(vol, None, None, {"select": vol.meta["pore_range"]})
    window.wait_idle()
    assert not window.errors, window.errors
    s = window.session
    f = window.frame
    x, y = _inside(s)
    sx, sy = f.width() / s.size[0], f.height() / s.size[1]
    at = QPoint(round((x + 0.5) * sx), round((y + 0.5) * sy))
    az = s.camera.azimuth
    QTest.mouseClick(f, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, at)
    window.wait_idle()
    assert s.camera.azimuth == az and s.picked is not None
    assert window.pick_label.text() == s.pick_text and "voxel x=" in s.pick_text
    px = at.x() * s.size[0] / f.width()
    py = at.y() * s.size[1] / f.height()
    assert s.picked.index == s.view.pick(px, py).index
    # a drag still turns the model (and leaves the pick shown)
    QTest.mousePress(f, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, at)
    QTest.mouseMove(f, QPoint(at.x() + 40, at.y() + 10))
    QTest.mouseRelease(f, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier,
                       QPoint(at.x() + 40, at.y() + 10))
    window.wait_idle()
    assert s.camera.azimuth != az and window.pick_label.text() == s.pick_text


def _ev(kind, **kw):  # what jupyter_rfb hands handle_event (old and new keys)
    return {"event_type": kind, "type": kind, "modifiers": (), "buttons": (), **kw}


def test_notebook_click_picks_into_the_read_out(ctx):
    pytest.importorskip("jupyter_rfb", reason="geoshade.show needs jupyter_rfb (geoshade[viewer])")
    import geoshade

    vol = synthetic_core(20, seed=2)
    w = geoshade.show(vol, size=SIZE, select=vol.meta["pore_range"])
    try:
        w.get_frame()
        x, y = _inside(w.session)
        az = w.session.camera.azimuth
        w.handle_event(_ev("pointer_down", x=x, y=y, button=1, buttons=(1,)))
        w.handle_event(_ev("pointer_move", x=x + 1, y=y, button=1, buttons=(1,)))
        w.handle_event(_ev("pointer_up", x=x + 1, y=y, button=1))
        assert w.session.camera.azimuth == az
        assert w.picked is not None and w.picked.index == w.view.pick(x, y).index
        assert w.readout().splitlines()[-1] == w.pick_text == w.picked.text()
        w.handle_event(_ev("pointer_down", x=x, y=y, button=1, buttons=(1,)))
        w.handle_event(_ev("pointer_move", x=x + 30, y=y, button=1, buttons=(1,)))
        w.handle_event(_ev("pointer_up", x=x + 30, y=y, button=1))
        assert w.session.camera.azimuth != az  # a drag turns
        # a picture drawn at twice the pointer's pixels (a HiDPI screen)
        w.handle_event(_ev("resize", width=48, height=36, pixel_ratio=2.0))
        w.get_frame()
        x, y = _inside(w.session)
        w.handle_event(_ev("pointer_down", x=x / 2, y=y / 2, button=1, buttons=(1,)))
        w.handle_event(_ev("pointer_up", x=x / 2, y=y / 2, button=1))
        assert w.picked is not None and w.picked.index == w.view.pick(x, y).index
    finally:
        w.close()
