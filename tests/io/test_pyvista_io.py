"""geoshade models ⇄ PyVista: round trips exact, and the datasets checked against PyVista's own
constructors and filters (the oracles)."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.compute.stacks import voxels_to_stacks
from geoshade.compute.voxels.synthetic import random_labels
from geoshade.errors import InputError, MissingExtraError
from geoshade.io.interop import pyvista_io
from geoshade.models import FieldSeries, StackModel, TriangleMesh, VoxelVolume

pv = pytest.importorskip("pyvista")


def _volume() -> VoxelVolume:
    rng = np.random.default_rng(3)
    return VoxelVolume(rng.integers(0, 4000, (5, 6, 7), dtype=np.uint16),
                       spacing=(0.5, 0.25, 2.0), origin=(10.0, -3.0, 7.5), unit="um",
                       name="core.raw")


# --- volumes ---------------------------------------------------------------------------------
def test_volume_is_image_data_of_cells_and_round_trips():
    vol = _volume()
    img = vol.to_pyvista(selection=(1000, 2500))
    assert isinstance(img, pv.ImageData)
    assert img.dimensions == (8, 7, 6) and img.spacing == vol.spacing
    assert img.origin == vol.origin
    # oracle: VTK's own cell centres are the voxel centres, in the volume's (x fastest) order
    nz, ny, nx = vol.data.shape
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    centres = np.stack([i, j, k], -1).reshape(-1, 3) * vol.spacing + vol.origin \
        + np.asarray(vol.spacing) / 2
    assert np.allclose(img.cell_centers().points, centres)
    assert np.array_equal(img.cell_data["values"], vol.data.ravel())
    sel = (vol.data >= 1000) & (vol.data <= 2500)
    assert img.cell_data["selected"].dtype == np.uint8
    assert np.array_equal(img.cell_data["selected"], sel.ravel().astype(np.uint8))
    back = geoshade.from_pyvista(img)
    assert np.array_equal(back.data, vol.data) and back.data.dtype == vol.data.dtype
    assert back.spacing == vol.spacing and back.origin == vol.origin and back.unit == "um"


def test_volume_shares_memory_with_image():
    vol = _volume()
    img = pyvista_io.volume_to_pyvista(vol)
    assert np.shares_memory(np.asarray(img.cell_data["values"]), vol.data)


def test_point_data_image_becomes_voxels_centred_on_points():
    img = pv.ImageData(dimensions=(4, 3, 2), spacing=(2.0, 1.0, 3.0), origin=(1.0, 1.0, 1.0))
    img.point_data["h"] = np.arange(24, dtype=np.float64)
    vol = geoshade.from_pyvista(img)
    assert vol.shape_xyz == (4, 3, 2)
    assert vol.origin == (0.0, 0.5, -0.5)
    # voxel centres are the image's points (x fastest)
    b = vol.bounds()
    assert np.allclose(b[0] + np.asarray(vol.spacing) / 2, img.points[0])
    assert np.allclose(b[1] - np.asarray(vol.spacing) / 2, img.points[-1])
    assert np.array_equal(vol.data.ravel(), img.point_data["h"])


def test_rotated_or_empty_image_refused():
    img = pv.ImageData(dimensions=(3, 3, 3))
    img.cell_data["v"] = np.zeros(8, np.float32)
    img.direction_matrix = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])
    with pytest.raises(InputError, match="rotated"):
        geoshade.from_pyvista(img)
    with pytest.raises(InputError, match="no cell or point array"):
        geoshade.from_pyvista(pv.ImageData(dimensions=(3, 3, 3)))


# --- corner-point grids ----------------------------------------------------------------------
def _pyvista_esg(g):
    """The ExplicitStructuredGrid PyVista builds itself from the corner-point layout of the
    cells' corners (its documented constructor), inactive cells hidden by its own method."""
    nx, ny, nz = g.dims
    c = g.corners().reshape(nx, ny, nz, 2, 2, 2, 3)          # i j k | c' b a | xyz
    c = c.transpose(0, 5, 1, 4, 2, 3, 6).reshape(2 * nx, 2 * ny, 2 * nz, 3)
    esg = pv.ExplicitStructuredGrid((nx + 1, ny + 1, nz + 1),
                                    c.transpose(2, 1, 0, 3).reshape(-1, 3))
    esg = esg.hide_cells(np.flatnonzero(~g.active.ravel(order="F")))
    return esg


