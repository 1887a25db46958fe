"""The Qt panel renders the viewers' control specs (issue 30): the controls of every part's View
are the browser's (:func:`geoshade.viewer.controls.controls`), each type made by one widget, a
change goes through :func:`~geoshade.viewer.controls.to_options` as the browser's does, the
values shown are the View's settings (and, sent back, change nothing), and showing them sends
nothing. Qt offscreen."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.grid.view import GridView
from geoshade.stacks import section_plane
from geoshade.styles.declare import GROUPS
from geoshade.viewer.controls import controls, to_options
from geoshade.viewer.session import Session
from geoshade.viewer.values import control_values
from geoshade.viewer.views import demo_views, open_view, run_now

pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")

KINDS = ["core", "grid", "iso", "stacks"]


def _open(win, model, kind, **settings):
    win.open(model, kind, None, settings)
    win.wait_idle()
    assert not win.errors, win.errors
    return win.active


def _picture(win):
    win.wait_idle()
    return win.session.image.copy()


class Host:
    """What a panel calls, recorded (no window, nothing drawn)."""

    def __init__(self):
        self.applied: list[dict] = []
        self.errors: list[str] = []

    def apply(self, **options):
        self.applied.append(options)

    def show_error(self, text):
        self.errors.append(text)

    def idle(self):
        return True


@pytest.fixture(scope="module")
def views(ctx):
    """Every part's demo View, small."""
    out = {}
    for kind, (_cls, model, settings) in demo_views().items():
        out[kind] = open_view(model, kind, size=(48, 36), **settings)
    yield out
    for v in out.values():
        v.release()


def _panel(qapp, view):
    from geoshade.viewer.panels import panel_for

    host = Host()
    return panel_for(Session(view, size=(48, 36)), host), host


@pytest.mark.parametrize("kind", KINDS)
def test_the_qt_panel_has_the_browsers_controls(window, kind):
    """Every control the browser shows (the specs) and no other, each made by its type's one
    widget, in the declared groups, in order; opening sends no change."""
    from PySide6.QtWidgets import QLabel

    from geoshade.viewer.panels.widgets import WIDGETS

    _cls, model, settings = demo_views()[kind]
    entry = _open(window, model, kind, **settings)
    groups = controls(entry.session.view)
    specs = [c for g in groups for c in g["controls"]]
    panel = entry.panel
    assert set(panel.controls) == {c["name"] for c in specs}
    assert list(panel.controls) == [c["name"] for c in specs]
    assert [b.title() for b in panel.boxes.values()] == [g["group"] for g in groups]
    for spec in specs:
        widget = panel.controls[spec["name"]]
        assert type(widget) is WIDGETS[spec["type"]], spec["name"]
        box = panel.boxes[GROUPS[spec["group"]]]
        if spec["type"] in ("check", "button"):   # they carry their label
            assert spec["label"] in widget.text()
        else:
            assert spec["label"] in {w.text() for w in box.findChildren(QLabel)}
        assert widget.toolTip().startswith(spec.get("help") or "")


@pytest.mark.parametrize("kind", KINDS)
def test_showing_the_settings_sends_nothing(window, kind, monkeypatch):
    _cls, model, settings = demo_views()[kind]
    entry = _open(window, model, kind, **settings)
    sent = []
    monkeypatch.setattr(window, "apply", lambda **kw: sent.append(kw))
    entry.panel.sync()
    window.select(0)
    assert sent == []


def test_categorical_from_the_qt_panel_drops_the_legend(window):
    """Issue 30's bug, from the desktop panel: a grid coloured by an integer region property
    (FIPNUM) is drawn as categories with a legend; "categorical" set to no in the panel draws
    the continuous colour bar, the picture a View opened with ``categorical=False`` draws."""
    grid, _settings = GridView.demo()
    entry = _open(window, grid, "grid", property="FIPNUM")
    box = entry.panel.controls["categorical"]
    assert box.currentText() == "auto"
    _picture(window)
    before = entry.session.stats
    assert before["categories"] and "legend" in before["annotations"]
    box.choose(False)
    img = _picture(window)
    after = entry.session.stats
    assert after["categories"] is None and "legend" not in after["annotations"]
    assert "colorbar" in after["annotations"] and box.currentText() == "no"
    assert entry.session.view.options.color.categorical is False
    s = entry.session
    with open_view(grid, "grid", size=s.size, property="FIPNUM", categorical=False) as v:
        want, _ = v.draw(s.camera)
    assert np.array_equal(img, want)
    box.choose("auto")   # back: the legend again
    _picture(window)
    assert entry.session.stats["categories"] == before["categories"]


