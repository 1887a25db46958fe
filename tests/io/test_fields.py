"""load_field (.npy, .npz, zarr, netCDF, ECLIPSE/OPM) and the mesh writers."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import load_field
from geoshade.io.interop.mesh import write_mesh
from geoshade.models import TriangleMesh

REEK_RUN = "reek_cornerpoint/opm_flow_run/2_R001_REEK-0"


@pytest.fixture
def series():
    rng = np.random.default_rng(0)
    return rng.random((3, 4, 5, 6)).astype(np.float32)


def test_npy_3d_and_4d(tmp_path, series):
    np.save(tmp_path / "one.npy", series[0])
    np.save(tmp_path / "all.npy", series)
    one = load_field(tmp_path / "one.npy")
    assert one.nsteps == 1 and one.shape == (4, 5, 6)
    f = load_field(tmp_path / "all.npy", spacing=(2, 2, 1), origin=(0, 0, -5))
    assert f.nsteps == 3 and f.spacing == (2.0, 2.0, 1.0) and f.origin == (0.0, 0.0, -5.0)
    assert isinstance(f.values, np.memmap)
    assert np.array_equal(f.step(2), series[2])
    assert np.array_equal(load_field(tmp_path / "all.npy", step=1).step(0), series[1])
    with pytest.raises(InputError, match="nothing to colour by"):
        load_field(tmp_path / "all.npy", color_by="P")
    np.save(tmp_path / "flat.npy", np.zeros((4, 5)))
    with pytest.raises(InputError, match=r"expected \(nz, ny, nx\) or \(time, nz, ny, nx\)"):
        load_field(tmp_path / "flat.npy")


def test_npz_members_keyword_and_metadata(tmp_path, series):
    p = tmp_path / "f.npz"
    np.savez(p, SWAT=series, PRESSURE=series * 100, spacing=np.array([1, 2, 3.0]),
             times=np.array(["2000-01-01", "2000-02-01", "2000-03-01"]))
    f = load_field(p, color_by="PRESSURE")
    assert f.name == "SWAT" and f.spacing == (1.0, 2.0, 3.0)
    assert f.times[1] == "2000-02-01"
    assert np.allclose(f.property_step("PRESSURE", 2), series[2] * 100)
    g = load_field(p, keyword="PRESSURE")
    assert g.name == "PRESSURE"
    with pytest.raises(InputError, match=r"array 'SGAS' not found; it holds SWAT, PRESSURE"):
        load_field(p, keyword="SGAS")
    assert load_field(p).name == "SWAT"  # a default name wins
    np.savez(tmp_path / "two.npz", a=series, b=series)
    with pytest.raises(InputError, match=r"holds 2 3D/4D arrays \(a, b\); choose one"):
        load_field(tmp_path / "two.npz")
    with pytest.raises(InputError, match="step 5 does not exist"):
        load_field(p, keyword="SWAT", step=5)


def test_npz_mismatched_step_shapes(tmp_path):
    p = tmp_path / "bad.npz"
    np.savez(p, SWAT=np.zeros((2, 3, 4, 5)), PRESSURE=np.zeros((2, 3, 4, 6)))
    with pytest.raises(InputError, match=r"PRESSURE: shape \(3, 4, 6\).*does not match"):
        load_field(p, keyword="SWAT", color_by="PRESSURE")


def test_zarr_is_lazy(tmp_path, series):
    zarr = pytest.importorskip("zarr")
    g = zarr.open_group(str(tmp_path / "f.zarr"), mode="w")
    g.create_array("SWAT", data=series, chunks=(1, 4, 5, 6))
    g.attrs.update({"spacing": [5, 5, 1], "origin": [100, 200, -50], "unit": "fraction"})
    f = load_field(tmp_path / "f.zarr")
    assert not isinstance(f.values, np.ndarray)
    assert f.spacing == (5.0, 5.0, 1.0) and f.origin == (100.0, 200.0, -50.0)
    assert np.array_equal(f.step(1), series[1])


def test_netcdf_dims_coords_and_times(tmp_path, series):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("netCDF4")
    t = np.array(["2000-01-01", "2000-02-01", "2000-03-01"], dtype="datetime64[ns]")
    # stored (time, x, y, z) with a decreasing z coordinate: read back as (z, y, x), z flipped
    data = series.transpose(0, 3, 2, 1)[..., ::-1]
    ds = xr.Dataset({"sw": (("time", "x", "y", "z"), data),
                     "p": (("time", "x", "y", "z"), data * 2)},
                    coords={"time": t, "x": 10.0 + 2 * np.arange(6), "y": np.arange(5.0),
                            "z": 30.0 - 10 * np.arange(4)})
    ds.to_netcdf(tmp_path / "f.nc")
    f = load_field(tmp_path / "f.nc", color_by="p")
    assert f.name == "sw" and f.shape == (4, 5, 6)
    assert f.spacing == (2.0, 1.0, 10.0) and f.origin == (10.0, 0.0, 0.0)
    assert f.times == ["2000-01-01", "2000-02-01", "2000-03-01"]
    assert np.allclose(f.step(2), series[2])
    assert np.allclose(f.property_step("p", 1), 2 * series[1])


def test_unknown_and_missing(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        load_field(tmp_path / "nope.npy")
    (tmp_path / "a.txt").write_text("x")
    with pytest.raises(InputError, match=r"unknown field format '\.txt'"):
        load_field(tmp_path / "a.txt")


# --- meshes -----------------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", [".ply", ".obj", ".stl"])
def test_mesh_writers_round_trip(tmp_path, suffix):
    meshio = pytest.importorskip("meshio")
    rng = np.random.default_rng(1)
    v = rng.random((12, 3)).astype(np.float32)
    f = np.array([[0, 1, 2], [2, 3, 4], [5, 6, 7], [8, 9, 11]])
    m = TriangleMesh(v, f, normals=rng.random((12, 3)), values=np.arange(12))
    out = write_mesh(tmp_path / f"m{suffix}", m)
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # nothing left behind
    r = meshio.read(out)
    faces = r.cells_dict["triangle"]
    assert len(faces) == 4
    assert np.allclose(r.points[faces], v[f], atol=1e-6)
    if suffix == ".ply":
        assert np.allclose(r.point_data["value"], np.arange(12))


def test_mesh_writer_rejects_unknown_suffix(tmp_path):
    with pytest.raises(InputError, match=r"unknown mesh format '\.vtk'"):
        write_mesh(tmp_path / "m.vtk", TriangleMesh(np.eye(3), [[0, 1, 2]]))
    with pytest.raises(InputError, match="output folder"):
        write_mesh(tmp_path / "no" / "m.ply", TriangleMesh(np.eye(3), [[0, 1, 2]]))


# --- the Reek OPM run ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def reek(shared_data):
    return load_field(shared_data / f"{REEK_RUN}.UNRST", keyword="SWAT", color_by="PRESSURE")


@pytest.mark.data
def test_reek_37_steps_in_order(reek):
    assert reek.nsteps == 37 and reek.is_cornerpoint
    assert reek.shape == (14, 64, 40)
    assert reek.times == sorted(reek.times) and len(set(reek.times)) == 37
    assert reek.times[0].startswith("2000-01") and reek.times[-1].startswith("2003-01")
    assert int(reek.active.sum()) == 35817
    s = reek.step(36)
    assert np.nanmax(s[reek.active]) <= 1.0 and np.nanmin(s[reek.active]) >= 0.0
    p = reek.property_step("PRESSURE", 0)
    assert 100 < float(np.median(p[reek.active])) < 1000  # bar


@pytest.mark.data
def test_reek_keyword_the_restart_lacks(shared_data):
    with pytest.raises(InputError, match="SOIL_X"):
        load_field(shared_data / f"{REEK_RUN}.UNRST", keyword="SOIL_X")


@pytest.mark.data
def test_reek_swat_front_moves(reek):
    """The CPU reference through the cell centres: water is injected, the water body
    (SWAT >= 0.5) grows and the SWAT = 0.5 surface around the shrinking oil zone changes (fewer
    triangles, a smaller area) only where SWAT changed; the surface sits inside the grid."""
    from geoshade.compute.mesh import marching_cubes as mc
    from geoshade.iso.api import geometry

    model, pos = geometry(reek)
    res = {}
    for k in (1, 36):
        pv = mc.prepare_values(reek.step(k), reek.active)
        r = mc.marching_cubes(pv, 0.5, positions=pos)
        res[k] = (r, mc.surface_area(r.triangles), pv)
    (r1, a1, p1), (r36, a36, p36) = res[1], res[36]
    assert (p36.values >= 0.5).sum() > (p1.values >= 0.5).sum() + 500
    assert r36.count < 0.9 * r1.count and a36 < 0.85 * a1
    # cells whose case changed have a node whose value changed
    k1, k36 = mc.classify(p1.values, 0.5), mc.classify(p36.values, 0.5)
    moved = np.argwhere(k1 != k36)
    assert len(moved) > 100
    diff = p1.values != p36.values
    near = np.zeros(len(moved), bool)
    for c in mc.CORNERS:  # 8 corners
        z, y, x = (moved + c[::-1]).T
        near |= diff[z, y, x]
    assert near.all()
    tri = r36.triangles.reshape(-1, 3).astype(np.float64) @ model[:3, :3].T + model[:3, 3]
    b = reek.bounds()
    assert (tri[:, :2] >= b[0, :2] - 1e-3).all() and (tri[:, :2] <= b[1, :2] + 1e-3).all()
    assert (-tri[:, 2] >= b[0, 2] - 1e-3).all() and (-tri[:, 2] <= b[1, 2] + 1e-3).all()
