"""Issue 33 item 5: a pick's cell as a table of every property at the shown step, and a
property of the cell over every report step (plotted with its unit), against numpy and, on the
Reek OPM run, resfo's records."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.grid.history import cell_history, cell_table, history_plot

REEK = Path("/work/shared/data/reek_cornerpoint/opm_flow_run/2_R001_REEK-0")


def test_table_and_history_are_the_cells_values():
    g = synthetic_grid(6, 5, 3, seed=2)
    rows = {r["name"]: r for r in cell_table(g, (2, 3, 1), step=2)}
    assert rows["PORO"]["value"] == pytest.approx(float(g.properties["PORO"][2, 3, 1]))
    assert rows["SWAT"]["value"] == pytest.approx(float(g.steps[2]["SWAT"][2, 3, 1]))
    assert rows["SWAT"]["step"] == 2 and rows["PORO"]["step"] is None
    assert rows["SOIL"]["value"] == pytest.approx(1 - float(g.steps[2]["SWAT"][2, 3, 1]),
                                                  abs=1e-6)
    h = cell_history(g, (2, 3, 1), "swat")
    assert h["values"] == pytest.approx([float(s["SWAT"][2, 3, 1]) for s in g.steps])
    with pytest.raises(InputError, match=r"^history: PORO does not change"):
        cell_history(g, (0, 0, 0), "PORO")
    with pytest.raises(InputError, match=r"^cell: I=7 J=1 K=1 is outside"):
        cell_table(g, (6, 0, 0))


def test_history_plot(tmp_path):
    g = synthetic_grid(6, 5, 3, seed=2)
    img = history_plot(cell_history(g, (2, 3, 1), "SWAT"), size=(400, 240), cursor=1)
    assert img.shape == (240, 400, 4) and len(np.unique(img.reshape(-1, 4), axis=0)) > 10
    history_plot(cell_history(g, (2, 3, 1), "SWAT"), tmp_path / "h.png")
    assert (tmp_path / "h.png").stat().st_size > 1000


@pytest.mark.skipif(not REEK.with_suffix(".UNRST").exists(), reason="Reek OPM run absent")
def test_reek_cell_history_is_resfos():
    import resfo

    g = geoshade.load(REEK.with_suffix(".EGRID"))
    act = np.asarray(g.active, bool)
    ijk = tuple(int(v[0]) for v in np.nonzero(act))   # the first active cell (F order)
    n = int(np.ravel_multi_index(ijk, g.dims, order="F"))
    index = int(np.count_nonzero(act.ravel(order="F")[:n]))   # its place among active cells
    pressure = [float(np.asarray(v)[index]) for k, v in resfo.read(REEK.with_suffix(".UNRST"))
                if k.strip() == "PRESSURE"]
    h = cell_history(g, ijk, "PRESSURE")
    assert h["values"] == pytest.approx(pressure, rel=1e-6) and h["unit"] == "bar"
    assert h["dates"][0].startswith("2000-01-01")