def test_each_control_type_sends_through_to_options(qapp, views):
    """A change of each type reaches ``host.apply`` as the browser's does (to_options)."""
    grid, host = _panel(qapp, views["grid"])
    ctl = grid.controls
    ctl["categorical"].choose(False)            # select, auto/yes/no
    ctl["categorical"].choose("auto")
    ctl["edges"].choose("paper")                # select
    ctl["well_xray"].setChecked(False)          # check
    ctl["wells"].setChecked(False)              # check: the wells it opened with, or none
    ctl["wells"].setChecked(True)
    ctl["filter"].setText(" PORO > 0.2 ")       # text, Enter
    ctl["filter"].returnPressed.emit()
    ctl["filter"].editingFinished.emit()        # unchanged: not sent twice
    ctl["expression"].setText("PORO * NTG")     # text that sets another option
    ctl["expression"].returnPressed.emit()
    ctl["well_radius"].setText("25")            # number
    ctl["well_radius"].editingFinished.emit()
    ctl["color_range"].set_values([0.1, 0.3])   # pair
    ctl["step"].slider.setValue(1)              # step
    ctl["colormap"].setEditText("RdYlBu")       # editable select, typed
    ctl["colormap"].lineEdit().returnPressed.emit()
    ctl["view"].choose("top")                   # camera: the session's
    wells = list(views["grid"].options.wells)
    assert host.applied == [
        {"categorical": False}, {"categorical": None}, {"edges": "paper"},
        {"well_xray": False}, {"wells": False}, {"wells": wells}, {"filter": "PORO > 0.2"},
        {"property": "PORO * NTG"}, {"well_radius": 25.0}, {"color_range": (0.1, 0.3)},
        {"step": 1}, {"colormap": "RdYlBu"}, {"view": "top"}]
    assert host.errors == []
    ctl["well_radius"].setText("wide")          # one line, nothing sent
    ctl["well_radius"].editingFinished.emit()
    assert host.errors == ["well radius: expected a number, got 'wide'"]
    assert len(host.applied) == 13
    ctl["color_range"].fields[0].setText("")    # half a pair waits
    ctl["color_range"].fields[0].editingFinished.emit()
    assert len(host.applied) == 13

    core, host = _panel(qapp, views["core"])
    core.controls["box"].set_values([1, 2, 3, 10, 20, 30])   # ints
    core.controls["otsu"].click()                            # button
    core.controls["select"].set_values([5, 900])             # pair
    assert host.applied == [{"box": (1, 2, 3, 10, 20, 30)}, {"select": "auto"},
                            {"select": (5.0, 900.0)}]
    core.controls["box"].set_values([1, 2, 3, 10, 20, 30.5])
    assert host.errors == ["box: expected a whole number, got '30.5'"]

    stacks, host = _panel(qapp, views["stacks"])
    mats, section = stacks.controls["materials"], stacks.controls["section"]
    codes = list(mats.visible)
    mats.visible[codes[0]].setChecked(False)                 # materials
    mats.opacity[codes[1]].setValue(25)
    section.on.setChecked(True)                              # section
    model = views["stacks"].model
    assert host.applied[:2] == [{"hide": (codes[0],), "opacity": {}},
                                {"hide": (codes[0],), "opacity": {codes[1]: 0.25}}]
    assert host.applied[2] == {"plane": section_plane(model, "x", 0.5, False)}
    assert stacks.section == ["x", 0.5, False]
    section.on.setChecked(False)
    assert host.applied[3] == {"plane": None}


