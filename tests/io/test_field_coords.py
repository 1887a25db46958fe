"""A netCDF or zarr field placed by its own coordinates (issue 31, item 2).

Each file is small and made here to reproduce one way real files place their nodes: layers stored
top-down with a positive-down depth of uneven thickness, a dim named ``depth``, decreasing x and y,
kilometres beside metres, longitudes and latitudes, CF bounds only, no coordinate at all, a
``percentile`` dimension that is not time, time told by ``axis="T"`` or ``units "... since"``.
The oracle is xarray: the values at each node and its coordinates as the file holds them.
"""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io.fields import load_field
from geoshade.models.field import FieldSeries

xr = pytest.importorskip("xarray")
pytest.importorskip("netCDF4")

#: layer thicknesses of a survey's voxel model stored top-down: 2 m at the top, 200 m at depth
THICK = np.array([2.0, 4.0, 10.0, 24.0, 60.0, 150.0, 200.0])
CENTRES = np.concatenate([[0.0], np.cumsum(THICK)[:-1]]) + THICK / 2
X = np.arange(0.0, 1000.0, 100.0)
Y = np.arange(0.0, 800.0, 100.0)


def _kh() -> np.ndarray:
    """(layer, y, x) values linear in the true depth and x: kh = depth + 0.1 x."""
    d, _, x = np.meshgrid(CENTRES, Y, X, indexing="ij")
    return (d + 0.1 * x).astype(np.float32)


def _topdown(path, positive="down", depth_name="depth", **extra):
    attrs = {"units": "m"} if positive is None else {"units": "m", "positive": positive}
    ds = xr.Dataset({"kh": (("layer", "y", "x"), _kh(), {"units": "m/d"})},
                    coords={"layer": np.arange(1, len(THICK) + 1),
                            "x": ("x", X, {"units": "m"}), "y": ("y", Y, {"units": "m"}),
                            depth_name: ("layer", CENTRES, attrs), **extra})
    ds.to_netcdf(path)
    return path


def test_top_down_layers_are_placed_at_their_depth_up_is_up(tmp_path):
    f = load_field(_topdown(tmp_path / "m.nc"))
    ds = xr.open_dataset(tmp_path / "m.nc")
    x, _, z = f.axes()
    assert f.is_rectilinear and f.length_unit == "m" and f.unit == "m/d"
    np.testing.assert_array_equal(z, -ds["depth"].values[::-1])       # deepest first, z up
    np.testing.assert_array_equal(x, ds["x"].values)
    np.testing.assert_array_equal(f.step(0), ds["kh"].values[::-1])   # layer order follows z
    assert f.bounds().tolist() == [[0.0, 0.0, -CENTRES[-1]], [900.0, 700.0, -CENTRES[0]]]
    assert any('positive="down"' in n for n in f.meta["notes"])
    assert any("uneven" in n or "apart" in n for n in f.meta["notes"])
    assert "uneven" in repr(f)


def test_depth_without_positive_is_down_by_its_name(tmp_path):
    f = load_field(_topdown(tmp_path / "m.nc", positive=None))
    np.testing.assert_array_equal(f.axes()[2], -CENTRES[::-1])
    assert any("its name" in n for n in f.meta["notes"])


def test_positive_up_height_is_kept(tmp_path):
    f = load_field(_topdown(tmp_path / "m.nc", positive="up", depth_name="height"))
    np.testing.assert_array_equal(f.axes()[2], CENTRES)
    np.testing.assert_array_equal(f.step(0), _kh())


def test_an_index_coordinate_is_not_a_position(tmp_path):
    """The layer index (1..7) is never taken as z when the file has a depth."""
    f = load_field(_topdown(tmp_path / "m.nc"))
    assert f.meta["axes"]["z"] == {"dim": "layer", "coordinate": "depth", "flipped": True}
    assert not np.array_equal(f.axes()[2], np.arange(1, 8))


