"""Issue 30: for every option of every part, ``update(x)`` then draw ≡ a View opened with ``x``
(pixel for pixel), and an option fixed at opening is refused by ``update`` in one line. The
cases come from the options' declarations (:mod:`geoshade.testing.parity`)."""

from __future__ import annotations

import pytest

from geoshade.testing.parity import check_parity, parity_cases

CASES = [c for kind in ("core", "grid", "iso", "stacks") for c in parity_cases(kind)]

pytestmark = [pytest.mark.gl, pytest.mark.filterwarnings("ignore")]


def test_every_part_has_many_cases():
    for kind in ("core", "grid", "iso", "stacks"):
        assert len([c for c in CASES if c.kind == kind]) >= 15, kind


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_update_draws_what_opening_with_the_option_draws(ctx, case):
    check_parity(case, ctx)