@pytest.mark.parametrize("kind", KINDS)
def test_the_values_shown_change_nothing_when_sent_back(views, kind):
    """Each value a control shows (a slice, a plane, a box, a colour range as typed) goes back
    through to_options to the View, which takes it and keeps its settings: what the panel
    shows is what the View draws."""
    view = views[kind]
    groups = controls(view)
    if kind == "grid":
        view.update(plane="1,0,0", filter="PORO > 0.1")
    before = view.settings()
    values = control_values(groups, {**before, "view": "iso", "ortho": False})
    assert values
    opened = {"drape": getattr(view.options, "drape", None),
              "wells": getattr(view.options, "wells", None)}
    for name, value in values.items():
        if name in ("view", "ortho", "exaggeration", "section"):
            continue   # the session's camera; a section is only known once set
        if name == "materials":
            options = {**to_options("hide", value["hide"], view, opened),
                       **to_options("opacity", value["opacity"], view, opened)}
        else:
            options = to_options(name, value, view, opened)
        run_now(view.jobs(**options))   # taken (a long change may be built again)
    after = view.settings()
    for k, v in before.items():
        if isinstance(v, np.ndarray):
            assert np.array_equal(v, after[k]), k
        else:
            assert after[k] == v, k
    if kind == "grid":
        # a grid's plane is set by the section control (axis, fraction, flip): a plane typed
        # elsewhere is no section of it, so the control shows none; the I/J/K ranges show the
        # whole grid, the value ranges none narrowed
        assert "plane" not in values and values["section"] is None
        assert values["slice"] == [[0, n] for n in view.model.dims] and values["ranges"] == {}
        view.update(plane=None, filter=None)


def test_keys_and_toolbar_show_in_the_camera_controls(window):
    """The camera controls follow what keys and the toolbar's named views did."""
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest

    _cls, model, settings = demo_views()["grid"]
    entry = _open(window, model, "grid", **settings)
    ctl = entry.panel.controls
    assert ctl["exaggeration"].text() == "5" and ctl["view"].currentText() == "iso"
    QTest.keyClick(window.frame, Qt.Key.Key_BracketRight)   # ×1.5
    assert ctl["exaggeration"].text() == "7.5"
    QTest.keyClick(window.frame, Qt.Key.Key_O)
    assert ctl["ortho"].isChecked() and entry.session.ortho
    window.set_view("top")
    assert ctl["view"].currentText() == "top"
    ctl["ortho"].setChecked(False)   # and the other way round
    assert not entry.session.ortho and not window.ortho
    _picture(window)
    assert entry.session.stats["exaggeration"] == 7.5


def test_the_pick_line_follows_a_property_chosen_in_the_panel(window):
    """A cell picked, then another property chosen in the panel: the status bar's pick line
    names the new property's value of the same cell (the pick is made again)."""
    from PySide6.QtCore import QPoint, Qt
    from PySide6.QtTest import QTest

    _cls, model, settings = demo_views()["grid"]
    entry = _open(window, model, "grid", **settings)
    s, f = entry.session, window.frame
    img = _picture(window)
    ys, xs = np.nonzero((img[..., :3] != 255).any(-1))
    h, w = img.shape[:2]
    order = np.argsort((xs - w / 2) ** 2 + (ys - h / 2) ** 2)   # from the middle out
    x, y = next((xs[k], ys[k]) for k in order if s.view.pick(xs[k], ys[k]) is not None)
    at = QPoint(round((x + 0.5) * f.width() / s.size[0]),
                round((y + 0.5) * f.height() / s.size[1]))
    QTest.mouseClick(f, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, at)
    window.wait_idle()
    assert s.picked is not None and "PORO" in window.pick_label.text()
    cell = s.picked.index
    entry.panel.controls["property"].choose("PERMX")
    _picture(window)
    assert "PERMX" in window.pick_label.text() and "PORO" not in window.pick_label.text()
    assert s.picked.index == cell and window.pick_label.text() == s.pick_text
