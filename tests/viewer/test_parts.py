"""Part adapters and the session (no GUI toolkit): the viewer's thin layer over the Views."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.synthetic import synthetic_core
from geoshade.errors import InputError
from geoshade.viewer.parts import demo_parts, open_part, run_now
from geoshade.viewer.parts.core import volume_histogram
from geoshade.viewer.session import KEY_VIEWS, Session

SIZE = (96, 72)


def test_histogram_is_numpy_histogram():
    vol = synthetic_core(20, seed=3)
    h = volume_histogram(vol, bins=32)
    a = np.asarray(vol.data)
    assert (h.vmin, h.vmax) == (float(a.min()), float(a.max()))
    want = np.histogram(a, bins=32, range=(a.min(), a.max() + 1))[0]
    assert np.array_equal(h.counts, want)
    f = synthetic_core(12, seed=1)
    f.data = f.data.astype(np.float32) / 7.0
    hf = volume_histogram(f, bins=16)
    af = np.asarray(f.data)
    assert np.array_equal(hf.counts, np.histogram(af, bins=16, range=(af.min(), af.max()))[0])


def test_core_two_halves_draw_what_coreview_draws(ctx):
    """The viewer builds maps off the GL thread and hands them over: same picture, same counts
    as CoreView.set_range/set_box doing both itself."""
    from geoshade.core import CoreView

    vol = synthetic_core(32, seed=2)
    lo, hi = vol.meta["pore_range"]
    part = open_part(vol, size=SIZE, range=(lo, hi))
    for job in part.apply(range=(lo, hi - 2000), box=[4, 2, 0, 24, 28, 30]):
        run_now(job)
    cam = part.camera(view="iso")
    img, st = part.draw(cam)
    ref = CoreView(vol, range=(lo, hi - 2000), box=[4, 2, 0, 24, 28, 30], size=SIZE,
                   color_range=part.view.color_range)
    try:
        ref_img, ref_st = ref.draw(cam)
    finally:
        ref.release()
        part.release()
    assert np.array_equal(img, ref_img)
    assert st["voxels_selected"] == ref_st["voxels_selected"]
    a = np.asarray(vol.data)[0:30, 2:30, 4:28]
    assert st["voxels_selected"] == int(np.count_nonzero((a >= lo) & (a <= hi - 2000)))


@pytest.mark.parametrize("kind", ["core", "grid", "iso", "stacks"])
def test_session_interaction_changes_the_picture(ctx, kind, tmp_path):
    demos = demo_parts()
    if kind not in demos:
        pytest.skip(f"the {kind} part is not installed")
    _cls, model, settings = demos[kind]
    part = open_part(model, kind=kind, size=SIZE, **settings)
    s = Session(part, size=SIZE)
    try:
        img0, st = s.draw()
        assert img0.shape == (SIZE[1], SIZE[0], 4)
        assert (img0[..., :3] != 255).any(), "the first frame is empty"
        assert "ms/frame" in s.readout() and "MiB" in s.readout()
        assert st["gpu_bytes"] > 0
        s.orbit(60, 15)
        img1, _ = s.draw(interactive=True)
        assert not np.array_equal(img0, img1)
        s.zoom(3)
        img2, _ = s.draw()
        assert not np.array_equal(img1, img2)
        s.pan(10, 0)
        img3, _ = s.draw()
        assert not np.array_equal(img2, img3)
        assert s.key("2") == "view" and s.camera.elevation == 90.0
        assert s.key("K") == "view" and s.camera.azimuth == 180.0
        assert s.key("o") == "ortho" and s.camera.ortho
        if part.exaggeration:
            before = s.camera.radius
            assert s.key("]") == "exaggerate"
            assert s.exaggeration == pytest.approx(settings.get("exaggeration", 1.0) * 1.5)
            assert s.camera.radius != before  # framed on the new bounds
        else:
            assert s.exaggeration is None and s.key("]") is None
        out = s.screenshot(tmp_path / "shot.png")
        from PIL import Image

        assert np.array_equal(np.asarray(Image.open(out)), s.image)
    finally:
        part.release()


def test_settings_errors_are_one_line(ctx):
    part = open_part(synthetic_core(16), size=SIZE)
    try:
        with pytest.raises(InputError, match="property: not a setting of the core view"):
            part.apply(property="PORO")
        with pytest.raises(InputError, match="method"):
            part.apply(method="fastest")
    finally:
        part.release()
    with pytest.raises(InputError, match="no view for a ndarray"):
        open_part(np.zeros(3))


def test_key_table_names_every_view():
    from geoshade.render.camera import VIEWS

    assert set(KEY_VIEWS.values()) == set(VIEWS)
    assert {KEY_VIEWS[str(k)] for k in range(1, 8)} == set(VIEWS)
