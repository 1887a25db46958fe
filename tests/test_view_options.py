"""Typed view options, parsed once, checked before any GL context exists (no GL needed here).

Each bad option of each part is refused with one clear line while OpenGL is unavailable: the
context factory is made to fail the test if anything asks for a context.
"""

from __future__ import annotations

import datetime

import numpy as np
import pytest

import geoshade
from geoshade.errors import GeoshadeDeprecationWarning, InputError
from geoshade.models.steps import resolve_step, step_label
from geoshade.styles.options import CameraSpec, ColorStyle, Plane


@pytest.fixture
def no_gl(monkeypatch):
    """Any request for an OpenGL context fails the test (and GEOSHADE_GL=off besides)."""
    import geoshade.render.context as context

    def refuse(*a, **kw):
        raise AssertionError("a View asked for an OpenGL context before checking its options")

    monkeypatch.setenv("GEOSHADE_GL", "off")
    monkeypatch.setattr(context, "get_context", refuse)
    monkeypatch.setattr(context, "create_context", refuse)


def _models():
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.compute.mesh.displacement import displacement_field
    from geoshade.compute.stacks import synthetic_layers
    from geoshade.compute.voxels.synthetic import synthetic_core

    return {"core": synthetic_core(16, seed=1), "grid": synthetic_grid(6, 5, 3, seed=1),
            "iso": displacement_field((16, 12, 12), steps=3), "stacks": synthetic_layers(8, 6, 10)}


BAD = [
    ("core", {"select": (2000, 1000)}, "select: lo 2000 > hi 1000"),
    ("core", {"select": (0, 70000)}, "outside uint16"),
    ("core", {"box": [10, 0, 0, 10, 4, 4]}, "outside the volume"),
    ("core", {"method": "fastest"}, "method: expected one of auto, raycast"),
    ("core", {"log": True}, "log colour scale is not available for voxel volumes"),
    ("core", {"bricks": -3}, "bricks: expected"),
    ("core", {"selct": (0, 1)}, "selct: not an option of the core view"),
    ("grid", {"property": "NOPE"}, "property: unknown name 'NOPE'"),
    ("grid", {"step": 9}, "step 9 does not exist; there are 4 steps"),
    ("grid", {"step": "R7"}, "the steps have no report numbers"),
    ("grid", {"filter": "PORO >"}, "not a valid expression"),
    ("grid", {"filter": "FOO > 1"}, "unknown property 'FOO'"),
    ("grid", {"slice": "i=4:2"}, "slice"),
    ("grid", {"plane": "0,0,0,1"}, "plane: the normal must not be zero"),
    ("grid", {"clip_plane": "1,2"}, "clip: expected NX,NY,NZ,D"),
    ("grid", {"exaggeration": 0}, "exaggeration: expected a positive number"),
    ("grid", {"approach": 4}, "approach: expected one of 1, 2, 3, got 4"),
    ("grid", {"colormap": "nosuchmap"}, "colormap: unknown colour map 'nosuchmap'"),
    ("grid", {"color_range": (5, 1)}, "color range: expected finite LO <= HI"),
    ("grid", {"log": True, "color_range": (0, 10)}, "log colour scale needs LO > 0"),
    ("iso", {"level": "half"}, "level: expected a number"),
    ("iso", {"step": "2001-01-01"}, "no step has that date"),
    ("iso", {"color_by": "SOIL"}, "color_by: unknown name 'SOIL'"),
    ("iso", {"patch_level": 65}, "patch_level: expected an integer 1..64"),
    ("iso", {"slice_axis": "w"}, "slice_axis: expected one of auto, z, y, x"),
    ("stacks", {"layout": "voxels"}, "layout: expected one of"),
    ("stacks", {"hide": [4242]}, "hide: unknown material code 4242"),
    ("stacks", {"opacity": {1: 2}}, "opacity: code 1: expected a number 0..1"),
    ("stacks", {"plane": "1,0,0,1e6"}, "misses the model"),
    ("stacks", {"section": "1,0"}, "section: expected 4 numbers"),
    ("stacks", {"drape": "no/such.png"}, "cannot read image: no such file"),
    ("core", {"size": "12xq"}, "size: expected WIDTHxHEIGHT"),
    ("core", {"view": "sideways"}, "view: unknown view 'sideways'"),
    ("iso", {"elevation": 100}, "elevation: expected -90..90"),
    ("stacks", {"zoom": -1}, "zoom: expected a positive number"),
]


@pytest.mark.filterwarnings("ignore::geoshade.errors.GeoshadeDeprecationWarning")
@pytest.mark.parametrize(("kind", "options", "message"), BAD,
                         ids=[f"{k}-{next(iter(o))}" for k, o, _ in BAD])
def test_bad_options_are_refused_before_any_gl_context(no_gl, kind, options, message):
    model = _models()[kind]
    with pytest.raises(InputError) as err:
        geoshade.view(model, **options)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_view_of_something_else(no_gl):
    with pytest.raises(InputError, match="nothing shows a list"):
        geoshade.view([1, 2, 3])
    with pytest.raises(InputError, match="as: unknown part 'mesh'"):
        geoshade.view(_models()["core"], as_="mesh")


