"""geoshade models ⇄ xarray: coordinates, units and values survive the round trips, GeoTOP-like
netCDF files and simulation fields included."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io.layers.geotop import read_geotop
from geoshade.models import CornerPointGrid, FieldSeries, VoxelVolume
from geoshade.models.field import GridSteps

xr = pytest.importorskip("xarray")


def _geotop_file(tmp_path):
    """A small GeoTOP-like netCDF: x ascending, y descending, cell-centre coordinates, NaN
    above ground, the EPSG code on the coordinates (as TNO writes it)."""
    rng = np.random.default_rng(4)
    x = 120000.0 + 100.0 * np.arange(5) + 50.0
    y = 450000.0 - 100.0 * np.arange(4) - 50.0
    z = -10.0 + 0.5 * np.arange(6) + 0.25
    lithok = rng.integers(1, 8, (5, 4, 6)).astype(np.float32)
    lithok[:, :, -2:] = np.nan
    ds = xr.Dataset({"lithok": (("x", "y", "z"), lithok)},
                    coords={"x": ("x", x, {"epsg": 28992, "units": "m"}),
                            "y": ("y", y, {"epsg": 28992, "units": "m"}),
                            "z": ("z", z, {"units": "m"})})
    path = tmp_path / "geotop.nc"
    ds.to_netcdf(path)
    return path, ds


def test_geotop_netcdf_round_trips_through_xarray(tmp_path):
    path, ds = _geotop_file(tmp_path)
    vol = read_geotop(path)
    da = geoshade.to_xarray(vol)
    assert da.dims == ("z", "y", "x") and da.name == "lithok"
    # the coordinates are the file's (sorted ascending), the values the file's at them
    for axis in "xyz":
        assert np.allclose(da[axis].values, np.sort(ds[axis].values), rtol=0, atol=1e-9)
        assert da[axis].attrs["units"] == "m"
    assert np.array_equal(da.values, ds["lithok"].transpose("z", "y", "x")
                          .sortby(["x", "y", "z"]).values, equal_nan=True)
    assert da.attrs["crs"] == "EPSG:28992"
    # and the file's own DataArray reads as the same volume
    with xr.open_dataset(path) as f:
        direct = geoshade.from_xarray(f["lithok"].load())
    assert np.allclose(direct.origin, vol.origin) and direct.spacing == vol.spacing
    assert np.array_equal(direct.data, vol.data, equal_nan=True)
    back = geoshade.from_xarray(da)
    assert back.origin == vol.origin and back.spacing == vol.spacing and back.unit == "m"
    assert np.array_equal(back.data, vol.data, equal_nan=True)


def test_volume_round_trip_through_netcdf_keeps_coordinates_and_units(tmp_path):
    vol = VoxelVolume(np.arange(60, dtype=np.uint16).reshape(3, 4, 5), spacing=(2.0, 3.0, 0.5),
                      origin=(-1.0, 4.0, 7.0), unit="um", name="scan")
    da = vol.to_xarray()
    assert np.shares_memory(da.values, vol.data)
    da.to_netcdf(tmp_path / "v.nc")
    with xr.open_dataarray(tmp_path / "v.nc") as f:
        back = geoshade.from_xarray(f.load())
    assert back.origin == vol.origin and back.spacing == vol.spacing and back.unit == "um"
    assert np.array_equal(back.data, vol.data) and back.data.dtype == np.uint16


def test_lazy_volume_stays_lazy():
    da_ = pytest.importorskip("dask.array")
    vol = VoxelVolume(da_.zeros((4, 4, 4), dtype=np.float32, chunks=2))
    arr = geoshade.to_xarray(vol)
    assert type(arr.data).__name__ == "Array"  # a dask array, not read
    assert geoshade.from_xarray(arr).is_lazy


def test_regular_field_round_trip_with_dates_and_units():
    rng = np.random.default_rng(5)
    values = rng.random((3, 4, 5, 6)).astype(np.float32)
    f = FieldSeries(values, spacing=(10, 10, 2), origin=(0, 0, -100), name="SWAT", unit="frac",
                    length_unit="m", times=["2001-01-01", "2001-07-01", "2002-01-01"])
    da = f.to_xarray()
    assert da.dims == ("time", "z", "y", "x") and da.attrs["units"] == "frac"
    assert da.x.values.tolist() == [0.0, 10.0, 20.0, 30.0, 40.0, 50.0]  # nodes
    assert np.issubdtype(da.time.dtype, np.datetime64) and da.z.attrs["units"] == "m"
    assert np.shares_memory(da.values, values)
    back = geoshade.from_xarray(da)
    assert isinstance(back, FieldSeries)
    assert back.times == f.times and back.spacing == f.spacing and back.origin == f.origin
    assert back.unit == "frac" and back.length_unit == "m" and back.name == "SWAT"
    for k in range(3):
        assert np.array_equal(back.step(k), f.step(k))


def test_simulation_field_on_a_grid_round_trips_lazily():
    g = synthetic_grid(5, 4, 3)
    reads = []

    def read(grid, k, name):
        reads.append(k)
        return grid.steps[k][name]

    f = FieldSeries(GridSteps(g, "SWAT", read=read), grid=g, name="SWAT", unit="frac",
                    times=g.step_dates)
    da = f.to_xarray()
    assert reads == []  # nothing read yet
    assert da.dims == ("time", "k", "j", "i") and da.i.values.tolist() == list(range(5))
    assert [str(t)[:10] for t in da.time.values] == g.step_dates
    assert np.array_equal(da.isel(time=2).values, g.steps[2]["SWAT"].T)
    assert reads == [2]
    back = geoshade.from_xarray(da, grid=g)
    assert back.grid is g and back.times == g.step_dates and back.unit == "frac"
    for k in range(4):
        assert np.array_equal(back.step(k), f.step(k))


def test_grid_dataset_round_trip_through_netcdf(tmp_path):
    g = synthetic_grid(5, 4, 3, inactive_fraction=0.2)
    ds = geoshade.to_xarray(g)
    assert ds["PERMX"].attrs["units"] == "mD" and ds["PORO"].dims == ("k", "j", "i")
    assert ds["COORD"].attrs["units"] == "METRES"
    assert np.shares_memory(ds["ZCORN"].values, g.zcorn)
    ds.to_netcdf(tmp_path / "g.nc")
    with xr.open_dataset(tmp_path / "g.nc") as f:
        back = geoshade.from_xarray(f.load())
    assert isinstance(back, CornerPointGrid)
    assert np.array_equal(back.corners(), g.corners())
    assert np.array_equal(back.actnum, g.actnum)
    assert np.array_equal(back.mapaxes, g.mapaxes) and back.units == g.units
    for name, arr in g.properties.items():
        assert np.array_equal(back.properties[name], arr), name
    assert back.step_dates == g.step_dates and len(back.steps) == len(g.steps)
    assert np.array_equal(back.steps[-1]["SWAT"], g.steps[-1]["SWAT"])
    one = g.to_xarray("permx")
    assert one.name == "PERMX" and np.array_equal(one.values, g.properties["PERMX"].T)


def test_bad_inputs_refused():
    with pytest.raises(InputError, match="not regularly spaced"):
        geoshade.from_xarray(xr.DataArray(np.zeros((3, 2, 2)), dims=("x", "y", "z"),
                                          coords={"x": [0, 1, 3]}))
    with pytest.raises(InputError, match="pass grid="):
        geoshade.from_xarray(xr.DataArray(np.zeros((2, 2, 2)), dims=("i", "j", "k")))
    with pytest.raises(InputError, match="expected x, y, z"):
        geoshade.from_xarray(xr.DataArray(np.zeros((2, 2)), dims=("a", "b"), name="T"))
    with pytest.raises(InputError, match="name one"):
        geoshade.from_xarray(xr.Dataset({"a": ("x", [1]), "b": ("x", [2])}))
    with pytest.raises(InputError, match="no property 'FOO'"):
        synthetic_grid(3, 3, 2).to_xarray("FOO")
