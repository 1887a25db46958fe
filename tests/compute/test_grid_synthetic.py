"""The synthetic corner-point grid: deterministic, realistic features."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.grid.geometry import is_conforming
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError


def test_deterministic_and_featured():
    a, b = synthetic_grid(12, 9, 5, seed=3), synthetic_grid(12, 9, 5, seed=3)
    for name in ("coord", "zcorn", "actnum"):
        assert np.array_equal(getattr(a, name), getattr(b, name))
    assert not np.array_equal(a.zcorn, synthetic_grid(12, 9, 5, seed=4).zcorn)
    assert a.ncells - a.nactive == round(0.05 * a.ncells)
    assert not is_conforming(a) and is_conforming(synthetic_grid(12, 9, 5, faults=False))
    c = np.asarray(a.coord)
    assert np.any(c[..., 0] != c[..., 3])  # sloping pillars
    assert (np.diff(a.zcorn.astype(np.float64), axis=2) >= 0).all()
    assert len(a.steps) == len(a.step_dates) == 4
    sw = [np.nanmean(s["SWAT"]) for s in a.steps]
    assert sw == sorted(sw) and sw[-1] > sw[0]  # the front advances
    assert [f.name for f in a.faults] == ["FA", "FB"]
    assert a.zcorn.flags.f_contiguous and a.properties["PORO"].flags.f_contiguous


def test_bad_arguments():
    with pytest.raises(InputError):
        synthetic_grid(0, 2, 2)
    with pytest.raises(InputError):
        synthetic_grid(2, 2, 2, inactive_fraction=1.5)
