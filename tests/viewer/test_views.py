"""The viewer's toolkit-free layer over the Views: opening, the session, the CPU/GL split."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.errors import InputError
from geoshade.viewer.session import KEY_VIEWS, Session
from geoshade.viewer.views import demo_views, open_view, prepare, run_now

SIZE = (96, 72)


def test_histogram_is_numpy_histogram():
    from geoshade.core import histogram

    vol = synthetic_core(20, seed=3)
    h = histogram(vol, bins=32)
    a = np.asarray(vol.data)
    assert (h.vmin, h.vmax) == (float(a.min()), float(a.max()))
    want = np.histogram(a, bins=32, range=(a.min(), a.max() + 1))[0]
    assert np.array_equal(h.counts, want)
    f = synthetic_core(12, seed=1)
    f.data = f.data.astype(np.float32) / 7.0
    hf = histogram(f, bins=16)
    af = np.asarray(f.data)
    assert np.array_equal(hf.counts, np.histogram(af, bins=16, range=(af.min(), af.max()))[0])


def test_opening_prepares_on_a_thread_and_only_uploads(ctx):
    """prepare() (any thread) builds the first selection's maps; the View uploads them."""
    from concurrent.futures import ThreadPoolExecutor

    vol = synthetic_core(24, seed=4)
    with ThreadPoolExecutor(1) as pool:
        opening = pool.submit(prepare, vol, None, None, None, porosity="z").result()
    assert opening.cls.kind == "core" and "selection" in opening.prepared
    assert "histogram" in opening.prepared
    maps = opening.prepared["selection"].maps
    view = opening.cls(opening.model, size=SIZE, prepared=opening.prepared,
                       options=opening.options)
    try:
        assert view.maps is maps  # uploaded as prepared, not built again
        assert view.histogram() is opening.prepared["histogram"]
        assert view.porosity is not None
    finally:
        view.release()


def test_core_jobs_draw_what_coreview_draws(ctx):
    """The viewer builds maps off the GL thread and hands them over: same picture, same counts
    as a CoreView made with the same options."""
    from geoshade.core import CoreView

    vol = synthetic_core(32, seed=2)
    lo, hi = vol.meta["pore_range"]
    view = open_view(vol, size=SIZE, select=(lo, hi), annotations=False)
    run_now(view.jobs(select=(lo, hi - 2000), box=[4, 2, 0, 24, 28, 30]))
    cam = view.camera("iso")
    img, st = view.draw(cam)
    ref = CoreView(vol, select=(lo, hi - 2000), box=[4, 2, 0, 24, 28, 30], size=SIZE,
                   color=view.options.color)
    try:
        ref_img, ref_st = ref.draw(cam)
    finally:
        ref.release()
        view.release()
    assert np.array_equal(img, ref_img)
    assert st["voxels_selected"] == ref_st["voxels_selected"]
    a = np.asarray(vol.data)[0:30, 2:30, 4:28]
    assert st["voxels_selected"] == int(np.count_nonzero((a >= lo) & (a <= hi - 2000)))


def test_jobs_not_yet_applied_are_carried_into_the_next(ctx):
    """A selection job superseded before it is applied loses nothing: the next carries it."""
    vol = synthetic_core(24, seed=6)
    lo, hi = vol.meta["pore_range"]
    view = open_view(vol, size=SIZE, select=(lo, hi))
    try:
        first = view.jobs(select=(lo, hi - 1000))     # never applied (superseded)
        second = view.jobs(box=[0, 0, 0, 12, 24, 24])
        assert len(first) == len(second) == 1
        run_now(second)
        assert view.options.select == (lo, hi - 1000)
        assert view.options.box.size == (12, 24, 24)
        assert not view._pending
    finally:
        view.release()


@pytest.mark.parametrize("kind", ["core", "grid", "iso", "stacks"])
def test_session_interaction_changes_the_picture(ctx, kind, tmp_path):
    _cls, model, settings = demo_views()[kind]
    view = open_view(model, kind=kind, size=SIZE, **settings)
    s = Session(view, size=SIZE)
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
        if view.has_exaggeration:
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
        view.release()


def test_settings_errors_are_one_line(ctx):
    view = open_view(synthetic_core(16), size=SIZE)
    try:
        with pytest.raises(InputError, match="property: not an option of the core view"):
            view.jobs(property="PORO")
        with pytest.raises(InputError, match="method"):
            view.jobs(method="fastest")
    finally:
        view.release()
    with pytest.raises(InputError, match="nothing shows a ndarray"):
        open_view(np.zeros(3))


def test_key_table_names_every_view():
    from geoshade.styles.options import VIEWS

    assert set(KEY_VIEWS.values()) == set(VIEWS)
    assert {KEY_VIEWS[str(k)] for k in range(1, 8)} == set(VIEWS)
