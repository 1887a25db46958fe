"""Issue 30 ("the iso panel has no colour-by choice unless the server was started with one"):
a field opened without ``color_by`` offers every quantity its file holds, and choosing one on
the open View reads it and draws what a View opened with it draws."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geoshade
from geoshade.compute.mesh.displacement import displacement_field
from geoshade.io.fields import load_field
from geoshade.viewer.controls import controls

pytestmark = pytest.mark.gl
REEK = Path("/work/shared/data/reek_cornerpoint/opm_flow_run/2_R001_REEK-0.EGRID")


@pytest.fixture
def npz(tmp_path):
    f = displacement_field((24, 20, 16), steps=3, seed=1)
    path = tmp_path / "front.npz"
    np.savez(path, SWAT=np.asarray(f.values), PRESSURE=np.asarray(f.properties["PRESSURE"]))
    return path


def _choices(view) -> list:
    spec = next(c for g in controls(view) for c in g["controls"] if c["name"] == "color_by")
    return spec["choices"]


def test_choose_a_quantity_the_view_did_not_read(ctx, npz):
    field = load_field(npz, keyword="SWAT")
    assert field.properties == {} and field.meta["quantities"] == ["PRESSURE"]
    with geoshade.view(field, level=0.5, size=(240, 180), ctx=ctx, annotations=True) as v:
        assert _choices(v) == [None, "PRESSURE"]
        v.update(color_by="PRESSURE")
        img, st = v.draw()
    with geoshade.view(load_field(npz, keyword="SWAT", color_by="PRESSURE"), level=0.5,
                       color_by="PRESSURE", size=(240, 180), ctx=ctx, annotations=True) as w:
        want, _ = w.draw()
    assert st["color_by"] == "PRESSURE" and np.array_equal(img, want)


@pytest.mark.skipif(not REEK.exists(), reason="the Reek OPM Flow run is absent")
def test_an_eclipse_case_offers_its_restart_keywords(ctx):
    field = load_field(REEK, keyword="SWAT")
    with geoshade.view(field, level=0.5, size=(200, 150), ctx=ctx) as v:
        names = _choices(v)
        assert {"PRESSURE", "SGAS"} <= set(names) and "SWAT" not in names
        v.update(color_by="pressure")
        _, st = v.draw()
    assert st["color_by"] == "PRESSURE"
