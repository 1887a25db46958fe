"""geoshade.progress: the protocol's no-op, resolve, scaled, stages and Counter."""

from __future__ import annotations

import pytest

from geoshade import progress as gp


def test_null_and_resolve():
    assert gp.NULL(3, 4) is None
    assert gp.resolve(None) is gp.NULL
    f = lambda d, t: None  # noqa: E731
    assert gp.resolve(f) is f
    with pytest.raises(TypeError, match="callable progress"):
        gp.resolve(0)


def test_scaled_clamps_and_ends_at_stop():
    calls = []
    p = gp.scaled(lambda d, t: calls.append((d, t)), 10, 30, 50)
    p(-1, 4)
    p(9, 4)  # more than its total: clamped
    p(0, 0)  # an empty stage is complete
    assert calls == [(10, 50), (30, 50), (30, 50)]
    with pytest.raises(ValueError):
        gp.scaled(lambda d, t: None, 5, 4, 10)


def test_stages_cover_the_total_in_order():
    calls = []
    a, b, c = gp.stages(lambda d, t: calls.append((d, t)), 50, 0, 50)
    for k in range(1, 6):
        a(k, 5)
    b(1, 1)
    for k in range(1, 11):
        c(k, 10)
    dones = [d for d, _ in calls]
    assert dones == sorted(dones) and calls[-1] == (100, 100)
    assert {t for _, t in calls} == {100}
    with pytest.raises(ValueError):
        gp.stages(lambda d, t: None)


def test_counter_grows():
    calls = []
    c = gp.Counter(lambda d, t: calls.append((d, t)), 5)
    c.add(5)
    c.grow(5)
    c.add(5)
    assert calls == [(5, 5), (10, 10)]