def test_decreasing_x_and_y_are_flipped_as_xarray_sorts(tmp_path):
    data = np.random.default_rng(1).random((4, 5, 6)).astype(np.float32)
    ds = xr.Dataset({"v": (("z", "y", "x"), data)},
                    coords={"x": 600.0 - 100 * np.arange(6), "y": 50.0 - 10 * np.arange(5),
                            "z": [-30.0, -20.0, -10.0, 0.0]})
    ds.to_netcdf(tmp_path / "d.nc")
    f = load_field(tmp_path / "d.nc")
    s = xr.open_dataset(tmp_path / "d.nc").sortby(["x", "y", "z"])
    assert not f.is_rectilinear   # evenly spaced after the flip: a regular grid
    np.testing.assert_array_equal(f.step(0), s["v"].values)
    assert f.origin == (100.0, 10.0, -30.0) and f.spacing == (100.0, 10.0, 10.0)


def test_kilometres_beside_metres_become_metres(tmp_path):
    ds = xr.Dataset({"v": (("z", "y", "x"), np.zeros((3, 2, 2), np.float32))},
                    coords={"x": ("x", [0.0, 1.5], {"units": "km"}),
                            "y": ("y", [0.0, 2.0], {"units": "km"}),
                            "z": ("z", [-300.0, -200.0, -100.0], {"units": "m"})})
    ds.to_netcdf(tmp_path / "k.nc")
    f = load_field(tmp_path / "k.nc")
    assert f.length_unit == "m" and f.bounds().tolist() == [[0, 0, -300], [1500, 2000, -100]]
    assert any("converted to m" in n for n in f.meta["notes"])


def test_degrees_are_drawn_in_metres_and_said(tmp_path):
    ds = xr.Dataset({"t": (("depth", "lat", "lon"), np.zeros((3, 4, 5), np.float32))},
                    coords={"lon": ("lon", 5.0 + 0.1 * np.arange(5), {"units": "degrees_east"}),
                            "lat": ("lat", 52.0 + 0.1 * np.arange(4),
                                    {"units": "degrees_north"}),
                            "depth": ("depth", [5.0, 15.0, 40.0], {"units": "m",
                                                                   "positive": "down"})})
    ds.to_netcdf(tmp_path / "o.nc")
    f = load_field(tmp_path / "o.nc")
    x, y, z = f.axes()
    lat0 = np.radians(52.15)
    assert x[-1] - x[0] == pytest.approx(0.4 * 6371008.8 * np.pi / 180 * np.cos(lat0))
    assert y[-1] - y[0] == pytest.approx(0.3 * 6371008.8 * np.pi / 180)
    assert z.tolist() == [-40.0, -15.0, -5.0] and f.length_unit == "m"
    assert any("degrees" in n for n in f.meta["notes"])


def test_cf_bounds_give_the_centres(tmp_path):
    edges = np.concatenate([[0.0], np.cumsum(THICK)])
    bnds = np.stack([edges[:-1], edges[1:]], axis=1)
    ds = xr.Dataset({"kh": (("depth", "y", "x"), _kh()),
                     "depth_bnds": (("depth", "nv"), bnds)},
                    coords={"x": X, "y": Y})
    ds.to_netcdf(tmp_path / "b.nc")
    f = load_field(tmp_path / "b.nc", keyword="kh")
    np.testing.assert_allclose(f.axes()[2], -CENTRES[::-1])


def test_no_coordinate_is_an_index_said_so(tmp_path):
    ds = xr.Dataset({"v": (("a", "b", "c"), np.zeros((2, 3, 4), np.float32))})
    ds.to_netcdf(tmp_path / "n.nc")
    f = load_field(tmp_path / "n.nc")
    assert f.shape == (2, 3, 4) and f.spacing == (1.0, 1.0, 1.0)
    assert sum("no coordinate" in n and "assumed" in n for n in f.meta["notes"]) == 3


