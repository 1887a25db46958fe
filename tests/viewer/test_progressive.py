"""The desktop viewer and the notebook widget show a progressive View's coarse preview first,
with a progress line, then the full picture; a change while loading supersedes the old load."""

from __future__ import annotations

import time

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid import GridView
from geoshade.grid import lod as lod_mod

OPTS = {"property": "PORO", "exaggeration": 5.0}


@pytest.fixture
def small_budget(monkeypatch):
    monkeypatch.setattr(lod_mod, "PREVIEW_CELLS", 2000)


@pytest.fixture(scope="module")
def grid():
    return synthetic_grid(24, 16, 8, seed=3)


def plain_picture(grid, size, camera=None, **opts):
    with GridView(grid, size=size, **{**OPTS, **opts}) as v:
        return v.draw(camera, frames=1)[0]


def test_window_shows_the_preview_then_the_full_picture(window, qapp, grid, small_budget):
    pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")
    from geoshade.viewer.views import make_view, prepare

    view = make_view(prepare(grid, "grid", None, None, progressive=True, **OPTS),
                     size=window._frame_size)
    assert view.loading
    labels = []
    window.runner.state_changed.connect(lambda label, done, total: labels.append(label))
    window.add_view(view, "g")
    window.session.draw()
    assert window.session.stats["coarse"] is True          # the preview is on screen first
    window.wait_idle()
    assert not view.loading and "coarse" not in window.session.stats
    assert any(lb.startswith("coarse preview — full picture") for lb in labels)
    img = window.session.image
    ref = plain_picture(grid, window.session.size, window.session.camera,
                        annotations=view.options.annotations)
    assert np.array_equal(img, ref)                         # exactly the full picture


def test_window_change_while_loading_supersedes(window, grid, small_budget):
    from geoshade.viewer.views import make_view, prepare

    view = make_view(prepare(grid, "grid", None, None, progressive=True, **OPTS),
                     size=window._frame_size)
    window.add_view(view, "g")
    window.apply(property="PERMX")          # while loading: a new preview, a new load
    window.wait_idle()
    assert not view.loading and window.session.stats["property"] == "PERMX"
    assert not window.errors


def test_notebook_widget_progress_line_then_full(ctx, grid, small_budget):
    pytest.importorskip("jupyter_rfb", reason="geoshade.show needs jupyter_rfb")
    import geoshade

    size = (160, 120)
    w = geoshade.show(grid, size=size, progressive=True, **OPTS)
    try:
        w.get_frame()
        assert w.stats["coarse"] is True
        assert "coarse preview — full picture" in w.readout()
        w.set(property="PERMX")               # supersedes the first load
        assert w.view.loading and w.view.preview.view.options.property == "PERMX"
        t_end = time.monotonic() + 60
        while not w.poll_loading():
            assert time.monotonic() < t_end, "the full picture never came"
            time.sleep(0.02)
        frame = w.get_frame()
        assert "coarse" not in w.stats and w.stats["property"] == "PERMX"
        assert "coarse preview" not in w.readout()
        ref = plain_picture(grid, size, property="PERMX",
                            annotations=w.view.options.annotations)
        assert np.array_equal(frame, ref[..., :3])
    finally:
        w.close()


def test_window_core_preview_then_full(window, tmp_path, monkeypatch):
    import geoshade
    from geoshade.core import preview as preview_mod
    from geoshade.io.stores.ingest import ingest

    monkeypatch.setattr(preview_mod, "PREVIEW_VOXELS", 20**3)
    a = np.asarray(geoshade.synthetic_core(48, porosity=0.25, seed=3).data)
    a.tofile(tmp_path / "c.raw")
    rep = ingest(tmp_path / "c.raw", tmp_path / "c.zarr", chunks=(16, 16, 16), levels=3,
                 shape=a.shape, dtype=str(a.dtype))
    window.open(str(rep.path), None, None, {"progressive": True, "select": (0, 15000)})
    window.wait_idle()
    assert not window.errors, window.errors
    view = window.session.view
    assert not view.loading and "coarse" not in window.session.stats
    assert window.session.stats["voxels_selected"] == int((a <= 15000).sum())
