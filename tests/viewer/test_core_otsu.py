"""The core panel's Otsu marker and button, and a cylinder ROI opened in the viewer."""

from __future__ import annotations

import numpy as np
import pytest

from tests.compute.test_roi import core_in_air, cylinder_mask

pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")
filters = pytest.importorskip("skimage.filters", reason="Otsu needs geoshade[threshold]")


def test_otsu_marker_and_button_select_the_pore_space(window):
    vol, (cx, cy, r) = core_in_air(32, seed=4)
    a = np.asarray(vol.data)
    window.open(vol, None, None, {"roi": f"cylinder:{cx},{cy},{r}", "select": (0, 255),
                                    "porosity": "z"})
    window.wait_idle()
    assert not window.errors, window.errors
    entry = window.active
    panel, view = entry.panel, entry.session.view
    inside = np.broadcast_to(cylinder_mask(a.shape, cx, cy, r), a.shape)
    t = float(filters.threshold_otsu(a[inside]))
    multi = [float(v) for v in filters.threshold_multiotsu(a[inside])]
    assert panel.histogram.otsu == t and panel.histogram.multi == multi  # the marker lines
    assert entry.session.stats["roi"]["cx"] == cx
    # every voxel inside the cylinder is selected, none outside
    assert entry.session.stats["voxels_selected"] == int(inside.sum())

    otsu = panel.controls["otsu"]
    assert otsu.isEnabled() and f"threshold {t:g}" in otsu.toolTip()
    otsu.click()  # selects the pore space: the values up to Otsu's threshold
    window.wait_idle()
    lo = float(a[inside].min())
    assert tuple(view.options.select) == (lo, t)
    sel = inside & (a >= lo) & (a <= t)
    assert entry.session.stats["voxels_selected"] == int(sel.sum())
    assert view.porosity.porosity == int(sel.sum()) / int(inside.sum())
    assert panel.figure.axes[0].get_xlabel() == "porosity"
    assert panel.controls["select"].texts() == [f"{lo:g}", f"{t:.6g}"]
    assert (panel.histogram.lo, panel.histogram.hi) == (lo, t)


def test_viewer_opens_with_select_auto(window):
    vol, (_, _, r) = core_in_air(32, seed=6)
    a = np.asarray(vol.data)
    window.open(vol, None, None, {"roi": "cylinder", "select": "auto"})
    window.wait_idle()
    assert not window.errors, window.errors
    view = window.active.session.view
    roi = view.options.roi
    assert roi.fitted and abs(roi.r - r) < 1.0
    inside = np.broadcast_to(cylinder_mask(a.shape, roi.cx, roi.cy, roi.r), a.shape)
    t = float(filters.threshold_otsu(a[inside]))
    assert view.options.select == (float(a[inside].min()), t)
    assert view.options.select_auto["threshold"] == t


def test_roi_typed_in_the_panel(window):
    vol, (cx, cy, r) = core_in_air(32, seed=7)
    a = np.asarray(vol.data)
    window.open(vol, None, None, {"select": (0, 255), "sample": "none",
                                    "porosity": "z"})  # the whole box
    window.wait_idle()
    entry = window.active
    roi = entry.panel.controls["roi"]
    assert entry.session.stats["voxels_selected"] == a.size and roi.text() == ""
    roi.setText(f"cylinder:{cx},{cy},{r}")
    roi.editingFinished.emit()
    window.wait_idle()
    inside = np.broadcast_to(cylinder_mask(a.shape, cx, cy, r), a.shape)
    assert entry.session.stats["voxels_selected"] == int(inside.sum())
    assert entry.session.view.porosity.total == int(inside.sum())
    assert roi.text() == f"cylinder:{cx:g},{cy:g},{r:g}"
    roi.setText("")  # back to the whole box
    roi.editingFinished.emit()
    window.wait_idle()
    assert entry.session.stats["voxels_selected"] == a.size and "roi" not in entry.session.stats
