"""One suite over the four Views (core, grid, iso, stacks): what the shared View shape promises,
through the contract checks geoshade ships (:mod:`geoshade.testing.views`).

- framing depends on the model only: selection, filter, step and colour changes do not move it;
- the base stats keys, and the part's;
- an empty scene gives the one EmptySceneWarning (and ``stats["warning"]``);
- ``release()`` frees every GPU object the View made (and ``gpu_bytes`` is 0), ``with`` too;
- ``geoshade.view`` picks the part by the model's type, ``as_`` overrides it.
"""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.errors import InputError
from geoshade.testing.views import (
    RecordingContext,
    check_empty_scene,
    check_framing_fixed,
    check_release,
    check_stats_keys,
)

SIZE = (64, 48)
KINDS = ("core", "grid", "iso", "stacks")
PART_KEYS = {
    "core": {"voxels_selected", "voxels_drawn", "triangles", "box", "select", "color_range"},
    "grid": {"cells", "active_cells", "shown_cells", "faces", "faces_drawn", "property", "step",
             "step_label", "filter", "plane", "color_range", "exaggeration"},
    "iso": {"cells", "triangles", "level", "step", "step_label", "time", "nsteps",
            "cells_marched", "color_by", "exaggeration"},
    "stacks": {"columns", "intervals", "max_intervals", "mrays_per_s", "hidden", "plane",
               "exaggeration"},
}


def model_of(kind: str):
    if kind == "core":
        from geoshade.compute.voxels.synthetic import synthetic_core

        return synthetic_core(24, seed=1)
    if kind == "grid":
        from geoshade.compute.grid.synthetic import synthetic_grid

        return synthetic_grid(10, 8, 4, faults=True, seed=2)
    if kind == "iso":
        from geoshade.compute.mesh.displacement import displacement_field

        return displacement_field((24, 16, 16), steps=3, seed=0)
    from geoshade.compute.stacks import synthetic_layers

    return synthetic_layers(16, 12, 20, seed=0)


#: changes that keep the model and must keep the framing (selection, filter, step, colour)
CHANGES = {
    "core": [{"select": (0, 9000)}, {"select": (0, 30000)}, {"color_range": (0, 5000)},
             {"colormap": "magma"}],
    "grid": [{"filter": "PORO > 0.2"}, {"step": 0}, {"property": "PERMX"},
             {"colormap": "gray", "log": True}, {"slice": "k=1:3"}, {"plane": "1,0,0"}],
    "iso": [{"step": 0}, {"level": 0.3}, {"color_by": "PRESSURE"}, {"colormap": "magma"}],
    "stacks": [{"hide": [1]}, {"opacity": {2: 0.5}}, {"boreholes": True}, {"plane": "1,0,0"}],
}
#: options that leave nothing to draw
EMPTY = {
    "core": {"select": (65000, 65535)},
    "grid": {"filter": "PORO > 10"},
    "iso": {"level": 5.0},
    "stacks": {"hide": "ALL"},
}


def options_of(kind: str, model) -> dict:
    return {"level": 0.5} if kind == "iso" else {"property": "PORO"} if kind == "grid" else {}


def opener(kind: str, ctx):
    """``open_view(**more)``: the part's View of its model (the contract checks open it)."""
    model = model_of(kind)

    def open_view(**more):
        return geoshade.view(model, size=SIZE, **{"ctx": ctx, **options_of(kind, model),
                                                  **more})
    return open_view


@pytest.mark.parametrize("kind", KINDS)
def test_dispatch_by_model_type(ctx, kind):
    model = model_of(kind)
    assert geoshade.view_kind(model) == kind
    with geoshade.view(model, size=SIZE, ctx=ctx, **options_of(kind, model)) as v:
        assert v.kind == kind and type(v).__name__.lower().startswith(kind[:4])
        img, st = v.draw()
    assert img.shape == (SIZE[1], SIZE[0], 4) and st["kind"] == kind


@pytest.mark.parametrize("kind", KINDS)
def test_framing_does_not_move_with_selection_filter_step_or_colour(ctx, kind):
    check_framing_fixed(opener(kind, ctx), CHANGES[kind])


@pytest.mark.parametrize("kind", KINDS)
def test_stats_keys(ctx, kind):
    st = check_stats_keys(opener(kind, ctx), PART_KEYS[kind])
    assert st["width"] == SIZE[0]


