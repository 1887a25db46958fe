"""Issue 31 item 1: local grid refinements drawn as ResInsight draws them, on OPM Flow's own
CARFIN output: the host cells hidden, the refined cells inside them coloured by their own
values (resfo's LGR restart arrays), on the parent's colour scale; a pick names the LGR, its
local I, J, K and its host; a slice and a filter apply to them; the stats list them."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from tests.acceptance import ecl_cases
from tests.acceptance.make_cases import CaseUnavailableError

pytestmark = pytest.mark.gl
resfo = pytest.importorskip("resfo")
SIZE = (480, 360)


@pytest.fixture(scope="module")
def lgr():
    try:
        return ecl_cases.spe1_lgr()
    except CaseUnavailableError as err:
        pytest.skip(str(err))


def test_hosts_hidden_refined_cells_drawn_and_picked(lgr, ctx):
    g = geoshade.load(lgr)
    hosts = g.host_cells()
    assert int(hosts.sum()) == 12   # LGR1's 2×2×1 and LGR2's 2×2×2 host cells
    with geoshade.view(g, property="SWAT", view="top", ortho=True, size=SIZE, exaggeration=20,
                       ctx=ctx) as v:
        img, st = v.draw()
        assert st["shown_cells"] == int(np.count_nonzero(np.asarray(g.active, bool)
                                                         & ~hosts)) == 288
        assert [r["name"] for r in st["refinements"]] == ["LGR1", "LGR2"]
        assert all(r["shown"] for r in st["refinements"])
        hits = [h for x in range(0, SIZE[0], 6) for y in range(0, SIZE[1], 6)
                if (h := v.pick(x, y)) is not None and h.label.startswith("LGR1")]
        assert hits, "no pixel shows LGR1's refined cells"
        h = hits[0]
        i, j, k = h.index
        # the value is LGR1's own SWAT at the shown step (resfo: the LGR's records)
        swat = _lgr_swat(lgr, "LGR1", st["step"])
        r = next(x for x in g.refinements if x.name == "LGR1")
        active = np.asarray(r.grid.active, bool).reshape(-1, order="F")
        flat = np.full(active.size, np.nan)
        flat[active] = swat
        assert h.value == pytest.approx(flat.reshape(r.dims, order="F")[i, j, k], rel=1e-6)
        assert "(host I=" in h.text() and ("LGR", "LGR1") in h.extra
    # without the refinements' cells the picture has holes where the hosts were
    bare = geoshade.load(lgr)
    bare.refinements = []
    with geoshade.view(bare, property="SWAT", view="top", ortho=True, size=SIZE,
                       exaggeration=20, ctx=ctx) as v:
        full, _ = v.draw()
    assert not np.array_equal(img, full)


def test_a_slice_keeps_the_refinements_whose_hosts_are_in_it(lgr, ctx):
    g = geoshade.load(lgr)
    with geoshade.view(g, property="PORO", slice="k=0", size=SIZE, ctx=ctx) as v:
        _, st = v.draw()
    shown = {r["name"]: r["shown"] for r in st["refinements"]}
    assert shown == {"LGR1": True, "LGR2": False}   # LGR2's hosts are in layers 2..3


def _lgr_swat(egrid, name, step):
    """resfo: the SWAT record of LGR ``name`` in report ``step``'s LGR section of the UNRST."""
    unrst = egrid.with_suffix(".UNRST")
    report, in_lgr, out = -1, None, []
    for kw, arr in resfo.read(unrst):
        kw = kw.strip()
        if kw == "SEQNUM":
            report += 1
        elif kw == "LGR":
            text = arr[0].decode() if isinstance(arr[0], bytes) else str(arr[0])
            in_lgr = text.strip() if report == step else None
        elif kw == "ENDLGR":
            in_lgr = None
        elif kw == "SWAT" and in_lgr == name:
            out.append(np.asarray(arr, np.float64))
    assert out, f"no SWAT of {name} at report {step}"
    return out[0]
