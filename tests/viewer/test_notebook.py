"""``geoshade.show``: the jupyter_rfb widget driven by synthetic events, without a notebook."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.voxels.synthetic import synthetic_core

pytest.importorskip("jupyter_rfb", reason="geoshade.show needs jupyter_rfb (geoshade[viewer])")


def _ev(kind, **kw):  # what jupyter_rfb hands handle_event (old and new keys)
    return {"event_type": kind, "type": kind, "modifiers": (), "buttons": (), **kw}


def test_show_widget_events_change_the_frame(ctx):
    import geoshade

    vol = synthetic_core(24, seed=4)
    w = geoshade.show(vol, size=(96, 72), select=vol.meta["pore_range"])
    try:
        from jupyter_rfb import RemoteFrameBuffer

        assert isinstance(w, RemoteFrameBuffer)
        f0 = w.get_frame()
        assert f0.shape == (72, 96, 3) and (f0 != 255).any()
        w.handle_event(_ev("pointer_down", x=20, y=20, button=1, buttons=(1,)))
        w.handle_event(_ev("pointer_move", x=60, y=30, button=1, buttons=(1,)))
        f1 = w.get_frame()
        assert w.stats["voxels_drawn"] is None  # dragging: no counting pass
        w.handle_event(_ev("pointer_up", x=60, y=30, button=1))
        f2 = w.get_frame()
        assert not np.array_equal(f0, f1) and np.array_equal(f1, f2)
        assert w.stats["voxels_drawn"] > 0
        w.handle_event(_ev("wheel", dx=0, dy=-200, x=48, y=36))
        f3 = w.get_frame()
        assert not np.array_equal(f2, f3)
        w.handle_event(_ev("key_down", key="2"))
        assert w.session.camera.elevation == 90.0
        w.handle_event(_ev("resize", width=64, height=48, pixel_ratio=1.5))
        assert w.get_frame().shape == (72, 96, 3)
        before = w.stats["voxels_selected"]
        lo, hi = vol.meta["pore_range"]
        w.set(select=(lo, hi - 3000))
        w.get_frame()
        a = np.asarray(vol.data)
        assert w.stats["voxels_selected"] == int(np.count_nonzero((a >= lo) & (a <= hi - 3000)))
        assert w.stats["voxels_selected"] != before and "voxels selected" in w.readout()
    finally:
        w.close()
    assert w.view.released and w.view.gpu_bytes == 0  # the GPU objects are released


def test_a_resize_frames_the_model_again_until_the_user_moves_it(ctx):
    """The widget's resize (the notebook's cell narrower, wider): while the camera is the
    framed one the model is framed again for the new size (the picture a fresh widget of that
    size draws: nothing clipped); after a drag the camera the user chose is kept. The desktop
    window and the browser tab resize through the same Session."""
    import geoshade

    vol = synthetic_core(24, seed=4)
    opts = {"select": vol.meta["pore_range"]}
    w = geoshade.show(vol, size=(160, 120), **opts)
    fresh = geoshade.show(vol, size=(60, 120), **opts)
    try:
        w.get_frame()
        w.handle_event(_ev("resize", width=60, height=120, pixel_ratio=1.0))
        assert w.session.framed
        np.testing.assert_array_equal(w.get_frame(), fresh.get_frame())
        w.handle_event(_ev("pointer_down", x=20, y=20, button=1, buttons=(1,)))
        w.handle_event(_ev("pointer_move", x=40, y=30, button=1, buttons=(1,)))
        w.handle_event(_ev("pointer_up", x=40, y=30, button=1))
        moved = w.session.camera
        assert not w.session.framed
        w.handle_event(_ev("resize", width=100, height=80, pixel_ratio=1.0))
        assert w.session.camera is moved and w.get_frame().shape == (80, 100, 3)
        w.handle_event(_ev("key_down", key="0"))     # reset: framed again, and resizes follow
        assert w.session.framed
    finally:
        w.close()
        fresh.close()