@pytest.mark.parametrize("kind", KINDS)
def test_empty_scene_gives_the_one_warning(ctx, kind):
    empty = dict(EMPTY[kind])
    if empty.get("hide") == "ALL":
        empty["hide"] = [int(c) for c in model_of(kind).legend.codes]
    img, _ = check_empty_scene(opener(kind, ctx), empty)
    assert (img[..., :3] == 255).all()  # nothing drawn on the white background


@pytest.mark.parametrize("kind", KINDS)
def test_release_frees_every_gpu_object(ctx, kind):
    check_release(opener(kind, ctx), ctx, CHANGES[kind][0])   # a change makes new objects


def test_with_releases(ctx):
    rec = RecordingContext(ctx)
    with geoshade.view(model_of("core"), size=SIZE, ctx=rec) as v:
        v.draw()
    assert v.released and rec.alive() == []


def test_as_overrides_the_part(ctx):
    """A grid with report steps shown as the SWAT isosurface; a labelled volume as stacks."""
    from geoshade.compute.stacks import stacks_to_voxels
    from geoshade.models import VoxelVolume

    grid = model_of("grid")
    with geoshade.view(grid, as_="iso", keyword="swat", level=0.5, size=SIZE, ctx=ctx) as v:
        assert v.kind == "iso" and v.field.name == "SWAT" and v.nsteps == len(grid.steps)
        _, st = v.draw()
        assert st["step"] == len(grid.steps) - 1  # the last step, as in every part
    layers = model_of("stacks")
    vol = VoxelVolume(stacks_to_voxels(layers), meta={"legend": layers.legend})
    assert geoshade.view_kind(vol) == "stacks"
    with pytest.raises(InputError, match="the core view cannot show a StackModel"):
        geoshade.view(layers, as_="core")


def test_lower_case_filter_follows_the_step(ctx):
    """Regression: a filter naming a report-step property in lower case (``swat > 0.3``) is
    re-applied when the step changes (it was not: 0 cells shown where a fresh view shows 340)."""
    grid = model_of("grid")
    swat = [np.asarray(s["SWAT"]) for s in grid.steps]
    counts = [int(((s > 0.3) & grid.active).sum()) for s in swat]
    assert counts[1] != counts[2] and min(counts[1:]) > 0
    with geoshade.view(grid, property="PORO", filter="swat > 0.3", step=2, size=SIZE,
                       ctx=ctx) as v:
        v.update(step=1)          # static property, so only the filter depends on the step
        _, moved = v.draw()
    with geoshade.view(grid, property="PORO", filter="SWAT > 0.3", step=1, size=SIZE,
                       ctx=ctx) as fresh:
        _, want = fresh.draw()
    assert moved["shown_cells"] == want["shown_cells"] == counts[1]


@pytest.mark.parametrize("kind", KINDS)
def test_every_part_has_a_vertical_exaggeration(ctx, kind):
    """exaggeration stretches z in every part: the framed bounds are z-scaled, the picture
    changes, and the stats say it."""
    model = model_of(kind)
    opts = options_of(kind, model)
    with geoshade.view(model, size=SIZE, ctx=ctx, **opts) as v:
        assert v.has_exaggeration and v.exaggeration == opts.get("exaggeration", 1.0)
        b1 = v.bounds().copy()
        img1, _ = v.draw()
        v.set_exaggeration(3.0 * v.exaggeration)
        b3 = v.bounds()
        img3, st = v.draw()
    ratio = (b3[1, 2] - b3[0, 2]) / (b1[1, 2] - b1[0, 2])
    assert ratio == pytest.approx(3.0, rel=1e-6) and st["exaggeration"] == pytest.approx(
        3.0 * opts.get("exaggeration", 1.0))
    np.testing.assert_allclose(b3[:, :2], b1[:, :2])
    assert not np.array_equal(img1, img3)


def test_core_exaggeration_draws_what_taller_voxels_draw(ctx):
    """Exact oracle: exaggeration 2 over voxels 1 × 1 × 1 is the same world as voxels 1 × 1 × 2."""
    from geoshade.models import VoxelVolume

    data = np.asarray(model_of("core").data)
    tall = VoxelVolume(data, spacing=(1.0, 1.0, 2.0))
    with geoshade.view(VoxelVolume(data), size=SIZE, ctx=ctx, exaggeration=2.0) as v:
        cam = v.camera()
        img, _ = v.draw(cam)
    with geoshade.view(tall, size=SIZE, ctx=ctx) as ref:
        want, _ = ref.draw(cam)
    np.testing.assert_array_equal(img, want)