def _percentiles(path):
    pk = np.stack([_kh() * 0.5, _kh(), _kh() * 2])
    xr.Dataset({"kh": (("percentile", "layer", "y", "x"), pk)},
               coords={"percentile": [10, 50, 75], "layer": np.arange(1, 8), "x": X, "y": Y,
                       "depth": ("layer", CENTRES, {"positive": "down", "units": "m"})}
               ).to_netcdf(path)
    return path


def test_a_percentile_dimension_is_never_time(tmp_path):
    p = _percentiles(tmp_path / "p.nc")
    with pytest.raises(InputError) as err:
        load_field(p)
    msg = str(err.value)
    assert "'percentile' (3 values: 10, 50, 75)" in msg and "neither time" in msg
    assert "--keyword 'kh[percentile=50]'" in msg and "\n" not in msg
    ds = xr.open_dataset(p)
    for key in ("kh[percentile=50]", "kh[percentile=p50]", "KH[Percentile=50]"):
        f = load_field(p, keyword=key)
        assert f.nsteps == 1 and f.times == ["step 0"]
        np.testing.assert_array_equal(f.step(0), ds["kh"].sel(percentile=50).values[::-1])
        assert f.meta["selected"] == {"percentile": 50} and "percentile = 50" in f.meta["notes"]
    with pytest.raises(InputError, match=r"no such percentile; it has 10, 50, 75"):
        load_field(p, keyword="kh[percentile=90]")
    with pytest.raises(InputError, match=r"has no dim 'member'"):
        load_field(p, keyword="kh[member=1]")


def test_a_leading_dim_without_time_marks_is_refused(tmp_path):
    """The old reader took any 4th dim as time; now only one the file calls time is."""
    ds = xr.Dataset({"v": (("realization", "z", "y", "x"), np.zeros((4, 2, 2, 2)))})
    ds.to_netcdf(tmp_path / "r.nc")
    with pytest.raises(InputError, match=r"dim 'realization' \(4 values: 0, 1, 2, 3\).*"
                                         r"realization=2"):
        load_field(tmp_path / "r.nc")
    f = load_field(tmp_path / "r.nc", keyword="v[realization=2]")
    assert f.nsteps == 1


@pytest.mark.parametrize("how", ["axis", "since", "dates", "name"])
def test_time_is_what_the_file_calls_time(tmp_path, how):
    data = np.arange(3 * 2 * 2 * 2, dtype=np.float32).reshape(3, 2, 2, 2)
    dim = {"axis": "tt", "since": "tt", "dates": "tt", "name": "time"}[how]
    attrs = {"axis": {"axis": "T"}, "since": {"units": "days since 2000-01-01"},
             "dates": {}, "name": {}}[how]
    values = (np.array(["2000-01-01", "2000-01-02", "2000-01-03T06:00"], "datetime64[ns]")
              if how == "dates" else np.array([0.0, 1.0, 2.25]))
    ds = xr.Dataset({"v": ((dim, "z", "y", "x"), data)},
                    coords={dim: (dim, values, attrs), "z": [0.0, 1.0]})
    ds.to_netcdf(tmp_path / "t.nc")
    f = load_field(tmp_path / "t.nc")
    assert f.nsteps == 3 and f.meta["time_dim"] == dim
    np.testing.assert_array_equal(f.step(2), data[2])
    if how in ("since", "dates"):
        assert f.times[2] == "2000-01-03 06:00" and f.times[0] == "2000-01-01 00:00"


def test_a_one_value_dimension_is_dropped(tmp_path):
    ds = xr.Dataset({"v": (("band", "z", "y", "x"), np.ones((1, 2, 2, 2)))})
    ds.to_netcdf(tmp_path / "one.nc")
    f = load_field(tmp_path / "one.nc")
    assert f.nsteps == 1 and f.shape == (2, 2, 2)


