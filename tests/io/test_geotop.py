"""GeoTOP netCDF, TNO legends, DINOloket boreholes, the saved stack model, drape images."""

from __future__ import annotations

import json

import numpy as np
import pytest

import geoshade
import geoshade.io.output as output_module
from geoshade.compute.stacks import (
    gpu_intervals,
    memory_table,
    place_boreholes,
    stacks_to_voxels,
    voxels_to_stacks,
)
from geoshade.errors import InputError
from geoshade.io.layers.geotop import read_boreholes, read_geotop, read_legend
from geoshade.io.layers.stackfile import read_stacks, write_stacks
from geoshade.io.volumes.image import read_image
from geoshade.models.stacks import EMPTY, StackModel


@pytest.fixture(scope="module")
def geotop(shared_data):
    return shared_data / "geotop_usp"


@pytest.mark.data
@pytest.mark.parametrize("variable", ["strat", "lithok"])
def test_round_trip_voxels_stacks_voxels_is_exact_on_geotop(geotop, variable):
    import xarray as xr

    vol = read_geotop(geotop / "geotop_usp.nc", variable)
    with xr.open_dataset(geotop / "geotop_usp.nc") as ds:
        ref = ds[variable].transpose("z", "y", "x").values   # the oracle: xarray itself
    assert np.array_equal(vol.data, ref, equal_nan=True)
    assert vol.shape_xyz == (19, 15, 313) and vol.spacing == (100.0, 100.0, 0.5)
    assert vol.origin == (139450.0, 454650.0, -50.25) and vol.meta["crs"] == "EPSG:28992"
    m = voxels_to_stacks(vol.data, spacing=vol.spacing, origin=vol.origin,
                         legend=vol.meta["legend"])
    assert np.array_equal(stacks_to_voxels(m, np.float32), vol.data, equal_nan=True)
    d = np.where(np.isnan(ref), -1, ref)
    runs = (np.diff(d, axis=0) != 0).sum(axis=0) + 1 - (d[0] == -1)
    assert m.counts().reshape(15, 19).tolist() == runs.tolist()


@pytest.mark.data
def test_memory_targets_against_4_bytes_per_voxel(geotop):
    saving = {}
    for variable in ("strat", "lithok"):
        vol = read_geotop(geotop / "geotop_usp.nc", variable)
        saving[variable] = memory_table(voxels_to_stacks(vol.data))["saving_vs_voxels"]
    assert saving["strat"] >= 0.95 and saving["lithok"] >= 0.90, saving


@pytest.mark.data
def test_tno_legends(geotop):
    lk = read_legend("lithok", geotop / "legend_nlmod")
    assert lk.codes.tolist() == [0, 1, 2, 3, 5, 6, 7, 8, 9, 10]
    assert lk.names[2] == "k klei" and lk.rgba[2].tolist() == [0, 146, 0, 255]
    st = read_legend("strat", geotop / "legend_nlmod")
    assert {1000, 2010, 5070}.issubset(set(st.codes.tolist())) and 0 in st.codes
    vol = read_geotop(geotop / "geotop_usp.nc", "strat")
    present = np.unique(vol.data[np.isfinite(vol.data)]).astype(int)
    assert np.isin(present, vol.meta["legend"].codes).all()
    with pytest.raises(InputError, match="no TNO table"):
        read_legend("kans_1", geotop / "legend_nlmod")


@pytest.mark.data
def test_boreholes_placed_into_columns(geotop):
    vol = read_geotop(geotop / "geotop_usp.nc", "lithok")
    m = voxels_to_stacks(vol.data, spacing=vol.spacing, origin=vol.origin,
                         legend=vol.meta["legend"])
    logs = read_boreholes(geotop / "boreholes_usp.parquet", "lithok", vol.meta["legend"])
    assert (logs.nboreholes, len(logs)) == (67, 1398)
    assert np.isin(logs.code, vol.meta["legend"].codes).all()
    b = place_boreholes(m, logs)
    info = b.meta["boreholes"]
    assert info["placed"] + info["duplicates"] + info["outside"] == 67
    assert int(b.borehole.sum()) == info["placed"] == info["columns"]
    # columns without a log are unchanged
    keep = ~b.borehole.reshape(15, 19)
    assert np.array_equal(stacks_to_voxels(b, np.float32)[:, keep],
                          vol.data[:, keep], equal_nan=True)
    # every borehole column's top is a log interval at the borehole's surface
    g = gpu_intervals(b)
    top = g.first + g.count - 1
    assert g.log[top[b.borehole]].all()
    strat = read_boreholes(geotop / "boreholes_usp.parquet", "strat",
                           read_geotop(geotop / "geotop_usp.nc", "strat").meta["legend"])
    assert {0, 2010, 4050}.issubset(set(strat.code.tolist()))


@pytest.mark.data
def test_netcdf_without_the_variable_and_unreadable_files(geotop, tmp_path):
    with pytest.raises(InputError) as e:
        read_geotop(geotop / "geotop_usp.nc", "porosity")
    msg = str(e.value)
    assert "no variable 'porosity'" in msg and "lithok" in msg and "\n" not in msg
    bad = tmp_path / "bad.nc"
    bad.write_bytes(b"not a netcdf")
    with pytest.raises(InputError, match="not a readable netCDF"):
        read_geotop(bad)
    with pytest.raises(InputError, match="no such file"):
        read_boreholes(tmp_path / "none.parquet")


