"""Pictures say what changes their meaning (issue 24, item 4): the vertical exaggeration in every
part's subtitle when it is not 1; the report step only for what changes with it; an iso
animation's colour range over all its steps; a terrain coloured by elevation with a height
colour bar, and picks on it that say elevation."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid

SIZE = (320, 240)


def _subtitle(st) -> str:
    lines = [t["text"] for t in st["annotations"].get("title", [])]
    return "\n".join(lines[1:])


def _hills(nx=60, ny=40):
    y, x = np.mgrid[0:ny, 0:nx]
    return 50 + 30 * np.sin(x / 9) * np.cos(y / 11) + 0.3 * x


def _terrain():
    from geoshade.stacks.terrain import from_surfaces

    return from_surfaces([_hills()], spacing=(25.0, 25.0), origin=(1000.0, 2000.0),
                         name="hills.tif")


def _models():
    from geoshade.compute.mesh.displacement import displacement_field
    from geoshade.models import VoxelVolume

    vol = VoxelVolume(np.random.default_rng(0).integers(0, 255, (24, 24, 24)).astype(np.uint8))
    return {
        "grid": (synthetic_grid(8, 6, 3, seed=1), {"property": "PORO"}),
        "iso": (displacement_field((24, 16, 16), steps=3), {"level": 0.5}),
        "core": (vol, {"select": (0, 100)}),
        "stacks": (_terrain(), {}),
    }


@pytest.mark.parametrize("part", ["grid", "iso", "core", "stacks"])
def test_exaggeration_is_said_when_not_one(ctx, part):
    model, opts = _models()[part]
    subs = {}
    for ex in (1.0, 5.0):
        with geoshade.view(model, size=SIZE, ctx=ctx, annotations=True, exaggeration=ex,
                           **opts) as v:
            _, st = v.draw()
            subs[ex] = _subtitle(st)
    assert "exaggeration" not in subs[1.0]
    assert "vertical exaggeration ×5" in subs[5.0]


def test_the_step_is_shown_only_for_dynamic_properties(ctx):
    g = synthetic_grid(8, 6, 3, seed=1)
    assert g.steps
    with geoshade.view(g, property="PORO", step=-1, size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
        assert "step" not in _subtitle(st)
        v.update(property="SWAT")
        _, st = v.draw()
        assert _subtitle(st).startswith(f"step {len(g.steps) - 1} of {len(g.steps)}")
        v.update(property="PORO", filter="SWAT > 0.2")   # a filter over a dynamic property
        _, st = v.draw()
        assert "step" in _subtitle(st)


@pytest.mark.data
def test_reek_static_permx_has_no_step_for_the_property(ctx, shared_data):
    egrid = shared_data / "reek_cornerpoint/opm_flow_run/2_R001_REEK-0.EGRID"
    if not egrid.exists():
        pytest.skip(f"{egrid} is absent")
    grid = geoshade.load(egrid)
    with geoshade.view(grid, property="PERMX", size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
    sub = _subtitle(st)
    assert not sub.startswith("step"), sub           # at most "wells at step ..."
    assert st["annotations"]["colorbar"]["label"] == "PERMX [mD]"


def test_iso_animation_colour_range_spans_every_step(ctx, tmp_path):
    """A property that grows step by step: one colour range over every frame (it was the
    first step's, so later frames were one flat colour), or the one given."""
    from geoshade.compute.mesh.displacement import displacement_field
    from geoshade.iso.tasks import animate
    from geoshade.models import FieldSeries

    base = displacement_field((24, 16, 16), steps=4, seed=1)
    n = int(np.prod(base.shape))
    ramp = np.linspace(0.0, 1.0, n, dtype=np.float32).reshape(base.shape)
    p = [100.0 * k + 10.0 * ramp for k in range(base.nsteps)]
    f = FieldSeries([base.step(k) for k in range(base.nsteps)], name="SWAT",
                    properties={"P": p})
    res = animate(f, 0.5, tmp_path / "a.gif", size=SIZE, fps=2, ctx=ctx, color_by="P")
    assert res["color_range"] == pytest.approx([0.0, 100.0 * (base.nsteps - 1) + 10.0])
    given = animate(f, 0.5, tmp_path / "b.gif", size=SIZE, fps=2, ctx=ctx, color_by="P",
                    color_range=(0.0, 1.0))
    assert given["color_range"] == [0.0, 1.0]
    # the frames of the first animation differ in colour from step to step
    from PIL import Image, ImageSequence

    frames = [np.asarray(fr.convert("RGB")) for fr in
              ImageSequence.Iterator(Image.open(tmp_path / "a.gif"))]
    assert len(frames) == base.nsteps
    assert not np.array_equal(frames[1], frames[-1])


def test_terrain_is_coloured_by_elevation_and_picks_say_elevation(ctx):
    from geoshade.stacks.terrain import elevation_colours

    m = _terrain()
    top = _hills()
    ec = elevation_colours(m)
    assert ec is not None
    with geoshade.view(m, size=(480, 360), ctx=ctx, annotations=True, view="top", ortho=True,
                       lighting=False) as v:
        img, st = v.draw()
        cb = st["annotations"]["colorbar"]
        assert cb["label"] == "elevation [m]" and "legend" not in st["annotations"]
        assert cb["lo"] == pytest.approx(float(top.min()), abs=1e-3)
        assert cb["hi"] == pytest.approx(float(top.max()), abs=1e-3)
        h, w = img.shape[:2]
        checked = 0
        colours = set()
        for px in range(w // 5, 3 * w // 5, 23):
            for py in range(h // 4, 3 * h // 4, 19):
                p = v.pick(px + 0.5, py + 0.5)
                if p is None:
                    continue
                cx, cy, _ = p.index
                assert p.name == "elevation" and p.unit == "m" and p.vertical == "elevation"
                assert "depth" not in p.text()
                # the smooth top lies between the heights of the neighbouring columns
                near = top[max(cy - 1, 0): cy + 2, max(cx - 1, 0): cx + 2]
                assert near.min() - 1e-3 <= p.value <= near.max() + 1e-3
                band = ec.band[cx + m.shape[0] * cy]
                want = ec.levels[band, :3]
                got = img[py, px, :3]
                if np.abs(got.astype(int) - want).max() <= 1:
                    checked += 1
                colours.add(tuple(int(c) for c in got))
        assert checked >= 20
        assert len(colours) >= 8           # many heights, many colours (not one flat brown)
