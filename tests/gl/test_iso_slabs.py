"""The isosurface marched in slabs of slices (a View with the mesh cache: one small field
texture written by each march) draws and captures exactly what the whole-field march does."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.mesh import marching_cubes as mc
from geoshade.compute.mesh.displacement import displacement_field
from geoshade.iso import IsoView
from geoshade.models import FieldSeries
from geoshade.render.visuals.isosurface import visual as iso_visual

pytestmark = pytest.mark.gl

WHOLE = {"mesh_cache": False, "prefetch": False}   # two whole field textures, every frame


def _field(seed: int, outside: bool = False, prop: bool = False) -> FieldSeries:
    f = displacement_field((40, 30, 24), steps=3, seed=seed)
    if not outside and not prop:
        return f
    vals = np.stack([f.step(k) for k in range(3)])
    active = None
    if outside:
        vals[1, 5:9, 10:14, 20:26] = np.nan   # NaN nodes: an open surface there
        active = np.ones(vals.shape[1:], bool)
        active[:, :4, :] = False              # inactive nodes too
    props = {"P": vals * 100 + 7} if prop else {}
    return FieldSeries(vals, name="SWAT", active=active, properties=props)


@pytest.mark.parametrize("slab_bytes", [4 * 24 * 30 * 4, 4 * 24 * 30 * 9])
@pytest.mark.parametrize(("axis", "outside", "colour"), [("x", False, None), ("z", True, None),
                                                         ("y", False, "P")])
def test_slabs_draw_and_capture_what_the_whole_field_does(ctx, monkeypatch, slab_bytes, axis,
                                                          outside, colour):
    """Slabs of 1 and 6 cell slices (monkeypatched budget): the same captured triangles in the
    same order, the same picture, through a prepared-ahead step, a cold step and a level
    change; the field texture is the slab's size, not the field's."""
    f = _field(3, outside, colour is not None)
    kw = {"slice_axis": axis, "patch_level": 4, "color_by": colour, "size": (96, 72)}
    steps = [(1, 0.5), (2, 0.5), (0, 0.5), (0, 0.35)]
    want = []
    with IsoView(f, 0.5, step=1, ctx=ctx, **WHOLE, **kw) as ref:
        for k, level in steps:
            ref.update(step=k, level=level)
            img, st = ref.draw(frames=1, warn=False)
            want.append((img, st["triangles"], ref.visual.capture(level, ref._crange())))
    monkeypatch.setattr(iso_visual, "FIELD_SLAB_BYTES", slab_bytes)
    with IsoView(f, 0.5, step=1, ctx=ctx, **kw) as view:
        assert view.visual.slabbed
        for (k, level), (img0, n0, cap0) in zip(steps, want, strict=True):
            view.wait_prefetch()
            view.update(step=k, level=level)
            img, st = view.draw(frames=3, warn=False)
            assert st["triangles"] == n0 > 0
            assert np.array_equal(img, img0)
            cap = view.visual.capture(level, view._crange())
            assert np.array_equal(cap, cap0)   # every vertex, in the GPU's order
        sizes = {n: b for n, b in view.visual.cache.breakdown().items()
                 if n in ("field", "property")}
        s = mc.SLICE_AXES[axis][0]
        slab = min(f.shape[s], max(4, slab_bytes // (4 * f.nodes // f.shape[s])))  # + 3
        assert sizes["field"] == 4 * f.nodes // f.shape[s] * slab < 4 * f.nodes
        assert ("property" in sizes) == (colour is not None)


def test_step_switch_after_slabs_is_a_swap_of_captured_surfaces(ctx, monkeypatch):
    """The step prepared ahead is marched in slabs while the previous one is shown; the
    switch draws its captured triangles: the count the CPU reference gives."""
    monkeypatch.setattr(iso_visual, "FIELD_SLAB_BYTES", 4 * 30 * 40 * 5)
    f = _field(5)
    with IsoView(f, 0.5, step=0, size=(64, 48), ctx=ctx) as view:
        for k in (1, 2):
            view.draw(frames=2)
            view.wait_prefetch()
            view.update(step=k)
            _, st = view.draw(frames=1)
            assert st["prefetched"] and st["premarched"]
            assert st["triangles"] == mc.triangle_count(f.step(k), 0.5)
