"""Cell filters: the mask equals the numpy expression; bad expressions fail in one line."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.grid.filters import cell_filter
from geoshade.errors import InputError


@pytest.fixture
def props():
    rng = np.random.default_rng(0)
    shape = (6, 5, 4)
    poro = rng.uniform(0, 0.35, shape).astype(np.float32)
    poro[rng.random(shape) < 0.1] = np.nan  # inactive cells
    permx = (10 ** rng.uniform(-1, 3.5, shape)).astype(np.float32)
    return {"PORO": np.asfortranarray(poro), "PERMX": permx,
            "FIPNUM": rng.integers(1, 4, shape).astype(np.int32)}


def test_masks_equal_numpy(props):
    p, k, f = props["PORO"], props["PERMX"], props["FIPNUM"]
    with np.errstate(invalid="ignore"):
        cases = {
            "PORO > 0.2 and PERMX > 100": (p > 0.2) & (k > 100),
            "PORO > 0.2 or not PERMX > 100": (p > 0.2) | ~(k > 100),
            "0.1 < PORO <= 0.3": (p > 0.1) & (p <= 0.3),
            "log10(PERMX) >= 2 and FIPNUM == 2": (np.log10(k) >= 2) & (f == 2),
            "abs(PORO - 0.2) < 0.05": np.abs(p - 0.2) < 0.05,
            "PORO * 2 + 1 > PERMX / 1000 - -1": p * 2 + 1 > k / 1000 - -1,
            "(PORO > 0.1) and (FIPNUM != 3 or PERMX < 10)": (p > 0.1) & ((f != 3) | (k < 10)),
            "poro > 0.25": p > 0.25,  # case-insensitive when unambiguous
            "1 < 2": np.ones(p.shape, bool),
        }
    for expr, want in cases.items():
        got = cell_filter(expr, props, p.shape)
        assert got.dtype == bool and got.shape == p.shape and got.flags.f_contiguous
        assert np.array_equal(got, want), expr
    nan = np.isnan(p)
    assert not cell_filter("PORO >= 0 or PORO < 0", props, p.shape)[nan].any()  # NaN fails


@pytest.mark.parametrize("expr, msg", [
    ("PORO > 0.2 and PERMY > 1", "unknown property 'PERMY'; available: FIPNUM, PERMX, PORO"),
    ("PORO >", "not a valid expression"),
    ("__import__('os').system('x')", "is not allowed"),
    ("PORO.max() > 1", "is not allowed"),
    ("PORO", "must be a condition"),
    ("PORO ** 2 > 1", "operator Pow is not allowed"),
    ("PORO in [1]", "is not allowed"),
    ("(PORO > 1) + 1 > 0", "is a condition where a number is expected"),
    ("PORO > 'a'", "is not a number"),
    ("", "expected an expression"),
])
def test_bad_expressions(props, expr, msg):
    with pytest.raises(InputError) as ei:
        cell_filter(expr, props, (6, 5, 4))
    text = str(ei.value)
    assert msg in text and "\n" not in text
    if expr:
        assert repr(expr) in text