def test_colour_by_a_variable_on_the_same_nodes(tmp_path):
    ds = xr.Dataset({"kh": (("layer", "y", "x"), _kh()), "kv": (("layer", "y", "x"), 2 * _kh())},
                    coords={"x": X, "y": Y, "layer": np.arange(7),
                            "depth": ("layer", CENTRES, {"positive": "down"})})
    ds.to_netcdf(tmp_path / "c.nc")
    f = load_field(tmp_path / "c.nc", keyword="kh", color_by="kv")
    np.testing.assert_array_equal(f.property_step("kv", 0), 2 * _kh()[::-1])


@pytest.mark.filterwarnings("ignore:Consolidated metadata")
def test_an_xarray_zarr_store_is_placed_like_netcdf(tmp_path):
    pytest.importorskip("zarr")
    _topdown(tmp_path / "m.nc")
    xr.open_dataset(tmp_path / "m.nc").to_zarr(tmp_path / "m.zarr")
    a, b = load_field(tmp_path / "m.nc"), load_field(tmp_path / "m.zarr")
    assert b.meta["format"] == "zarr" and b.is_rectilinear
    for u, v in zip(a.axes(), b.axes(), strict=True):
        np.testing.assert_array_equal(u, v)
    np.testing.assert_array_equal(a.step(0), b.step(0))


def test_given_spacing_wins_and_says_so(tmp_path):
    f = load_field(_topdown(tmp_path / "m.nc"), spacing=(100, 100, 10))
    assert not f.is_rectilinear and f.spacing == (100.0, 100.0, 10.0)
    assert any("spacing given" in n for n in f.meta["notes"])


def test_rectilinear_exports_keep_the_nodes(tmp_path):
    f = load_field(_topdown(tmp_path / "m.nc"))
    da = f.to_xarray()
    np.testing.assert_array_equal(da["z"].values, f.axes()[2])
    pv = pytest.importorskip("pyvista")
    g = f.to_pyvista()
    assert isinstance(g, pv.RectilinearGrid)
    np.testing.assert_array_equal(g.z, f.axes()[2])
    np.testing.assert_array_equal(g.point_data["kh"], f.step(0).ravel())


def test_coords_contract():
    with pytest.raises(InputError, match="z is not strictly increasing"):
        FieldSeries(np.zeros((3, 2, 2)), coords=([0, 1], [0, 1], [0, 2, 1]))
    with pytest.raises(InputError, match="x has 3 values for 2 nodes"):
        FieldSeries(np.zeros((3, 2, 2)), coords=([0, 1, 2], [0, 1], [0, 2, 3]))
    even = FieldSeries(np.zeros((3, 2, 2)), coords=([0, 5], [0, 1], [0, 2, 4]))
    assert even.coords is None and even.spacing == (5.0, 1.0, 2.0)
    with pytest.raises(InputError, match="not evenly spaced"):
        FieldSeries(np.zeros((3, 2, 2)), coords=([0, 1], [0, 1], [0, 2, 9])).index_to_world()


def test_a_one_cell_thick_grid_points_to_grid_render():
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.iso.api import field_of

    with pytest.raises(InputError) as err:
        field_of(synthetic_grid(4, 3, 1), "PORO")
    msg = str(err.value)
    assert "4×3×1 cells" in msg and "geoshade grid render" in msg and "\n" not in msg


def test_a_non_unified_restart_opened_itself_is_the_iso_default(tmp_path):
    from geoshade.iso.options import IsoOptions
    from tests.io.test_ecl_variants import _synthetic

    _synthetic(tmp_path, unified=False)
    files = sorted(tmp_path.glob("CASE.X*"))
    given = files[1]
    f = load_field(given, keyword="SWAT")
    assert f.meta["default_step"] == 1 and f.nsteps == len(files)
    assert IsoOptions.check_step(None, f) == 1
    assert IsoOptions.check_step(-1, f) == len(files) - 1
    assert IsoOptions.check_step(None, load_field(tmp_path / "CASE.EGRID", keyword="SWAT")) \
        == len(files) - 1