def test_deprecated_names_still_work_with_a_warning(no_gl):
    from geoshade.core import CoreOptions
    from geoshade.iso import IsoOptions
    from geoshade.stacks import StacksOptions

    m = _models()
    with pytest.warns(GeoshadeDeprecationWarning, match="range is deprecated: use select"):
        o = CoreOptions.parse(m["core"], range=(0, 9000))
    assert o.select == (0.0, 9000.0)
    with pytest.warns(GeoshadeDeprecationWarning, match="z_scale is deprecated: use "
                      "exaggeration"):
        assert IsoOptions.parse(m["iso"], z_scale=3).exaggeration == 3.0
    with pytest.warns(GeoshadeDeprecationWarning, match="section is deprecated: use plane"):
        p = StacksOptions.parse(m["stacks"], section="1,0,0,4").plane
    assert p.normal == (-1.0, 0.0, 0.0) and p.offset == -4.0   # keeps x <= 4 (cut x > 4)
    with pytest.raises(InputError, match=r"give either range \(deprecated\) or select"):
        CoreOptions.parse(m["core"], range=(0, 1), select=(0, 2))


def test_names_are_case_insensitive(no_gl):
    from geoshade.grid import GridOptions
    from geoshade.iso import IsoOptions

    m = _models()
    o = GridOptions.parse(m["grid"], property="poro", filter="permx > 100 and Poro < 0.3")
    assert o.property == "PORO" and o.filter.resolve(m["grid"].property_names()) == {
        "permx": "PERMX", "Poro": "PORO"}
    assert IsoOptions.parse(m["iso"], color_by="pressure").color_by == "PRESSURE"


def test_the_same_step_forms_and_default_in_every_part(no_gl):
    from geoshade.grid import GridOptions
    from geoshade.iso import IsoOptions

    m = _models()
    g, f = m["grid"], m["iso"]
    assert GridOptions.parse(g).step == len(g.steps) - 1          # default: the last step
    assert IsoOptions.parse(f).step == f.nsteps - 1
    assert GridOptions.parse(g, step=-1).step == len(g.steps) - 1
    assert GridOptions.parse(g, step="1").step == IsoOptions.parse(f, step="1").step == 1
    date = g.step_dates[2]
    assert GridOptions.parse(g, step=date).step == 2
    assert GridOptions.parse(g, step=datetime.date.fromisoformat(date)).step == 2


def test_resolve_step_forms():
    dates, reports = ["2000-01-01", "2000-02-01", "2000-03-01"], [0, 10, 20]
    assert resolve_step(None, 3) == 2 and resolve_step(-3, 3) == 0 and resolve_step("last", 3) == 2
    assert resolve_step("R10", 3, reports=reports) == resolve_step("report:10", 3,
                                                                     reports=reports) == 1
    assert resolve_step("2000-3-1", 3, dates=dates) == 2
    for bad, msg in ((3, "step 3 does not exist"), ("R5", "no report step has number 5"),
                     ("1999-01-01", "no step has that date"), ("soon", "is not a step"),
                     (True, "expected an index")):
        with pytest.raises(InputError, match=msg):
            resolve_step(bad, 3, dates=dates, reports=reports)
    assert step_label(2, dates, reports) == "step 2 (report 20, 2000-03-01)"


def test_plane_has_one_meaning():
    p = Plane.parse("2,0,0,10")               # 2x >= 10: x >= 5 is kept
    assert p.normal == (1.0, 0.0, 0.0) and p.offset == 5.0
    assert p.keeps([[4.9, 0, 0], [5, 0, 0], [6, 9, 9]]).tolist() == [False, True, True]
    through = Plane.parse("0,0,-1").resolve([0, 0, 7])  # through the centre, keep below
    assert through.keeps([[0, 0, 6], [0, 0, 8]]).tolist() == [True, False]
    assert Plane.parse("1,0,0,5").crosses([[0, 0, 0], [10, 1, 1]])
    assert not Plane.parse("1,0,0,50").crosses([[0, 0, 0], [10, 1, 1]])
    for bad in ("1,2", "a,b,c", "0,0,0"):
        with pytest.raises(InputError, match="plane"):
            Plane.parse(bad)


def test_color_style_and_camera_spec():
    c = ColorStyle.parse("viridis_r", log=True, range=(1, 1000))
    assert c.reverse and c.colormap == "viridis"
    assert c.transformed_range(1, 1000) == (0.0, 3.0)
    assert np.allclose(c.transform([10, 100, -1]), [1, 2, np.nan], equal_nan=True)
    solid = ColorStyle.parse(solid="tan").palette_rgba()
    assert (solid == solid[0]).all() and tuple(solid[0][:3]) == (210, 180, 140)
    spec = CameraSpec.parse("top", zoom=2, ortho=True)
    assert (spec.view, spec.zoom, spec.ortho, spec.angles()) == ("top", 2.0, True, (0.0, 90.0))
    assert CameraSpec.parse(spec, azimuth=30).angles() == (30.0, 90.0)


def test_load_as_field_and_dispatch(tmp_path, no_gl):
    a = np.random.default_rng(0).random((2, 5, 6, 7)).astype(np.float32)
    np.save(tmp_path / "s.npy", a)
    np.save(tmp_path / "v.npy", a[0])
    assert type(geoshade.load(tmp_path / "v.npy")).__name__ == "VoxelVolume"
    f = geoshade.load(tmp_path / "v.npy", as_="field")
    assert type(f).__name__ == "FieldSeries" and f.nsteps == 1
    fs = geoshade.load(tmp_path / "s.npy")
    assert fs.nsteps == 2 and geoshade.view_kind(fs) == "iso"
    with pytest.raises(InputError, match="not a grid model"):
        geoshade.load(tmp_path / "v.npy", as_="grid")
