"""The isosurface of a case can be coloured by every property of the case: static ones, other
report-step ones and derived SOIL, read only when shown."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid


def test_every_property_of_the_case_is_offered_and_drawn(ctx):
    g = synthetic_grid(10, 8, 4, faults=True, seed=2)
    with geoshade.view(g, as_="iso", keyword="swat", level=0.5, size=(160, 120),
                       ctx=ctx) as v:
        names = v.color_names()
        assert set(names) == {"PORO", "PERMX", "NTG", "FIPNUM", "SOIL"}
        imgs = {}
        for name in (None, "PORO", "SOIL"):
            v.update(color_by=name)
            img, st = v.draw()
            assert st["color_by"] == name
            imgs[name] = img
        soil = v.field.property_step("SOIL", v.step)
        swat = v.field.step(v.step)
        np.testing.assert_allclose(soil, 1 - swat, atol=1e-6)
    assert not np.array_equal(imgs[None], imgs["PORO"])
    assert not np.array_equal(imgs["PORO"], imgs["SOIL"])


def test_properties_are_read_only_when_shown():
    """Opening reads no report step of the other properties."""
    from geoshade.iso.api import field_of

    g = synthetic_grid(6, 5, 3, seed=1)
    reads = []

    class Counting(dict):
        def __getitem__(self, name):
            reads.append(name)
            return super().__getitem__(name)

    g.steps = [Counting(s) for s in g.steps]
    f = field_of(g, "SWAT")
    assert reads == [] and "SOIL" in f.properties
    f.property_step("SOIL", 2)
    assert reads == ["SWAT"]


@pytest.mark.data
def test_reek_run_offers_every_keyword(ctx, shared_data):
    egrid = shared_data / "reek_cornerpoint/opm_flow_run/2_R001_REEK-0.EGRID"
    grid = geoshade.load(egrid)
    with geoshade.view(grid, as_="iso", keyword="SWAT", level=0.5, size=(160, 120),
                       ctx=ctx) as v:
        names = set(v.color_names())
        assert {"PRESSURE", "SGAS", "SOIL", "PORO", "PERMX"} <= names
        v.update(color_by="sgas")
        _, st = v.draw()
    assert st["color_by"] == "SGAS" and st["triangles"] > 0