# --- the same file in the stacks part ----------------------------------------------------------
@pytest.mark.parametrize("bounds", [True, False], ids=["cf-bounds", "centres"])
def test_labels_stored_top_down_with_uneven_layers_as_stacks(tmp_path, bounds):
    """A label model stored like the voxel model above: its stacks start at the layers' true
    edges (numpy over the labels and the depths written: CF bounds, else halfway between the
    centres, said as assumed), z up; a voxel volume refuses it."""
    from geoshade.io import load
    from geoshade.stacks import convert

    rng = np.random.default_rng(5)
    labels = rng.integers(1, 4, (len(THICK), len(Y), len(X))).astype(np.float32)
    depth_edges = np.concatenate([[0.0], np.cumsum(THICK)])
    attrs = {"units": "m", "positive": "down", **({"bounds": "depth_bnds"} if bounds else {})}
    more = {"depth_bnds": (("layer", "nv"), np.stack([depth_edges[:-1], depth_edges[1:]], 1))}
    xr.Dataset({"unit": (("layer", "y", "x"), labels), **(more if bounds else {})},
               coords={"layer": np.arange(1, len(THICK) + 1), "x": ("x", X, {"units": "m"}),
                       "y": ("y", Y, {"units": "m"}), "depth": ("layer", CENTRES, attrs)}
               ).to_netcdf(tmp_path / "l.nc")
    with pytest.raises(InputError, match=r"layer centres 3–175 m apart.*stacks render/convert"):
        load(tmp_path / "l.nc")
    m = convert(tmp_path / "l.nc", variable="unit")
    if bounds:
        edges = -depth_edges[::-1]                                     # bottom first, z up
    else:
        c = -CENTRES[::-1]
        mid = (c[1:] + c[:-1]) / 2
        edges = np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])
        assert any("assumed" in n for n in m.meta["notes"])
    up = labels[::-1]                                                   # deepest layer first
    z = lambda lv: m.origin[2] + float(lv) * m.spacing[2]   # noqa: E731
    assert m.origin[2] == pytest.approx(edges[0])
    assert z(m.nlevels) == pytest.approx(edges[-1])
    for col_id in range(m.ncols):
        j, i = divmod(col_id, len(X))
        col = up[:, j, i]
        change = np.flatnonzero(np.diff(col)) + 1
        want = [(edges[0], col[0])] + [(edges[k], col[k]) for k in change]
        a, b = m.offsets[col_id], m.offsets[col_id + 1]
        got = [(z(s), k) for s, k in zip(m.starts[a:b], m.codes[a:b], strict=True)]
        assert len(got) == len(want)
        for (zg, kg), (zw, kw) in zip(got, want, strict=True):
            assert kg == kw and zg == pytest.approx(zw, abs=1e-3)
    assert any("positive" in n for n in m.meta["notes"])


def test_a_zarr_group_with_coordinate_arrays(tmp_path):
    """A zarr group written without xarray: the field and 1D ``x``, ``y``, ``depth`` arrays
    (``positive="down"``) beside it place it as netCDF coordinates do."""
    zarr = pytest.importorskip("zarr")
    g = zarr.open_group(str(tmp_path / "g.zarr"), mode="w")
    g.create_array("kh", data=_kh(), chunks=(2, 8, 10))
    g.create_array("x", data=X)
    g.create_array("y", data=Y)
    d = g.create_array("depth", data=CENTRES)
    d.attrs.update({"positive": "down", "units": "m"})
    f = load_field(tmp_path / "g.zarr")
    assert f.is_rectilinear and f.meta["format"] == "zarr"
    np.testing.assert_array_equal(f.axes()[2], -CENTRES[::-1])
    np.testing.assert_array_equal(f.step(0), _kh()[::-1])
