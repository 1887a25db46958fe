"""FieldSeries and TriangleMesh: shape contracts and one clear error per bad input."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.models import CornerPointGrid, FieldSeries, TriangleMesh


def small_grid(nx=4, ny=3, nz=2):
    x, y = np.meshgrid(np.arange(nx + 1) * 10.0, np.arange(ny + 1) * 10.0, indexing="ij")
    coord = np.zeros((nx + 1, ny + 1, 6))
    coord[..., 0], coord[..., 1], coord[..., 2] = x, y, 1000.0
    coord[..., 3], coord[..., 4], coord[..., 5] = x, y, 1100.0
    k = np.arange(2 * nz)
    zc = 1000.0 + 5.0 * ((k + 1) // 2)
    zcorn = np.broadcast_to(zc, (2 * nx, 2 * ny, 2 * nz)).copy()
    act = np.ones((nx, ny, nz), bool)
    act[0, 0, 0] = False
    return CornerPointGrid(coord, zcorn, actnum=act)


def test_forms_of_values_give_one_layout():
    a = np.arange(2 * 3 * 4 * 5, dtype=np.float64).reshape(2, 3, 4, 5)
    for values in (a, [a[0], a[1]], (a[0], a[1])):
        f = FieldSeries(values, name="S")
        assert f.nsteps == 2 and f.shape == (3, 4, 5) and f.shape_xyz == (5, 4, 3)
        assert f.cells == 4 * 3 * 2 and f.nodes == 60
        s = f.step(1)
        assert s.dtype == np.float32 and np.array_equal(s, a[1])
    one = FieldSeries(a[0])
    assert one.nsteps == 1 and one.times == ["step 0"]


def test_steps_and_their_errors():
    f = FieldSeries(np.zeros((3, 2, 2, 2)), name="SWAT", source="case.UNRST")
    assert f.check_step(-1) == 2
    with pytest.raises(InputError, match=r"case.UNRST: step 3 does not exist: SWAT has 3 steps "
                                         r"\(0..2\)"):
        f.step(3)
    with pytest.raises(InputError, match="expected an integer"):
        f.step("x")
    with pytest.raises(InputError, match="step 1 has shape"):
        FieldSeries([np.zeros((2, 2, 2)), np.zeros((2, 3, 2))], name="S")
    with pytest.raises(InputError, match="fewer than 2 nodes"):
        FieldSeries(np.zeros((1, 4, 4)))
    with pytest.raises(InputError, match=r"expected \(nz, ny, nx\) or \(time, nz, ny, nx\)"):
        FieldSeries(np.zeros((4, 4)))
    with pytest.raises(InputError, match="2 labels for 3 steps"):
        FieldSeries(np.zeros((3, 2, 2, 2)), times=["a", "b"])


def test_properties_share_the_nodes_and_steps():
    v = np.zeros((3, 2, 3, 4))
    f = FieldSeries(v, properties={"P": v + 1, "PORO": np.full((2, 3, 4), 0.2)})
    assert f.property_step("P", 2).mean() == 1.0
    assert f.property_step("PORO", 2).mean() == pytest.approx(0.2)  # static: every step
    with pytest.raises(InputError, match="property 'X' is not available; this field has: P, PORO"):
        f.property_step("X")
    with pytest.raises(InputError, match="does not match"):
        FieldSeries(v, properties={"P": np.zeros((3, 2, 3, 5))})
    with pytest.raises(InputError, match="2 steps, the field has 3"):
        FieldSeries(v, properties={"P": np.zeros((2, 2, 3, 4))})


def test_regular_geometry_and_checks():
    f = FieldSeries(np.zeros((3, 4, 5)), spacing=(2, 3, 4), origin=(1, 2, 3))
    assert f.bounds().tolist() == [[1, 2, 3], [9, 11, 11]]
    m = f.index_to_world()
    assert (m @ [4, 3, 2, 1])[:3].tolist() == [9, 11, 11]
    with pytest.raises(InputError, match="spacing"):
        FieldSeries(np.zeros((2, 2, 2)), spacing=(1, 0, 1))
    with pytest.raises(InputError, match="origin"):
        FieldSeries(np.zeros((2, 2, 2)), origin=(1, np.nan, 1))
    with pytest.raises(InputError, match="active: expected shape"):
        FieldSeries(np.zeros((2, 2, 2)), active=np.ones((2, 2, 3), bool))


def test_cornerpoint_field_takes_the_grids_cells_and_actnum():
    g = small_grid()
    nx, ny, nz = g.dims
    sw = np.random.default_rng(0).random((nx, ny, nz))
    f = FieldSeries([sw.T, sw.T * 0.5], grid=g, name="SWAT")
    assert f.is_cornerpoint and f.shape == (nz, ny, nx)
    assert f.active.shape == (nz, ny, nx) and not f.active[0, 0, 0] and f.active.sum() == 23
    assert f.step(0)[1, 2, 3] == np.float32(sw[3, 2, 1])
    assert np.allclose(f.bounds(), g.bounds())
    with pytest.raises(InputError, match="does not match the grid's"):
        FieldSeries(np.zeros((nz, ny, nx + 1)), grid=g)


def test_lazy_values_are_read_per_step():
    reads = []

    class Lazy:
        shape = (4, 2, 2, 2)

        def __getitem__(self, k):
            reads.append(k)
            return np.full((2, 2, 2), float(k))

    f = FieldSeries(Lazy())
    assert reads == []
    assert f.step(3).mean() == 3.0 and reads == [3]


def test_triangle_mesh_contract():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    m = TriangleMesh(v, [[0, 1, 2], [0, 1, 3]], normals=np.ones((4, 3)), values=np.arange(4))
    assert (m.n_vertices, m.n_faces) == (4, 2)
    assert m.area() == pytest.approx(1.0)
    assert m.triangles().shape == (2, 3, 3)
    with pytest.raises(InputError, match=r"faces: indices must lie in 0..3"):
        TriangleMesh(v, [[0, 1, 4]])
    with pytest.raises(InputError, match="normals"):
        TriangleMesh(v, [[0, 1, 2]], normals=np.ones((3, 3)))
    with pytest.raises(InputError, match="vertices"):
        TriangleMesh(np.zeros((4, 2)), [[0, 1, 2]])
