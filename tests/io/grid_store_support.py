"""Test helpers of the grid-store tests: an ingest interrupted after some slabs."""

from __future__ import annotations

import pytest

from geoshade.io.stores import grid_store


class StopError(Exception):
    """Raised by the patched slab hook: the ingest is interrupted there."""


def interrupted_ingest(monkeypatch, case, out, after: int = 2, **kw) -> None:
    """Run ``ingest_grid(case, out, **kw)`` until ``after`` slabs are written, then stop it (as
    a killed process would leave it); the hook is reset, so the next ingest runs through."""
    def stop(done):
        if done == after:
            raise StopError

    monkeypatch.setattr(grid_store, "_after_slab", stop)
    with pytest.raises(StopError):
        grid_store.ingest_grid(case, out, **kw)
    monkeypatch.setattr(grid_store, "_after_slab", None)
