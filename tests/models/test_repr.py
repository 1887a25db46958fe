"""Short reprs of every model (like xarray's): sizes, bounds, properties, steps; no arrays."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.models import CornerPointGrid, FieldSeries, VoxelVolume, WellPath
from geoshade.models.field import TriangleMesh
from geoshade.models.wells import DeckWell, SimWell, SimWells, Trajectory


def _short(obj, limit=900) -> str:
    text = repr(obj)
    assert len(text) <= limit, (type(obj).__name__, len(text))
    assert "array(" not in text and "[[" not in text and "..." not in text
    assert repr(obj) == str(obj) or str(obj).startswith("<")
    return text


def test_grid_repr_is_short_and_says_what_it_holds():
    g = synthetic_grid(60, 50, 20)
    text = _short(g)
    assert text.splitlines()[0] == f"<CornerPointGrid {g.name!r}>"
    assert "nx: 60, ny: 50, nz: 20 (60,000 cells" in text
    b = g.bounds()
    assert f"depth {b[0, 2]:.6g}–{b[1, 2]:.6g}" in text
    for name in list(g.properties)[:3]:
        assert name in text
    assert f"Steps:       {len(g.steps)} " in text and "SWAT" in text


def test_grid_repr_of_a_huge_grid_reads_no_corner_depths():
    class Lazy:   # a store's ZCORN stand-in: reading it fails the test
        shape, dtype, ndim, size = (2000, 2000, 200), np.dtype(np.float32), 3, 8 * 10**8

        def __array__(self, *a, **k):
            raise AssertionError("ZCORN read for a repr")

    g = synthetic_grid(4, 3, 2)
    g.zcorn = Lazy()
    g.meta["nactive"] = 24
    assert "Pillars:" in _short(g)


def test_volume_field_mesh_wells_stacks():
    v = VoxelVolume(np.zeros((4, 5, 6), ">i2"), spacing=(0.5, 0.5, 1), unit="mm", name="v.raw")
    text = _short(v)
    assert "x: 6, y: 5, z: 4 (120 voxels)" in text and "int16 (big-endian)" in text
    assert "x 0–3, y 0–2.5, z 0–4 mm" in text
    f = FieldSeries(np.zeros((2, 3, 3, 3), np.float32), name="SWAT", unit="fraction",
                    times=["2000-01-01", "2000-02-01"])
    assert "Steps:       2 (2000-01-01 … 2000-02-01)" in _short(f)
    m = TriangleMesh(np.eye(3), [[0, 1, 2]], values=np.ones(3, np.float32), name="iso")
    assert "Triangles:  1 (3 vertices)" in _short(m) and "values" in repr(m)
    w = WellPath("A", [[0, 0, 10], [1, 0, 20]], markers=[[0, 0, 15]])
    assert _short(w) == "WellPath('A', 2 points, x 0–1, y 0–0, depth 10–20, 1 markers)"
    t = Trajectory("T", np.ones((500, 3)), md=np.arange(500.0))
    assert _short(t).endswith("md 0–499)")
    d = DeckWell("WI_1", [[0, 0, 900], [0, 0, 1000]], [[0, 0, 1000]], [[0, 0, 3]],
                 type="water injector", cell_open=[False])
    assert "water injector" in _short(d) and "1 completions (0 open)" in repr(d)
    sw = SimWells(4, 5, "2000-05-01", tuple(
        SimWell(f"P{n}", "producer", n % 2 == 0, (n, 0), [[n, 0, 0]], [True]) for n in range(30)))
    text = _short(sw)
    assert text.splitlines()[0] == "<SimWells step 4 (report 5, 2000-05-01)>"
    assert "30 (15 open): P0, P1" in text and "(+22)" in text and "30 producer" in text
    assert "SimWell('P0', producer, open, head (0, 0), 1 completions (1 open))" == \
        _short(sw.wells[0])


def test_real_deck_grid(shared_data):
    from geoshade.io.grids.deck import read_deck

    deck = shared_data / "reek_cornerpoint" / "model" / "2_R001_REEK-0.DATA"
    if not deck.is_file():
        pytest.skip("Reek deck is absent")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = read_deck(deck)
    assert isinstance(g, CornerPointGrid)
    text = _short(g)
    assert "35,840 cells, 35,820 active" in text and "Faults:      6: F1" in text
    assert "OP_1" in text


def test_stack_model_repr():
    from geoshade.models import StackModel

    m = StackModel(np.arange(0, 2 * 300 + 1, 2), np.tile([0.0, 4.0], 300),
                   np.tile([1, 2], 300), (20, 15), 9, spacing=(100, 100, 0.5),
                   origin=(1000, 2000, -5), name="geotop")
    text = _short(m)
    assert text.splitlines()[0] == "<StackModel 'geotop'>"
    assert "20×15 (300, 0 from boreholes), 9 levels" in text
    assert "Intervals:  600 (at most 2 a column)" in text
    assert "x 1000–3000, y 2000–3500, z -5–-0.5" in text
