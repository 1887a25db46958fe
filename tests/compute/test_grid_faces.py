"""Face visibility: the vectorised method equals the brute-force reference."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade.compute.grid.faces as gf
from geoshade.compute.grid.faces import FaceSet, brute_force_visible_faces, visible_faces
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.models import CornerPointGrid, Fault

FIELDS = ("cells", "face", "fault", "fault_id", "neighbour_shown")


def random_faulted_grid(seed: int) -> CornerPointGrid:
    """A conforming grid with throws of random size on a random set of pillar columns, random
    vertical gaps, inactive cells and random FAULTS entries."""
    rng = np.random.default_rng(seed)
    nx, ny, nz = (int(v) for v in rng.integers(2, 7, 3))
    g = synthetic_grid(nx, ny, nz, faults=False, inactive_fraction=0.0, seed=seed, steps=0)
    z = np.array(g.zcorn, np.float64)
    cols = rng.random((nx, ny)) < 0.3
    throws = np.round(rng.uniform(-20, 20, (nx, ny)), 1) * cols
    throws[rng.random((nx, ny)) < 0.1] = 0.0  # some moved by nothing: still matching
    z += np.repeat(np.repeat(throws, 2, 0), 2, 1)[..., None]
    gaps = rng.random((nx, ny, nz)) < 0.1  # a cell's bottom lifted: a gap along k
    lift = np.repeat(np.repeat(gaps, 2, 0), 2, 1)
    z[:, :, 1::2] -= 0.5 * lift
    actnum = (rng.random((nx, ny, nz)) > 0.2).astype(np.int32)
    faults = []
    for n in range(int(rng.integers(0, 4))):  # a few named faults of random faces
        m = int(rng.integers(1, 8))
        faces = np.stack([rng.integers(0, nx, m), rng.integers(0, ny, m),
                          rng.integers(0, nz, m), rng.integers(0, 6, m)], 1)
        faults.append(Fault(f"F{n}", faces))
    return CornerPointGrid(coord=g.coord, zcorn=z.astype(np.float32), actnum=actnum,
                           faults=faults, name=f"random {seed}")


def assert_same(a: FaceSet, b: FaceSet) -> None:
    a, b = a.sorted(), b.sorted()
    for name in FIELDS:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.cells.dtype == np.int32 and a.face.dtype == np.uint8
    assert a.fault_id.dtype == np.int16 and a.fault.dtype == bool


@pytest.mark.parametrize("seed", range(12))
def test_vectorised_equals_brute_force(seed, monkeypatch):
    g = random_faulted_grid(seed)
    rng = np.random.default_rng(100 + seed)
    if seed % 3 == 0:  # several k-slabs
        monkeypatch.setattr(gf, "SLAB_CELLS", 1)
    shown = g.active & (rng.random(g.dims) > 0.15)  # a filter on top of ACTNUM
    for s in (None, shown):
        assert_same(visible_faces(g, s), brute_force_visible_faces(g, s))
    tol = 0.6  # gaps (0.5) match within the tolerance, throws (>= 0.1, mostly larger) do not
    assert_same(visible_faces(g, shown, fault_tol=tol),
                brute_force_visible_faces(g, shown, fault_tol=tol))


def test_rules_on_a_conforming_box():
    g = synthetic_grid(4, 3, 2, faults=False, inactive_fraction=0)
    fs = visible_faces(g)
    assert len(fs) == 2 * (4 * 3 + 4 * 2 + 3 * 2) and not fs.fault.any()
    assert not fs.neighbour_shown.any() and (fs.fault_id == -1).all()
    shown = np.ones(g.dims, bool)
    shown[1, 1, 0] = False  # a hole: its 5 inner neighbours show a face each
    fs = visible_faces(g, shown)
    assert len(fs) == 52 - 1 + 5
    cells, mask = fs.per_cell()
    assert len(np.unique(fs.cell_index())) == len(cells)
    assert int(sum(bin(m).count("1") for m in mask.tolist())) == len(fs)


def test_faults_flagged_and_labelled():
    g = synthetic_grid(6, 6, 3, inactive_fraction=0)
    fs = visible_faces(g)
    named = fs.fault_id >= 0
    # FA (I+ faces at i = 1) and FB (J+ faces at j = 3) are visible from both sides
    assert set(np.unique(fs.fault_id[named]).tolist()) == {0, 1}
    fa = fs.fault_id == 0
    assert set(fs.face[fa].tolist()) == {0, 3}
    assert fs.fault[fa].all() and fs.neighbour_shown[fa].all()
    assert set(fs.cells[fa & (fs.face == 0), 0].tolist()) == {1}
    assert set(fs.cells[fa & (fs.face == 3), 0].tolist()) == {2}


def test_shown_shape_is_checked():
    g = synthetic_grid(3, 2, 2)
    with pytest.raises(InputError, match=r"shown must have the grid shape \(3, 2, 2\)"):
        visible_faces(g, np.ones((2, 2, 2), bool))


def test_random_grids_exercise_every_rule():
    total = {"fault": 0, "named": 0, "inactive_side": 0, "boundary": 0}
    for seed in range(12):
        g = random_faulted_grid(seed)
        fs = visible_faces(g)
        nb = fs.cells + gf.FACE_OFFSETS[fs.face]
        inside = np.all((nb >= 0) & (nb < g.dims), axis=1)
        total["fault"] += int((fs.fault & fs.neighbour_shown).sum())
        total["named"] += int((fs.fault_id >= 0).sum())
        total["inactive_side"] += int((inside & ~fs.neighbour_shown).sum())
        total["boundary"] += int((~inside).sum())
    assert min(total.values()) > 10, total
