"""Acceptance: a national survey's voxel model in netCDF drawn where its file places it (issue 31,
items 2 and 5).

Cases:

- GeoTOP v1.6 (TNO) around Utrecht Science Park, read in place from ../shared/data/geotop_usp
  (Deltares geost, LGPL-3.0; TNO open data): its probability of fine sand ``kans_5`` as it ships
  (x, y, z in m NAP), and made from it at test time the two ways survey files store such a model:
  top-down, with a ``depth`` coordinate ``positive="down"`` beside a layer index, its layers kept
  at uneven steps (0.5–3 m); and the nine probabilities as one variable over a ``lithoclass``
  dimension (a dimension that is not time). Oracle: xarray (the nodes' coordinates and values).
- OPM Flow's SPE1 with hourly non-unified restarts (tests/acceptance/ecl_cases.py): iso opened on
  ``HOURLY.X0012`` shows report 12. Oracle: resfo (the file's SWAT).
- The committed SPE1 deck cut to one layer: iso points to grid render.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from tests.acceptance import ecl_cases
from tests.acceptance.conftest import title_text
from tests.acceptance.make_cases import CaseUnavailableError

xr = pytest.importorskip("xarray")
pytest.importorskip("netCDF4")

#: the isosurface: 50 % probability of fine sand (kans_5 is in per cent)
LEVEL = 50.0
pytestmark = pytest.mark.data  # reads ../shared/data
#: layers kept in the top-down copy: every 6th near the base, every 2nd, then all (0.5–3 m)
KEEP = np.unique(np.concatenate([np.arange(0, 60, 6), np.arange(60, 200, 2),
                                 np.arange(200, 313)]))


@pytest.fixture(scope="module")
def geotop(shared):
    return shared / "geotop_usp" / "geotop_usp.nc"


@pytest.fixture(scope="module")
def topdown(geotop, tmp_path_factory):
    """kans_5 stored top-down: depth below 106.5 m NAP, positive down, uneven layers."""
    with xr.open_dataset(geotop) as ds:
        sub = ds["kans_5"].isel(z=KEEP).transpose("z", "y", "x").load()
        x, y, z = (ds[c].values.astype(float) for c in ("x", "y", "z"))
    depth = 106.5 - z[KEEP]
    out = tmp_path_factory.mktemp("fields") / "geotop_topdown.nc"
    xr.Dataset({"kans_5": (("layer", "y", "x"), sub.values[::-1])},
               coords={"layer": np.arange(1, KEEP.size + 1),
                       "x": ("x", x, {"units": "m"}), "y": ("y", y, {"units": "m"}),
                       "depth": ("layer", depth[::-1], {"units": "m", "positive": "down"})}
               ).to_netcdf(out)
    return out


@pytest.fixture(scope="module")
def by_class(geotop, tmp_path_factory):
    """The nine probabilities as kans(lithoclass, x, y, z)."""
    out = tmp_path_factory.mktemp("fields") / "geotop_kans.nc"
    with xr.open_dataset(geotop) as ds:
        kans = xr.concat([ds[f"kans_{i}"] for i in range(1, 10)], dim="lithoclass")
        xr.Dataset({"kans": kans.assign_coords(lithoclass=np.arange(1, 10))}).to_netcdf(out)
    return out


def _vertices_on_edges(mesh, axes, values, level: float) -> int:
    """Check that every vertex lies on an edge between two nodes (at the file's coordinates)
    where the values, interpolated linearly along that edge, equal ``level``; the count."""
    xs, ys, zs = axes
    checked = 0
    for v in mesh.vertices:
        idx, frac = [], []
        for c, q in zip((xs, ys, zs), v, strict=True):
            k = int(np.clip(np.searchsorted(c, q) - 1, 0, c.size - 2))
            t = (q - c[k]) / (c[k + 1] - c[k])
            if abs(t) < 1e-4 or abs(t - 1) < 1e-4:
                idx.append(k + round(t))
                frac.append(None)
            else:
                idx.append(k)
                frac.append(t)
        moving = [a for a, f in enumerate(frac) if f is not None]
        if len(moving) != 1:     # a vertex on a node: its value is the level
            assert np.isclose(values[idx[2], idx[1], idx[0]], level, atol=1e-3)
            continue
        a = moving[0]
        i0 = list(idx)
        i1 = list(idx)
        i1[a] += 1
        v0, v1 = values[i0[2], i0[1], i0[0]], values[i1[2], i1[1], i1[0]]
        # float32 positions on the GPU: a few 1e-4 of the edge
        tol = 1e-3 * abs(float(v1) - float(v0)) + 1e-5
        assert v0 + frac[a] * (v1 - v0) == pytest.approx(level, abs=tol), (v, v0, v1)
        checked += 1
    return checked


def test_geotop_as_it_ships_is_placed_by_its_coordinates(geotop):
    from geoshade.io.fields import load_field

    f = load_field(geotop, keyword="kans_5")
    with xr.open_dataset(geotop) as ds:
        for axis, c in zip("xyz", f.axes(), strict=True):
            np.testing.assert_allclose(c, ds[axis].values.astype(float))
        np.testing.assert_array_equal(f.step(0), ds["kans_5"].transpose("z", "y", "x").values)
    assert f.length_unit == "m" and not f.is_rectilinear
    assert not any("positive" in n for n in f.meta.get("notes", []))  # positive="up" kept


@pytest.mark.gl
def test_top_down_uneven_copy_is_drawn_where_its_depths_are(cli, geotop, topdown):
    import geoshade
    from geoshade.io.fields import load_field

    f = load_field(topdown)
    with xr.open_dataset(geotop) as ds:
        z_nap = ds["z"].values.astype(float)[KEEP]
        np.testing.assert_allclose(f.axes()[2], z_nap - 106.5)     # z up, in the file's order
        want = ds["kans_5"].transpose("z", "y", "x").values[KEEP]
    np.testing.assert_array_equal(f.step(0), want)
    assert f.is_rectilinear
    with geoshade.view(f, level=LEVEL, size=(320, 240)) as v:
        v.draw()
        mesh = v.mesh()
    assert mesh.n_faces > 1000
    assert _vertices_on_edges(mesh, f.axes(), want, LEVEL) > 0.9 * mesh.n_vertices
    st = cli.render("geotop_topdown_iso", "iso", "render", topdown, "--level", str(LEVEL),
                    "--exaggeration", "10", "--size", "800x600")
    assert st["nodes"] == "rectilinear"
    assert any('positive="down"' in n for n in st["notes"])
    assert "z = −depth" in title_text(st)
    ref = cli.render("geotop_asships_iso", "iso", "render", geotop, "--keyword", "kans_5",
                     "--level", str(LEVEL), "--exaggeration", "10", "--size", "800x600")
    assert ref["nodes"] == "regular"


@pytest.mark.gl
def test_pick_on_the_top_down_copy_names_an_elevation(topdown):
    import geoshade

    with geoshade.view(topdown, as_="iso", level=LEVEL, exaggeration=10, size=(320, 240),
                       annotations=False) as v:
        img, _ = v.draw()
        ys, xs = np.nonzero(np.abs(img[..., :3].astype(int) - img[0, 0, :3]).sum(-1) > 30)
        picks = [v.pick(float(x), float(y)) for x, y in zip(xs[::97], ys[::97], strict=True)]
    picks = [p for p in picks if p is not None]
    assert len(picks) > 5
    for p in picks:
        assert p.vertical == "elevation" and "elevation" in p.text()
        assert -156.5 <= p.world[2] <= 0.0      # inside the model's depths, z up


def test_a_lithoclass_dimension_is_never_time(cli, by_class, geotop):
    rc, _, err = cli("iso", "render", by_class, "--level", str(LEVEL), "-o",
                     cli.tmp / "never.png")
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert "'lithoclass' (9 values: 1, 2, 3" in err and "kans[lithoclass=5]" in err
    from geoshade.io.fields import load_field

    f = load_field(by_class, keyword="kans[lithoclass=5]")
    with xr.open_dataset(geotop) as ds:
        np.testing.assert_array_equal(f.step(0), ds["kans_5"].transpose("z", "y", "x").values)
    assert f.nsteps == 1 and "lithoclass = 5" in f.meta["notes"]


@pytest.mark.gl
def test_a_chosen_lithoclass_is_said_on_the_picture(cli, by_class):
    st = cli.render("geotop_kans5_iso", "iso", "render", by_class, "--keyword",
                    "kans[lithoclass=5]", "--level", str(LEVEL), "--exaggeration", "10",
                    "--size", "800x600")
    assert "lithoclass = 5" in title_text(st) and st["nsteps"] == 1


@pytest.fixture(scope="module")
def lithok_topdown(geotop, tmp_path_factory):
    """lithok stored like ``topdown`` (a depth positive down beside a layer index, uneven)."""
    with xr.open_dataset(geotop) as ds:
        sub = ds["lithok"].isel(z=KEEP).transpose("z", "y", "x").values
        x, y, z = (ds[c].values.astype(float) for c in ("x", "y", "z"))
    out = tmp_path_factory.mktemp("fields") / "geotop_lithok_topdown.nc"
    xr.Dataset({"lithok": (("layer", "y", "x"), sub[::-1])},
               coords={"layer": np.arange(1, KEEP.size + 1),
                       "x": ("x", x, {"units": "m"}), "y": ("y", y, {"units": "m"}),
                       "depth": ("layer", (106.5 - z[KEEP])[::-1],
                                 {"units": "m", "positive": "down"})}).to_netcdf(out)
    return out, sub, z[KEEP]


def test_stacks_keep_the_uneven_layers_at_their_heights(lithok_topdown):
    """Each column's intervals start where numpy finds the lithoclass changing over the kept
    layers, at their edges halfway between the layers' centres (said as assumed)."""
    from geoshade.stacks import convert

    path, labels, z_nap = lithok_topdown
    m = convert(path, boreholes=None)
    zc = z_nap - 106.5                              # the copy's z: −depth below 106.5 m NAP
    mid = (zc[1:] + zc[:-1]) / 2
    edges = np.concatenate([[2 * zc[0] - mid[0]], mid, [2 * zc[-1] - mid[-1]]])
    z = lambda lv: m.origin[2] + float(lv) * m.spacing[2]   # noqa: E731
    assert z(0) == pytest.approx(edges[0]) and z(m.nlevels) == pytest.approx(edges[-1])
    assert any("assumed" in n for n in m.meta["notes"])
    nx = labels.shape[2]
    for c in range(m.ncols):
        j, i = divmod(c, nx)
        col = np.where(np.isnan(labels[:, j, i]), -1, labels[:, j, i]).astype(int)
        starts = [0, *(np.flatnonzero(np.diff(col)) + 1)]
        want = [(edges[k], col[k]) for k in starts]
        if want and want[0][1] == -1:
            want = want[1:]                        # no leading empty interval
        a, b = m.offsets[c], m.offsets[c + 1]
        got = [(z(s), k) for s, k in zip(m.starts[a:b], m.codes[a:b], strict=True)]
        assert [k for _, k in got] == [k for _, k in want], c
        np.testing.assert_allclose([g for g, _ in got], [w for w, _ in want], atol=1e-3)


@pytest.mark.gl
def test_stacks_render_of_the_top_down_copy(cli, lithok_topdown):
    path = lithok_topdown[0]
    st = cli.render("geotop_lithok_topdown_stacks", "stacks", "render", path, "--logs", "none",
                    "--exaggeration", "20", "--size", "800x600")
    assert "kept at their heights" in title_text(st) or any(
        "kept at their heights" in n for n in st.get("notes", []))


# --- item 5: a non-unified restart's own step; a one-layer case ------------------------------
@pytest.fixture(scope="module")
def hourly():
    try:
        return ecl_cases.spe1_hourly()
    except CaseUnavailableError as err:
        pytest.skip(str(err))


@pytest.mark.gl
def test_iso_on_a_non_unified_file_shows_its_own_report(cli, hourly):
    resfo = pytest.importorskip("resfo")
    x12 = hourly.with_name("HOURLY.X0012")
    st = cli.render("hourly_x0012_iso", "iso", "render", x12, "--keyword", "SWAT",
                    "--size", "640x480")
    assert st["step"] == 12 and "report 12" in st["step_label"], st["step_label"]
    assert re.search(r"report 12\b", title_text(st)), title_text(st)
    from geoshade.io.fields import load_field

    f = load_field(x12, keyword="SWAT")
    swat = next(e.read_array() for e in resfo.lazy_read(str(x12))
                if e.read_keyword().strip() == "SWAT")
    np.testing.assert_allclose(f.step(12).ravel(), np.asarray(swat, np.float32))
    last = cli.render("hourly_last_iso", "iso", "render", hourly, "--keyword", "SWAT",
                      "--size", "640x480")
    assert last["step"] == f.nsteps - 1


def _one_layer(real, tmp_path):
    src = (real / "opm_spe1_field" / "SPE1CASE1.DATA").read_text()
    for old, new in (("   10 10 3 /", "   10 10 1 /"), ("300*1000", "100*1000"),
                     ("100*20 100*30 100*50", "100*20"), ("300*0.3", "100*0.3"),
                     ("100*500 100*50 100*200", "100*500")):
        assert old in src, old
        src = src.replace(old, new)
    src = src[:src.index("SCHEDULE")] + "SCHEDULE\nEND\n"
    deck = tmp_path / "ONE.DATA"
    deck.write_text(src)
    return deck


@pytest.mark.gl
def test_iso_on_one_layer_points_to_grid_render(cli, real, tmp_path):
    deck = _one_layer(real, tmp_path)
    rc, _, err = cli("iso", "render", deck, "--keyword", "PORO", "-o", tmp_path / "i.png")
    errors = [line for line in err.splitlines() if line.startswith("geoshade: error")]
    assert rc == 2 and len(errors) == 1, err
    assert "10×10×1 cells" in err and "geoshade grid render" in err
    st = cli.render("one_layer_grid", "grid", "render", deck, "--size", "480x360")
    assert st["faces_drawn"] is None or st["faces_drawn"] >= 0


def test_info_describes_a_field_as_iso_reads_it(cli, geotop, topdown, by_class):
    """``geoshade info FILE --keyword NAME``: the nodes, where the file's coordinates place
    them (z up; xarray's), the steps (a lithoclass dimension is selected, never time), the
    values of the step shown (numpy's over xarray's arrays)."""
    import json

    rc, out, err = cli("info", topdown, "--keyword", "kans_5", "--json")
    assert rc == 0, err
    d = json.loads(out)
    with xr.open_dataset(geotop) as ds:
        z_nap = ds["z"].values.astype(float)[KEEP]
        want = ds["kans_5"].transpose("z", "y", "x").values[KEEP]
        x = ds["x"].values.astype(float)
    assert d["kind"] == "field" and d["placement"] == "the file's coordinates (uneven)"
    assert d["nodes_xyz"] == [x.size, want.shape[1], KEEP.size] and d["steps"] == 1
    assert d["z"] == pytest.approx([z_nap.min() - 106.5, z_nap.max() - 106.5])
    assert d["x"] == pytest.approx([x.min(), x.max()])
    assert any('positive="down"' in n for n in d["notes"])
    assert d["min"] == pytest.approx(float(np.nanmin(want)))
    assert d["max"] == pytest.approx(float(np.nanmax(want)))
    assert d["nan_count"] == int(np.isnan(want).sum())
    rc, text, err = cli("info", by_class, "--keyword", "kans[lithoclass=5]")
    assert rc == 0, err
    assert "steps    1 (no dates)" in text and "lithoclass = 5" in text, text
    rc, _, err = cli("info", by_class, "--keyword", "kans")
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "'lithoclass'" in err, err
