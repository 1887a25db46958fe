"""Categorical properties (issue 24, item 3): integer codes and region/facies keywords get one
qualitative colour and one legend entry per code; the picture's colours are the legend's
(sampled pixel by pixel on an unlit picture); ``categorical`` overrides; many codes are capped;
the legend is never clipped at the picture's edge."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.styles.annotate import Annotations, Legend, annotate
from geoshade.styles.categories import MAX_ENTRIES, categorical_palette

UNLIT = {"light_dir": (0.0, 0.0, 1.0), "material": (1.0, 0.0, 0.0, 1.0)}
SIZE = (480, 360)


def _grid(ncodes=5, seed=4, name="FACIES", dtype=np.int32):
    g = synthetic_grid(12, 10, 3, seed=seed)
    rng = np.random.default_rng(seed)
    codes = np.arange(ncodes) * 3 + 1   # uneven values: 1, 4, 7 ...
    g.properties[name] = codes[rng.integers(0, ncodes, g.dims)].astype(dtype)
    return g


def _model_colours(img, legend_bbox=None) -> np.ndarray:
    """(n, 3) RGB of the pixels the model covers (the background and the annotations'
    corners left out)."""
    h, w = img.shape[:2]
    keep = np.any(img[..., :3] != img[0, 0, :3], axis=-1)
    keep[: h // 8] = False                  # the title
    keep[:, : w // 6] = False               # the triad
    if legend_bbox is not None:
        x, y, _bw, bh = legend_bbox
        keep[max(0, y - 2): y + bh + 2, max(0, x - 2):] = False
    return img[keep][:, :3]


def _check_picture_matches_legend(img, st, codes_present):
    leg = st["annotations"]["legend"]
    legend_rgb = {tuple(e["rgba"][:3]) for e in leg["entries"] if e["rgba"][3]}
    px = _model_colours(img, leg["bbox"])
    assert len(px) > 500
    keys, counts = np.unique(px, axis=0, return_counts=True)
    in_legend = np.array([tuple(k) in legend_rgb for k in keys.tolist()])
    # every colour of the picture is a legend swatch (but antialiased outline pixels)
    assert counts[in_legend].sum() >= 0.97 * counts.sum()
    seen = {tuple(k) for k in keys[in_legend].tolist()}
    assert len(seen) >= max(2, int(0.8 * len(codes_present)))


def test_grid_codes_get_a_legend_in_the_pictures_colours(ctx):
    g = _grid()
    codes = np.unique(g.properties["FACIES"][g.active])
    with geoshade.view(g, property="FACIES", size=SIZE, ctx=ctx, annotations=True,
                       view="top", ortho=True) as v:
        v.shading = dict(UNLIT)
        img, st = v.draw()
    leg = st["annotations"]["legend"]
    assert "colorbar" not in st["annotations"]
    assert [e["text"] for e in leg["entries"]] == [str(int(c)) for c in codes]
    pal = categorical_palette(codes)
    assert [tuple(e["rgba"]) for e in leg["entries"]] == [pal.rgba_of(c) for c in codes]
    assert len({tuple(e["rgba"]) for e in leg["entries"]}) == codes.size
    _check_picture_matches_legend(img, st, codes)


def test_grid_keyword_float_codes_and_the_overrides(ctx):
    """SATNUM stored as floats is categorical by name; --continuous gives a colour bar; a
    float PORO with --categorical gets one entry per value."""
    g = _grid(name="SATNUM", dtype=np.float32)
    with geoshade.view(g, property="satnum", size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
        assert len(st["annotations"]["legend"]["entries"]) == 5
        v.update(color=dict(categorical=False))
        _, st = v.draw()
        assert "legend" not in st["annotations"] and st["annotations"]["colorbar"]
    g.properties["PORO"] = np.round(g.properties["PORO"] * 10) / 10
    with geoshade.view(g, property="PORO", size=SIZE, ctx=ctx, annotations=True,
                       color=dict(categorical=True)) as v:
        _, st = v.draw()
    want = np.unique(g.properties["PORO"][g.active])
    assert len(st["annotations"]["legend"]["entries"]) == want.size


def test_many_codes_are_capped_and_names_come_from_the_file(ctx):
    g = _grid(ncodes=40)
    with geoshade.view(g, property="FACIES", size=SIZE, ctx=ctx, annotations=True,
                       view="top", ortho=True) as v:
        v.shading = dict(UNLIT)
        img, st = v.draw()
    entries = st["annotations"]["legend"]["entries"]
    assert len(entries) == MAX_ENTRIES
    assert entries[-1]["text"] == f"+{40 - MAX_ENTRIES + 1} more"
    px = _model_colours(img, st["annotations"]["legend"]["bbox"])
    assert len(np.unique(px, axis=0)) >= 30   # 40 codes, 40 distinct colours drawn
    g = _grid(ncodes=3)
    g.meta["codes"] = {"FACIES": {1: "sand", 4: "shale", 7: "coal"}}
    with geoshade.view(g, property="FACIES", size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
    assert [e["text"] for e in st["annotations"]["legend"]["entries"]] == \
        ["1 sand", "4 shale", "7 coal"]


def test_iso_coloured_by_codes(ctx):
    g = synthetic_grid(14, 12, 4, seed=5)
    with geoshade.view(g, as_="iso", keyword="SWAT", level=0.5, color_by="FIPNUM", size=SIZE,
                       ctx=ctx, annotations=True, view="top", ortho=True) as v:
        v.shading = dict(UNLIT)
        img, st = v.draw()
        codes = np.unique(g.properties["FIPNUM"][g.active])
        leg = st["annotations"]["legend"]
        assert [e["text"] for e in leg["entries"]] == [str(int(c)) for c in codes]
        _check_picture_matches_legend(img, st, codes)
        v.update(color=dict(categorical=False))
        _, st = v.draw()
        assert st["annotations"]["colorbar"]["label"] == "FIPNUM"


@pytest.mark.parametrize("title", ["REGIONS", "A VERY LONG REGION TITLE"])
def test_legend_title_is_never_clipped(title):
    w, h = 320, 240
    leg = Legend(title, (("1", (255, 0, 0, 255)), ("2", (0, 0, 255, 255))))
    img, layout = annotate(np.zeros((h, w, 4), np.uint8), Annotations(legend=leg))
    x, _y, bw, _bh = layout["legend"]["bbox"]
    margin = max(4, round(0.8 * layout["font_px"]))
    assert x >= 0 and x + bw <= w - margin
    # nothing of the title (halo included) reaches the picture's last columns
    assert img[:, : w - margin // 2, 3].any() and not img[:, w - margin // 2:, 3].any()


@pytest.mark.gl
def test_cli_categorical_and_continuous(tmp_path, capsys):
    import json

    from geoshade.io.grids.grdecl_writer import write_grdecl
    from tests.corruption import run_cli

    g = _grid()
    path = tmp_path / "g.grdecl"
    write_grdecl(g, path)
    got = {}
    for flag in ("", "--continuous", "--categorical"):
        stats = tmp_path / f"s{flag}.json"
        prop = "PORO" if flag == "--categorical" else "FACIES"
        rc, _out, err = run_cli(capsys, ["grid", "render", path, "--property", prop,
                                         *([flag] if flag else []), "-o", tmp_path / "o.png",
                                         "--size", "320x240", "--stats", stats])
        assert rc == 0, err
        got[flag] = json.loads(stats.read_text())["annotations"]
    assert len(got[""]["legend"]["entries"]) == 5 and "colorbar" not in got[""]
    assert "legend" not in got["--continuous"] and got["--continuous"]["colorbar"]
    assert "legend" in got["--categorical"]


def test_roff_undefined_code_is_no_value_not_a_class(ctx):
    """ROFF's -999 in active cells: no legend entry of its own, drawn in the no-value colour
    (the legend's "no value" swatch), never in the colour of the lowest code."""
    g = _grid(ncodes=3)
    g.meta["format"] = "ROFF"
    f = g.properties["FACIES"]
    f[:6, :, :] = -999                       # a block of cells with no value, on top too
    with geoshade.view(g, property="FACIES", size=SIZE, ctx=ctx, annotations=True,
                       view="top", ortho=True) as v:
        v.shading = dict(UNLIT)
        img, st = v.draw()
    leg = st["annotations"]["legend"]
    assert [e["text"] for e in leg["entries"]] == ["1", "4", "7"]
    nan_rgb = tuple(leg["nan"]["rgba"][:3])
    assert leg["nan"]["text"] == "no value" and st["no_value_cells"] == int(
        (f[g.active] == -999).sum())
    px = _model_colours(img, leg["bbox"])
    keys = {tuple(k) for k in np.unique(px, axis=0).tolist()}
    assert nan_rgb in keys
    assert nan_rgb not in {tuple(e["rgba"][:3]) for e in leg["entries"]}


def test_iso_never_blends_two_codes_into_a_third(ctx):
    """A surface across a boundary between codes 1 and 7 (code 4 lies elsewhere): no pixel
    takes code 4's colour (an interpolated 1..7 would), and picks read real codes."""
    from geoshade.models import FieldSeries

    nz, ny, nx = 12, 16, 20
    z, y, x = np.mgrid[0:nz, 0:ny, 0:nx].astype(np.float32)
    swat = x / (nx - 1)                                   # the surface: the plane x = mid
    codes = np.where(y + 0.3 * z < ny / 2, 1, 7).astype(np.int32)
    codes[:, :, :2] = 4                                   # code 4 only far from the surface
    f = FieldSeries(swat, name="SWAT", properties={"FACIES": codes})
    with geoshade.view(f, level=0.5, color_by="FACIES", size=SIZE, ctx=ctx, annotations=True,
                       view="right", ortho=True) as v:
        v.shading = dict(UNLIT)
        img, st = v.draw()
        leg = st["annotations"]["legend"]
        rgb = {e["text"]: tuple(e["rgba"][:3]) for e in leg["entries"]}
        assert list(rgb) == ["1", "4", "7"]
        px = _model_colours(img, leg["bbox"])
        keys, counts = np.unique(px, axis=0, return_counts=True)
        found = {tuple(k): int(c) for k, c in zip(keys.tolist(), counts, strict=True)}
        assert found.get(rgb["1"], 0) > 100 and found.get(rgb["7"], 0) > 100
        assert found.get(rgb["4"], 0) == 0
        h, w = img.shape[:2]
        values = set()
        for px_, py_ in ((w // 2 + dx, h // 2 + dy) for dx in range(-40, 41, 8)
                         for dy in range(-40, 41, 8)):
            p = v.pick(px_, py_)
            if p is not None:
                values.add(p.value)
        assert values and values <= {1.0, 7.0}


def test_grid_pick_names_the_class(ctx):
    g = _grid(ncodes=3)
    g.meta["codes"] = {"FACIES": {1: "sand", 4: "shale", 7: "coal"}}
    names = g.meta["codes"]["FACIES"]
    with geoshade.view(g, property="FACIES", size=SIZE, ctx=ctx, view="top", ortho=True) as v:
        v.draw()
        w, h = SIZE
        picks = [v.pick(w / 2 + dx, h / 2 + dy) for dx in (-30, 0, 30) for dy in (-20, 0, 20)]
    picks = [p for p in picks if p is not None]
    assert len(picks) >= 5
    for p in picks:
        i, j, k = p.index
        code = int(g.properties["FACIES"][i, j, k])
        assert p.value == code and dict(p.extra)["class"] == names[code]
        assert f"class {names[code]}" in p.text()


def test_more_codes_than_colours_is_said(ctx):
    g = synthetic_grid(30, 30, 2, seed=1)
    g.properties["FIPNUM"] = (np.arange(g.ncells).reshape(g.dims, order="F") % 400
                              ).astype(np.int32)
    with geoshade.view(g, property="FIPNUM", size=SIZE, ctx=ctx) as v:
        _, st = v.draw()
    assert len(st["categories"]) == 400
    assert any("share a colour" in n for n in st["notes"])