@pytest.mark.data
def test_load_registers_netcdf_and_stack_models(geotop, tmp_path):
    vol = geoshade.load(geotop / "geotop_usp.nc", variable="strat")
    assert vol.meta["variable"] == "strat"
    m = voxels_to_stacks(vol.data, legend=vol.meta["legend"])
    p = write_stacks(tmp_path / "m.stacks.npz", m)
    back = geoshade.load(p)
    assert isinstance(back, StackModel) and np.array_equal(back.codes, m.codes)
    d = geoshade.io.describe(back)
    assert d["kind"] == "stacks" and d["intervals"] == m.nintervals


# --- the saved model --------------------------------------------------------------------------
def model_with_boreholes() -> StackModel:
    m = StackModel([0, 2, 3, 3], [0.0, 2.5, 1.0], [4, EMPTY, 5], (3, 1), 6, crs="EPSG:28992",
                   name="m", origin=(10.0, 20.0, -5.0), spacing=(100.0, 100.0, 0.5),
                   borehole=[False, True, False], log_base=[0.0, 1.0, 0.0],
                   meta={"variable": "lithok", "obj": object()})
    return m


def test_stackfile_round_trip_keeps_everything(tmp_path):
    m = model_with_boreholes()
    r = read_stacks(write_stacks(tmp_path / "a.stacks.npz", m))
    for f in ("offsets", "starts", "codes", "borehole", "log_base"):
        assert np.array_equal(getattr(r, f), getattr(m, f)), f
    assert (r.shape, r.nlevels, r.origin, r.spacing, r.crs, r.name) == (
        m.shape, m.nlevels, m.origin, m.spacing, m.crs, m.name)
    assert r.legend.names == m.legend.names and np.array_equal(r.legend.rgba, m.legend.rgba)
    assert r.meta["variable"] == "lithok" and "obj" not in r.meta
    # plain numpy reads it, and the header is versioned JSON
    with np.load(tmp_path / "a.stacks.npz") as z:
        h = json.loads(bytes(z["header"]).decode())
    assert (h["format"], h["version"]) == ("geoshade-stacks", 1)


def _rewrite(src, dst, **changes):
    with np.load(src) as z:
        arrays = {k: z[k] for k in z.files}
    h = json.loads(bytes(arrays["header"]).decode())
    for k, v in changes.items():
        if k == "drop":
            arrays.pop(v)
        elif k in arrays:
            arrays[k] = v
        else:
            h[k] = v
    arrays["header"] = np.frombuffer(json.dumps(h).encode(), np.uint8)
    np.savez(dst, **arrays)
    return dst


@pytest.mark.parametrize("change, what", [
    ({"version": 2}, "format version 2"),
    ({"format": "other"}, "expected 'geoshade-stacks'"),
    ({"drop": "codes"}, "members ['codes'] missing"),
    ({"starts": np.array([0.0, 0.0, 1.0], np.float32)}, "non-monotonic or overlapping"),
])
def test_stackfile_bad_files_are_one_line_errors(tmp_path, change, what):
    good = write_stacks(tmp_path / "a.stacks.npz", model_with_boreholes())
    bad = _rewrite(good, tmp_path / "b.stacks.npz", **change)
    with pytest.raises(InputError) as e:
        read_stacks(bad)
    assert what in str(e.value) and "\n" not in str(e.value)


def test_stackfile_write_is_atomic(tmp_path, monkeypatch):
    p = write_stacks(tmp_path / "a.stacks.npz", model_with_boreholes())
    before = p.read_bytes()

    def boom(*a, **k):
        raise RuntimeError("disk full")

    monkeypatch.setattr(output_module.os, "replace", boom)  # fails at the final rename
    with pytest.raises(RuntimeError):
        write_stacks(p, voxels_to_stacks(np.ones((2, 2, 2), np.int8)))
    assert p.read_bytes() == before
    assert [f.name for f in tmp_path.iterdir()] == ["a.stacks.npz"]


# --- drape images -----------------------------------------------------------------------------
def test_geotiff_extent_and_bad_images(tmp_path):
    import tifffile

    f = tmp_path / "ortho.tif"
    tifffile.imwrite(f, np.zeros((10, 20, 3), np.uint8),
                     extratags=[(33550, "d", 3, (100.0, 50.0, 0.0)),
                                (33922, "d", 6, (0, 0, 0, 1000.0, 2000.0, 0))])
    rgba, extent = read_image(f)
    assert rgba.shape == (10, 20, 4) and extent == (1000.0, 1500.0, 3000.0, 2000.0)
    g = tmp_path / "grey.tif"
    tifffile.imwrite(g, np.arange(12, dtype=np.uint16).reshape(3, 4))
    rgba, extent = read_image(g)
    assert extent is None and rgba[0, 0, 0] == 0 and rgba[-1, -1, 0] == 255
    junk = tmp_path / "junk.png"
    junk.write_bytes(b"\x89PNG not really")
    for p in (junk, tmp_path / "missing.jpg"):
        with pytest.raises(InputError, match="cannot read image"):
            read_image(p)
