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


def _lgr_records(egrid, name, keyword, step):
    """resfo: the ``keyword`` record of LGR ``name`` (or of the global grid: ``name`` None) in
    report ``step`` of the UNRST."""
    report, in_lgr, out = -1, None, []
    for kw, arr in resfo.read(egrid.with_suffix(".UNRST")):
        kw = kw.strip()
        if kw == "SEQNUM":
            report += 1
        elif kw == "LGR":
            text = arr[0].decode() if isinstance(arr[0], bytes) else str(arr[0])
            in_lgr = text.strip()
        elif kw == "ENDLGR":
            in_lgr = None
        elif kw == keyword and report == step and in_lgr == name:
            out.append(np.asarray(arr, np.float64))
    assert out, f"no {keyword} of {name or 'the global grid'} at report {step}"
    return out[0]


def _nodes(cells, active, dims):
    """(nz, ny, nx) float64 of one value per active cell (F order), NaN elsewhere."""
    flat = np.full(int(np.prod(dims)), np.nan)
    flat[np.asarray(active, bool).ravel(order="F")] = cells
    return flat.reshape(dims, order="F").T


def test_iso_over_refinements_is_each_grid_marched_on_its_own_cells(lgr, ctx):
    """Issue 31 item 1 (iso over LGRs): the global cells marched with LGR2's hosts taken out,
    LGR2's own PRESSURE (resfo's LGR records) marched on its 4×4×4 cells, at one level: each
    surface has the triangles this project's table gives on numpy's arrays (scikit-image's
    lorensen on the negated field, case for case), the picture's count is their sum, the mesh
    holds them all, a pick names LGR2 and its host; LGR1 (one cell thick) keeps its hosts in
    the global surface and says so."""
    from geoshade.iso import IsoView
    from tests.compute.test_marching_cubes_open import skimage_masked, whole_cell_count

    g = geoshade.load(lgr)
    step, level = 6, 5000.0
    r2 = next(r for r in g.refinements if r.name == "LGR2")
    lgr_p = _nodes(_lgr_records(lgr, "LGR2", "PRESSURE", step), r2.grid.active, r2.dims)
    host2 = g.host_cells(["LGR2"])
    glob_p = _nodes(_lgr_records(lgr, None, "PRESSURE", step), g.active, g.dims)
    glob_act = (np.asarray(g.active, bool) & ~host2).T
    want_lgr, whole = whole_cell_count(lgr_p, np.ones(lgr_p.shape, bool), level)
    assert want_lgr > 0, "the level crosses LGR2"
    assert len(skimage_masked(-lgr_p, np.ones(lgr_p.shape, bool), -level, whole)[1]) == want_lgr
    want_glob, _ = whole_cell_count(glob_p, glob_act, level)
    with IsoView(g, keyword="PRESSURE", level=level, step=step, size=SIZE, ctx=ctx) as v:
        img, st = v.draw()
        by = {r["name"]: r for r in st["refinements"]}
        assert by["LGR2"]["shown"] and by["LGR2"]["triangles"] == want_lgr
        assert not by["LGR1"]["shown"] and "one cell thick" in by["LGR1"]["why"]
        assert st["triangles"] == want_glob + want_lgr
        assert v.mesh().n_faces == st["triangles"]
        hits = [h for x in range(0, SIZE[0], 4) for y in range(0, SIZE[1], 4)
                if (h := v.pick(x, y)) is not None and h.label.startswith("LGR2")]
        assert hits and "(host I=" in hits[0].label and ("LGR", "LGR2") in hits[0].extra
        # a new level reaches the refinement's surface too (update == open)
        v.update(level=5050.0)
        _, st2 = v.draw()
        assert {r["name"]: r for r in st2["refinements"]}["LGR2"]["triangles"] == \
            whole_cell_count(lgr_p, np.ones(lgr_p.shape, bool), 5050.0)[0]
    # without LGR2's surface the picture is another one (its triangles are drawn)
    bare = geoshade.load(lgr)
    bare.refinements = []
    with IsoView(bare, keyword="PRESSURE", level=level, step=step, size=SIZE, ctx=ctx) as v:
        full, st3 = v.draw()
    assert st3["triangles"] == whole_cell_count(glob_p, np.asarray(g.active, bool).T, level)[0]
    assert not np.array_equal(img, full)
