"""Issue 30 ("the iso panel has no … keyword choice unless the server was started with one"): the
isosurface's quantity is a live control; ``update(keyword=X)`` draws what a View opened with
``keyword=X`` draws, pixel for pixel, on a corner-point grid, a field file read by
``load_field`` and a field given as arrays; what belonged to the old quantity (level, step,
diff) is assumed again unless given; a quantity the file lacks is one line."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.compute.mesh.displacement import displacement_field
from geoshade.errors import InputError
from geoshade.io.fields import load_field
from geoshade.viewer.controls import controls

pytestmark = pytest.mark.gl
SIZE = (200, 150)


def _keyword_choices(view):
    spec = [c for g in controls(view) for c in g["controls"] if c["name"] == "keyword"]
    return spec[0]["choices"] if spec else None


def _same(model, ctx, first: dict, then: dict, **kw):
    """update(**then) on a View opened with ``first`` == a View opened with both."""
    with geoshade.view(model, size=SIZE, ctx=ctx, as_="iso", **kw, **first) as v:
        v.draw()
        v.update(**then)
        img, st = v.draw()
    with geoshade.view(model, size=SIZE, ctx=ctx, as_="iso", **kw, **then) as w:
        ref, st_ref = w.draw()
    assert st["name"] == st_ref["name"] and st["level"] == st_ref["level"]
    assert st["step"] == st_ref["step"] and st["triangles"] == st_ref["triangles"]
    np.testing.assert_array_equal(img, ref)
    return st


def test_a_grid_shows_another_keyword(ctx):
    g = synthetic_grid(12, 10, 6)
    with geoshade.view(g, size=SIZE, ctx=ctx, as_="iso") as v:
        choices = _keyword_choices(v)
        assert choices[0] == "SWAT" and "PORO" in choices and "PRESSURE" not in choices[:1]
    st = _same(g, ctx, {}, {"keyword": "PORO"})
    assert st["nsteps"] == 1      # a static keyword: one step, the level assumed for it
    _same(g, ctx, {"keyword": "PORO"}, {"keyword": "SWAT"})
    _same(g, ctx, {"step": 0}, {"keyword": "PORO", "level": 0.2})


def test_a_file_is_read_again_with_the_keyword(ctx, tmp_path):
    f = displacement_field((24, 20, 16), steps=3, seed=1)
    path = tmp_path / "front.npz"
    np.savez(path, SWAT=np.asarray(f.values), PRESSURE=np.asarray(f.properties["PRESSURE"]))
    field = load_field(path, keyword="SWAT")
    with geoshade.view(field, size=SIZE, ctx=ctx) as v:
        assert _keyword_choices(v) == ["SWAT", "PRESSURE"]
        v.update(keyword="PRESSURE")
        img, st = v.draw()
    with geoshade.view(load_field(path, keyword="PRESSURE"), size=SIZE, ctx=ctx) as w:
        ref, st_ref = w.draw()
    assert st["name"] == "PRESSURE" and st["level"] == st_ref["level"]
    np.testing.assert_array_equal(img, ref)


def test_arrays_take_one_of_their_properties_and_refuse_others(ctx):
    f = displacement_field((24, 20, 16), steps=2, seed=2)
    with geoshade.view(f, size=SIZE, ctx=ctx) as v:
        before, _ = v.draw()
        with pytest.raises(InputError) as err:
            v.update(keyword="SGAS")
        assert "\n" not in str(err.value) and "PRESSURE" in str(err.value)
        again, _ = v.draw()          # refused: the view is as it was
        np.testing.assert_array_equal(before, again)
        v.update(keyword="PRESSURE")
        _, st = v.draw()
        pressure = np.asarray(f.properties["PRESSURE"][st["step"]], np.float64)
        assert st["name"] == "PRESSURE"
        assert st["value_range"] == pytest.approx([pressure.min(), pressure.max()], rel=1e-6)