def test_grid_matches_pyvistas_own_construction():
    g = synthetic_grid(7, 5, 4, inactive_fraction=0.2)
    ours = g.to_pyvista(step=None)
    ref = _pyvista_esg(g)
    assert isinstance(ours, pv.ExplicitStructuredGrid)
    assert ours.dimensions == ref.dimensions and ours.n_cells == ref.n_cells
    assert np.array_equal(np.asarray(ours.points), np.asarray(ref.points))
    assert np.array_equal(ours.cell_data["vtkGhostType"], ref.cell_data["vtkGhostType"])
    assert int((ours.cell_data["vtkGhostType"] == pyvista_io.HIDDEN_CELL).sum()) \
        == g.ncells - g.nactive
    # cell (i, j, k) is cell i + nx (j + ny k), with its property value
    nx, ny, _ = g.dims
    i, j, k = 5, 3, 2
    cid = i + nx * (j + ny * k)
    assert ours.cell_data["PORO"][cid] == g.properties["PORO"][i, j, k]
    assert np.array_equal(np.sort(ours.get_cell(cid).points, axis=0),
                          np.sort(g.corners()[i, j, k], axis=0))


def test_grid_round_trip_exact():
    g = synthetic_grid(6, 4, 3, inactive_fraction=0.15)
    back = geoshade.from_pyvista(g.to_pyvista(step=-1))
    assert np.array_equal(back.corners(), g.corners())
    assert np.array_equal(back.zcorn, g.zcorn) and back.zcorn.dtype == g.zcorn.dtype
    assert np.array_equal(back.coord, g.coord)
    assert np.array_equal(back.actnum, g.actnum) and back.actnum.dtype == g.actnum.dtype
    assert np.array_equal(back.mapaxes, g.mapaxes) and back.units == g.units
    for name, arr in g.properties.items():
        assert np.array_equal(back.properties[name], arr), name
        assert back.properties[name].dtype == arr.dtype
    assert np.array_equal(back.steps[0]["SWAT"], g.steps[-1]["SWAT"])
    assert back.step_dates == [g.step_dates[-1]]


def test_boolean_and_integer_properties_keep_their_cells():
    g = synthetic_grid(5, 4, 3)
    g.properties["SAND"] = np.asfortranarray(g.properties["PORO"] > 0.2)
    esg = g.to_pyvista(step=None)
    assert np.array_equal(esg.cell_data["SAND"], g.properties["SAND"].reshape(-1, order="F"))
    assert np.array_equal(esg.cell_data["FIPNUM"], g.properties["FIPNUM"].reshape(-1, order="F"))


def test_grid_z_up_round_trip():
    g = synthetic_grid(4, 3, 2)
    esg = g.to_pyvista(z_up=True)
    assert esg.bounds[5] < 0  # depths became elevations
    back = geoshade.from_pyvista(esg)
    assert np.array_equal(back.corners(), g.corners())


def test_foreign_explicit_grid_gets_its_pillars_from_the_corners():
    g = synthetic_grid(5, 4, 3, inactive_fraction=0.1)
    back = geoshade.from_pyvista(_pyvista_esg(g))  # no geoshade field data: pillars rebuilt
    assert np.array_equal(back.zcorn, g.zcorn.astype(np.float64))
    assert np.array_equal(back.active, g.active)
    assert np.allclose(back.corners(), g.corners(), rtol=0, atol=1e-7)


def test_explicit_grid_off_its_pillars_refused():
    g = synthetic_grid(3, 3, 2)
    esg = _pyvista_esg(g)
    pts = np.array(esg.points)
    pts[5, 0] += 7.0  # one corner off its pillar
    esg.points = pts
    with pytest.raises(InputError, match="not a corner-point grid"):
        geoshade.from_pyvista(esg)


# --- fields, meshes, stacks ------------------------------------------------------------------
def test_regular_field_round_trip_all_steps():
    rng = np.random.default_rng(1)
    f = FieldSeries(rng.random((3, 4, 5, 6)).astype(np.float32), spacing=(2, 3, 1),
                    origin=(5, 6, 7), name="SWAT", unit="frac", length_unit="m",
                    times=["2001-01-01", "2001-02-01", "2001-03-01"])
    img = f.to_pyvista(step="all")
    assert np.allclose(img.points[-1], f.bounds()[1])
    back = geoshade.from_pyvista(img)
    assert isinstance(back, FieldSeries) and back.nsteps == 3 and back.times == f.times
    assert back.spacing == f.spacing and back.origin == f.origin and back.unit == "frac"
    for k in range(3):
        assert np.array_equal(back.step(k), f.step(k))
    one = f.to_pyvista()  # default: the last step, named after the field
    assert np.array_equal(one.point_data["SWAT"], f.step(-1).ravel())


