"""Annotations on the Views: every part's picture carries its title, colour key and triad; the
overlay changes only the pixels it covers; automatic log for permeability, legends for classes,
a rock colour for a single selected value, the date on every frame of an animation."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

import geoshade
from geoshade.styles.annotate import annotate
from tests.gl.test_views_common import model_of, options_of

SIZE = (320, 240)
KEYS = {"core": "colorbar", "grid": "colorbar", "iso": "colorbar", "stacks": "legend"}


@pytest.mark.parametrize("kind", ["core", "grid", "iso", "stacks"])
def test_every_part_is_annotated_and_only_covered_pixels_change(ctx, kind):
    model = model_of(kind)
    opts = options_of(kind, model)
    if kind == "iso":
        opts["color_by"] = "PRESSURE"
    with geoshade.view(model, size=SIZE, ctx=ctx, annotations=True, **opts) as v:
        cam = v.camera()
        img, st = v.draw(cam)
        ann = v.annotations(cam, st, SIZE)
    with geoshade.view(model, size=SIZE, ctx=ctx, annotations=False, **opts) as bare:
        ref, st0 = bare.draw(cam)   # the same camera: the bare render of that framing
    lay = st["annotations"]
    assert lay["title"][0]["text"] and KEYS[kind] in lay and "triad" in lay
    assert {a["label"] for a in lay["triad"]["axes"]} == {"E", "N", "Up"}
    assert "annotations" not in st0
    over, _ = annotate(np.zeros_like(img), ann)
    free = over[..., 3] == 0
    assert 0.5 < free.mean() < 1
    np.testing.assert_array_equal(img[free], ref[free])


def test_framing_leaves_room_for_the_annotations(ctx):
    """The default camera of an annotated view frames the model into the free part of the
    picture: the colour bar and the title cover no model pixel."""
    grid = model_of("grid")
    with geoshade.view(grid, property="PORO", size=(640, 480), ctx=ctx, annotations=True,
                       background=(1, 1, 1)) as v:
        _img, st = v.draw()
        cam = v.camera()
    with geoshade.view(grid, property="PORO", size=(640, 480), ctx=ctx,
                       annotations=False) as bare:
        ref, _ = bare.draw(cam)
    model_px = (ref[..., :3] != 255).any(-1)
    x0, top, _bw, bh = st["annotations"]["colorbar"]["bbox"]
    assert not model_px[top:top + bh, x0 - 60:].any()
    assert not model_px[: st["annotations"]["font_px"] * 3].any()


def test_permeability_spanning_decades_is_log_automatically(ctx):
    g = model_of("grid")
    rng = np.random.default_rng(3)
    g.properties["PERMX"] = np.asfortranarray(10 ** rng.uniform(-2.5, 4, g.dims))
    with geoshade.view(g, property="permx", size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
        v.update(log=False)
        _, lin = v.draw()
    cb = st["annotations"]["colorbar"]
    assert st["log"] and st["log_auto"] and cb["log"] and cb["scale"] == "log scale (auto)"
    assert all(np.log10(t["value"]).is_integer() for t in cb["ticks"])
    assert cb["label"] == "PERMX [mD]"
    assert not lin["log"] and not lin["annotations"]["colorbar"]["log"]


def test_an_integer_class_property_gets_a_legend(ctx):
    g = model_of("grid")
    fip = np.ones(g.dims, np.int32)
    fip[: g.dims[0] // 2] = 2
    fip[:, :, -1] = 7
    g.properties["FIPNUM"] = np.asfortranarray(fip)
    with geoshade.view(g, property="FIPNUM", size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
    leg = st["annotations"]["legend"]
    assert leg["title"] == "FIPNUM" and [e["text"] for e in leg["entries"]] == ["1", "2", "7"]
    assert len({tuple(e["rgba"]) for e in leg["entries"]}) == 3


def test_a_single_selected_value_is_drawn_in_one_rock_colour(ctx):
    from geoshade.core.view import SOLID_ROCK
    from geoshade.models import VoxelVolume

    a = (np.random.default_rng(0).random((20, 20, 20)) > 0.7).astype(np.uint8)
    vol = VoxelVolume(a, name="seg.raw")
    with geoshade.view(vol, select=(1, 1), size=SIZE, ctx=ctx, annotations=True) as v:
        _img, st = v.draw()
        pal = v.palette
    from matplotlib.colors import to_rgba

    want = np.rint(np.asarray(to_rgba(SOLID_ROCK)) * 255).astype(np.uint8)
    assert (pal == want).all()
    assert st["annotations"]["legend"]["entries"][0]["text"] == "value 1"
    assert "values 1 selected" in st["annotations"]["title"][0]["text"]


def test_every_animation_frame_carries_its_date(ctx, tmp_path):
    from geoshade.iso import animate
    from geoshade.models import FieldSeries

    f = model_of("iso")
    dates = ["2001-01-01", "2001-02-01", "2001-03-01"]
    f = FieldSeries(f.values, spacing=f.spacing, name="SWAT", times=dates,
                    properties=f.properties)
    res = animate(f, 0.5, tmp_path / "a.gif", size=SIZE, fps=2, ctx=ctx, annotations=True)
    subtitles = [t[1] for t in res["titles"]]
    assert [s.split(" · ")[-1] for s in subtitles] == dates
    assert [s.split(" · ")[0] for s in subtitles] == [f"step {k} of 3" for k in range(3)]
    gif = Image.open(tmp_path / "a.gif")
    frames = []
    for k in range(3):
        gif.seek(k)
        frames.append(np.asarray(gif.convert("RGB")))
    band = slice(0, 40)
    assert not np.array_equal(frames[0][band], frames[1][band])   # the title line changes


@pytest.mark.gl
@pytest.mark.parametrize("flag", [[], ["--no-annotations"]])
def test_cli_pictures_are_annotated_unless_asked(capsys, tmp_path, flag):
    from geoshade.cli.main import main
    from geoshade.io.grids.grdecl_writer import write_grdecl

    path = tmp_path / "g.grdecl"
    write_grdecl(model_of("grid"), path)
    out, stats = tmp_path / "o.png", tmp_path / "s.json"
    rc = main(["grid", "render", str(path), "--property", "PORO", "--size", "320x240",
               "--frames", "1", "-o", str(out), "--stats", str(stats), *flag])
    assert rc == 0, capsys.readouterr().err
    st = json.loads(stats.read_text())
    assert ("annotations" in st) == (not flag)
    if not flag:
        assert st["annotations"]["colorbar"]["label"] == "PORO [fraction]"


def test_cells_without_a_value_get_the_nan_colour(ctx):
    """NaN cells are not painted with the lowest colour: the palette's last entry is the NaN
    colour, the colour bar shows it as 'no value'."""
    from geoshade.styles.options import NAN_COLOR

    g = model_of("grid")
    poro = np.asarray(g.properties["PORO"], float).copy()
    poro[0, :, :] = np.nan
    g.properties["PORO"] = np.asfortranarray(poro)
    with geoshade.view(g, property="PORO", size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
        (ci, cells), pal = v.colour_indices, v.palette  # the drawn cells' colour indices
    i = (cells if cells is not None else np.arange(g.ncells)) % g.dims[0]
    want = np.rint(np.asarray(NAN_COLOR) * 255).astype(np.uint8)
    assert (i == 0).any() and (ci[i == 0] == 255).all() and (ci[i != 0] < 255).all()
    assert (pal[255] == want).all()
    assert st["no_value_cells"] == int(g.active[0].sum())
    assert st["annotations"]["colorbar"]["nan"] is not None
    with geoshade.view(g, property="PORO", size=SIZE, ctx=ctx, nan_color="red") as v:
        v.draw()
        assert tuple(v.palette[255]) == (255, 0, 0, 255)


def test_soil_is_derived_where_the_case_has_none(ctx):
    """SOIL = 1 - SWAT (- SGAS) for colouring and filters, at every step."""
    g = model_of("grid")
    assert "SOIL" not in g.property_names()
    swat = np.asarray(g.steps[1]["SWAT"], float)
    with geoshade.view(g, property="soil", step=1, filter="SOIL > 0.5", size=SIZE, ctx=ctx,
                       annotations=True) as v:
        _, st = v.draw()
        np.testing.assert_allclose(v.values("SOIL", 1), 1 - swat)
    assert st["property"] == "SOIL"
    assert st["shown_cells"] == int(((1 - swat) > 0.5)[g.active].sum())
    assert st["annotations"]["colorbar"]["label"] == "SOIL [fraction]"


def test_a_thumbnail_is_drawn_bare_and_says_why(ctx):
    model = model_of("grid")
    with geoshade.view(model, size=(96, 64), ctx=ctx, annotations=True,
                       **options_of("grid", model)) as v:
        assert v.viewport() is None
        img, st = v.draw()
    with geoshade.view(model, size=(96, 64), ctx=ctx, annotations=False,
                       **options_of("grid", model)) as bare:
        ref, _ = bare.draw()
    assert "too small" in st["annotations"]["skipped"]
    np.testing.assert_array_equal(img, ref)


def _keys(stats: dict) -> set[str]:
    lay = stats["annotations"]
    assert lay["title"][0]["text"] and "triad" in lay, lay
    return {k for k in ("colorbar", "legend") if k in lay}


@pytest.mark.gl
def test_every_render_command_and_the_demo_are_annotated_by_default(capsys, tmp_path,
                                                                     monkeypatch):
    """core/grid/iso/stacks render and every demo picture: title, triad and a colour key."""
    import geoshade.styles.options as options
    from geoshade.cli.main import main

    monkeypatch.setattr(options, "ANNOTATIONS_DEFAULT", True)   # the default outside tests
    from geoshade.io.grids.grdecl_writer import write_grdecl
    from geoshade.io.layers.stackfile import write_stacks
    from geoshade.stacks.view import StacksView

    core = tmp_path / "core.npy"
    np.save(core, np.asarray(model_of("core").data))
    grid = write_grdecl(model_of("grid"), tmp_path / "g.grdecl")
    iso = model_of("iso")
    field = tmp_path / "f.npz"
    np.savez(field, SWAT=np.stack([np.asarray(iso.step(k)) for k in range(3)]),
             PRESSURE=np.stack([iso.property_step("PRESSURE", k) for k in range(3)]))
    stacks = write_stacks(tmp_path / "s.stacks.npz", StacksView.demo()[0])
    runs = {"core": (["core", "render", core], "colorbar"),
            "grid": (["grid", "render", grid, "--property", "PORO"], "colorbar"),
            "iso": (["iso", "render", field, "--level", "0.5", "--keyword", "SWAT",
                     "--color-by", "PRESSURE"],
                    "colorbar"),
            "stacks": (["stacks", "render", stacks], "legend")}
    for name, (argv, key) in runs.items():
        js = tmp_path / f"{name}.json"
        rc = main([str(a) for a in argv] + ["--size", "640x480", "-o",
                                            str(tmp_path / f"{name}.png"), "--stats", str(js)])
        assert rc == 0, (name, capsys.readouterr().err)
        assert _keys(json.loads(js.read_text())) == {key}, name
    assert main(["demo", "-o", str(tmp_path / "demo"), "--voxels", "24", "--size",
                 "320x240"]) == 0
    seen = 0
    for js in (tmp_path / "demo").glob("*stats.json"):
        for name, st in json.loads(js.read_text()).items():
            if isinstance(st, dict) and "width" in st:
                assert _keys(st), (js.name, name)
                seen += 1
    assert seen >= 10


def test_an_index_space_grid_says_so(ctx):
    """A deck without geometry is drawn in unit cells: the title says so, the triad is I/J/K
    and the scale bar counts cells."""
    g = model_of("grid")
    g.meta["index_space"] = True
    with geoshade.view(g, property="PORO", size=(640, 480), ctx=ctx, annotations=True,
                       view="top", ortho=True) as v:
        _, st = v.draw()
    lay = st["annotations"]
    assert lay["title"][0]["text"].startswith("synthetic 10x8x4 (IJK index space)")
    assert {a["label"] for a in lay["triad"]["axes"]} == {"I", "J", "K"}
    assert lay["scalebar"]["text"].endswith("cells")


def test_the_unit_system_the_deck_declares_labels_the_bar(ctx):
    g = model_of("grid")
    g.meta["unit_system"] = "LAB"
    with geoshade.view(g, property="SWAT", size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
    assert st["annotations"]["colorbar"]["label"] == "SWAT [fraction]"
    g.properties["PRESSURE"] = np.full(g.dims, 200.0, order="F")
    with geoshade.view(g, property="PRESSURE", size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
    assert st["annotations"]["colorbar"]["label"] == "PRESSURE [atm]"


def test_a_static_isosurface_has_no_time_line(ctx):
    g = model_of("grid")
    with geoshade.view(g, as_="iso", keyword="PORO", level=0.2, size=SIZE, ctx=ctx,
                       annotations=True) as v:
        _, st = v.draw()
    texts = [t["text"] for t in st["annotations"]["title"]]
    assert texts[0].endswith("PORO = 0.2") and all("step" not in t for t in texts)



def test_a_ct_colour_bar_says_grey_value(ctx):
    with geoshade.view(model_of("core"), select=(0, 30000), size=SIZE, ctx=ctx,
                       annotations=True) as v:
        _, st = v.draw()
    assert st["annotations"]["colorbar"]["label"] == "grey value"
