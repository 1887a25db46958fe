"""Big-endian volumes (tifffile ``byteorder=">"``, raw ``">u2"``, npy) on every path: load, render,
to_pyvista, to_xarray, napari — each equal to the same volume in native order."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.io.volumes.raw import native_order, raw_dtype

tifffile = pytest.importorskip("tifffile")


def _values() -> np.ndarray:
    rng = np.random.default_rng(7)
    return rng.integers(0, 4000, (12, 14, 16)).astype(np.uint16)   # (z, y, x)


@pytest.fixture(params=["tiff", "raw", "npy"])
def pair(request, tmp_path):
    """(big-endian volume, native volume, values)."""
    a = _values()
    nz, ny, nx = a.shape
    if request.param == "tiff":
        tifffile.imwrite(tmp_path / "be.tif", a, byteorder=">", photometric="minisblack")
        tifffile.imwrite(tmp_path / "le.tif", a, byteorder="<", photometric="minisblack")
        be, le = (geoshade.load(tmp_path / f) for f in ("be.tif", "le.tif"))
    elif request.param == "npy":
        np.save(tmp_path / "be.npy", a.astype(">u2"))
        np.save(tmp_path / "le.npy", a)
        be, le = (geoshade.load(tmp_path / f) for f in ("be.npy", "le.npy"))
    else:
        a.astype(">u2").tofile(tmp_path / "be.raw")
        a.tofile(tmp_path / "le.raw")
        be = geoshade.load(tmp_path / "be.raw", dtype=">u2", shape=(nx, ny, nz))
        le = geoshade.load(tmp_path / "le.raw", dtype="uint16", shape=(nx, ny, nz))
    return be, le, a


def test_load_reads_the_values(pair):
    be, le, a = pair
    assert be.data.dtype.byteorder == ">"   # mapped as it is on disk, not copied
    np.testing.assert_array_equal(be.data, a)
    np.testing.assert_array_equal(le.data, a)


def test_raw_dtype_byte_order_from_the_dtype():
    assert raw_dtype(">u2").str == ">u2"
    assert raw_dtype("u2", "big").str == ">u2"
    assert raw_dtype(np.dtype(">f4")).str == ">f4"
    with pytest.raises(geoshade.errors.InputError, match="little-endian but endian is 'big'"):
        raw_dtype("<u2", "big")


def test_to_pyvista(pair):
    pytest.importorskip("pyvista")
    be, _, a = pair
    img = geoshade.to_pyvista(be, selection=(0, 1000))
    values = np.asarray(img.cell_data["values"])
    assert values.dtype.isnative
    np.testing.assert_array_equal(values, a.reshape(-1))
    assert int(img.cell_data["selected"].sum()) == int(((a >= 0) & (a <= 1000)).sum())
    np.testing.assert_array_equal(geoshade.from_pyvista(img).data, a)


def test_to_xarray(pair, tmp_path):
    pytest.importorskip("xarray")
    be, _, a = pair
    da = geoshade.to_xarray(be)
    np.testing.assert_array_equal(da.values, a)
    assert float(da.mean()) == pytest.approx(float(a.mean()))
    pytest.importorskip("netCDF4")
    import xarray as xr

    da.to_netcdf(tmp_path / "be.nc")   # written and read back with the values
    with xr.open_dataarray(tmp_path / "be.nc") as back:
        np.testing.assert_array_equal(back.values, a)


def test_napari_layer_is_native(pair, tmp_path):
    from geoshade.napari._reader import layer_data

    be, _, a = pair
    path = be.meta["source"]
    if str(path).endswith(".raw"):   # napari is not offered raw files
        pytest.skip("raw files are not offered to napari")
    [(data, _, kind)] = layer_data(path)
    assert data.dtype.isnative and kind == "image"
    np.testing.assert_array_equal(np.asarray(data), a)


def test_native_order_keeps_native_arrays():
    a = np.arange(6, dtype=np.uint16)
    assert native_order(a) is a
    lazy = native_order(np.arange(6, dtype=">i2"), lazy=True)
    assert hasattr(lazy, "dask") and lazy.dtype.isnative
    assert lazy.compute().tolist() == list(range(6))


def test_render_equals_native(ctx, pair):
    be, le, _ = pair
    pictures = []
    for vol in (be, le):
        with geoshade.view(vol, select=(0, 1500), size=(96, 80), ctx=ctx,
                           annotations=False) as v:
            img, _ = v.draw()
            pictures.append(img)
    assert (pictures[0][..., 3] > 0).mean() > 0.05   # something drawn
    np.testing.assert_array_equal(pictures[0], pictures[1])


def test_field_and_stack_paths_equal_native(ctx, tmp_path):
    """A big-endian ``.npy`` field over time (iso) and label volume (stacks) draw the same
    pictures as their native copies."""
    from geoshade.io.fields import load_field

    z, y, x = np.mgrid[0:16, 0:16, 0:16]
    f = np.stack([np.sqrt((x - 8) ** 2 + (y - 8) ** 2 + (z - 8) ** 2) / (8 + k)
                  for k in range(3)]).astype(np.float32)
    np.save(tmp_path / "fle.npy", f)
    np.save(tmp_path / "fbe.npy", f.astype(">f4"))
    labels = np.random.default_rng(0).integers(0, 4, (10, 12, 14)).astype(np.int16)
    np.save(tmp_path / "lle.npy", labels)
    np.save(tmp_path / "lbe.npy", labels.astype(">i2"))
    pictures = {}
    for name in ("fle", "fbe", "lle", "lbe"):
        path = tmp_path / f"{name}.npy"
        if name[0] == "f":
            model, opts = load_field(path), {"level": 0.6}
        else:
            model, opts = geoshade.stacks.convert(path), {}
        with geoshade.view(model, size=(96, 80), ctx=ctx, annotations=False, **opts) as v:
            pictures[name], _ = v.draw()
    assert load_field(tmp_path / "fbe.npy").values.dtype.byteorder == ">"
    for le, be in (("fle", "fbe"), ("lle", "lbe")):
        assert (pictures[le][..., 3] > 0).mean() > 0.02
        np.testing.assert_array_equal(pictures[le], pictures[be])