def test_grid_field_round_trip():
    g = synthetic_grid(4, 3, 2)
    from geoshade.models.field import GridSteps

    f = FieldSeries(GridSteps(g, "SWAT"), grid=g, name="SWAT", times=g.step_dates)
    esg = f.to_pyvista(step="all")
    back = geoshade.from_pyvista(esg)
    assert isinstance(back, FieldSeries) and back.grid is not None and back.nsteps == 4
    assert np.array_equal(back.grid.corners(), g.corners())
    assert sorted(back.grid.properties) == sorted(g.properties)
    for k in range(4):
        assert np.array_equal(back.step(k), f.step(k))


def test_mesh_round_trip_and_area():
    skimage = pytest.importorskip("skimage.measure")
    z, y, x = np.mgrid[-1:1:12j, -1:1:12j, -1:1:12j]
    verts, faces, normals, values = skimage.marching_cubes(x * x + y * y + z * z, 0.5)
    mesh = TriangleMesh(verts.astype(np.float32), faces, normals=normals, values=values,
                        name="r2")
    poly = mesh.to_pyvista()
    assert poly.n_points == mesh.n_vertices and poly.n_cells == mesh.n_faces
    assert poly.area == pytest.approx(mesh.area(), rel=1e-6)  # VTK's own area
    back = geoshade.from_pyvista(poly)
    assert np.array_equal(back.vertices, mesh.vertices)
    assert np.array_equal(back.faces, mesh.faces)
    assert np.array_equal(back.normals, mesh.normals)
    assert np.array_equal(back.values, mesh.values) and back.name == "r2"


def test_quads_refused_with_the_fix():
    with pytest.raises(InputError, match="triangulate"):
        geoshade.from_pyvista(pv.Plane())


def test_stacks_are_exact_hexahedra_and_round_trip():
    labels = random_labels((6, 5, 9), 0.5, seed=2)
    model = voxels_to_stacks(labels.data, spacing=(2.0, 3.0, 0.5), origin=(100, 200, -4))
    ug = model.to_pyvista()
    assert isinstance(ug, pv.UnstructuredGrid)
    full = model.codes != -1
    assert ug.n_cells == int(full.sum())
    # oracle: VTK's cell volumes per code = the voxels of that code
    vol = ug.compute_cell_sizes(length=False, area=False)["Volume"]
    voxel = 2.0 * 3.0 * 0.5
    data = np.asarray(labels.data)
    for code in np.unique(model.codes[full]):
        assert vol[ug.cell_data["code"] == code].sum() == pytest.approx(
            voxel * np.count_nonzero(data == code))
    back = geoshade.from_pyvista(ug)
    assert isinstance(back, StackModel)
    for attr in ("offsets", "starts", "codes", "borehole", "log_base"):
        assert np.array_equal(getattr(back, attr), getattr(model, attr)), attr
    assert back.origin == model.origin and back.spacing == model.spacing
    assert np.array_equal(back.legend.codes, model.legend.codes)


def test_stacks_of_fractional_heights_round_trip():
    m = StackModel([0, 3, 4], [0.0, 1.25, 2.75, 0.5], [4, -1, 5, 4], (2, 1), 4,
                   spacing=(1.0, 1.0, 0.1))
    ug = m.to_pyvista()
    assert ug.n_cells == 3
    assert np.allclose(np.sort(ug.compute_cell_sizes()["Volume"]),
                       np.sort([1.25 * 0.1, 1.25 * 0.1, 3.5 * 0.1]))
    back = geoshade.from_pyvista(ug)
    assert back.starts.tolist() == m.starts.tolist() and back.codes.tolist() == m.codes.tolist()


# --- errors ----------------------------------------------------------------------------------
def test_missing_pyvista_is_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "pyvista", None)
    with pytest.raises(MissingExtraError, match=r"pip install 'geoshade\[pyvista\]'"):
        _volume().to_pyvista()


def test_unknown_things_refused():
    with pytest.raises(InputError, match="cannot convert a str"):
        geoshade.to_pyvista("volume")
    with pytest.raises(InputError, match="StructuredGrid has no geoshade model"):
        geoshade.from_pyvista(pv.ImageData(dimensions=(2, 2, 2)).cast_to_structured_grid())
