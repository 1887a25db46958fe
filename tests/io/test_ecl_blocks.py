"""The memory-mapped reader of unformatted ECLIPSE records against resfo, and the benchmark's
independent case writer (benchmarks/grid_cases.py) against resfo and xtgeo."""

from pathlib import Path

import numpy as np
import pytest
import resfo

from geoshade.io.grids.ecl_records import RecordError, scan
from tests.grid_cases import grid_cases as benchmark_cases


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    grid_cases = benchmark_cases()
    folder = tmp_path_factory.mktemp("case")
    paths = grid_cases.write_case(folder, 37, 29, 6, steps=3)
    paths["GRDECL"] = grid_cases.write_grdecl_case(folder / "BIG.GRDECL", 37, 29, 6)
    return paths


def test_records_read_as_resfo_reads_them_whole_and_in_ranges(case):
    rng = np.random.default_rng(0)
    for kind in ("EGRID", "INIT", "UNRST"):
        ref = [np.asarray(v) for _, v in resfo.read(case[kind])]
        recs = list(scan(case[kind]))
        assert len(recs) == len(ref)
        for r, v in zip(recs, ref, strict=True):
            if r.type not in ("INTE", "REAL", "DOUB") or not r.length:
                continue
            a = r.read()
            assert a.dtype.isnative and np.array_equal(a, v), r.keyword
            for _ in range(25):  # ranges cutting blocks anywhere
                lo = int(rng.integers(0, r.length))
                hi = int(rng.integers(lo, r.length + 1))
                assert np.array_equal(r.read_range(lo, hi - lo), v[lo:hi]), (r.keyword, lo, hi)


def test_a_damaged_block_marker_is_one_clean_line(case, tmp_path):
    data = bytearray(Path(case["EGRID"]).read_bytes())
    z = next(r for r in scan(case["EGRID"]) if r.keyword == "ZCORN")
    at = z.start + 24 + 2 * 4008  # the opening marker of block 2
    data[at:at + 4] = (123).to_bytes(4, "big")
    bad = tmp_path / "BAD.EGRID"
    bad.write_bytes(bytes(data))
    rec = next(r for r in scan(bad) if r.keyword == "ZCORN")
    with pytest.raises(RecordError, match=r"ZCORN: damaged record .*block 2"):
        rec.read()


def test_the_generated_case_reads_the_same_in_geoshade_xtgeo_and_from_grdecl(case):
    import geoshade

    g = geoshade.load(case["EGRID"])
    assert g.dims == (37, 29, 6) and 0 < g.ncells - g.nactive < 0.1 * g.ncells
    # vertical pillars on a 50 m grid: x along i, y along j
    i, j = np.meshgrid(np.arange(38), np.arange(30), indexing="ij")
    assert np.array_equal(g.coord[..., 0], 50.0 * i) and np.array_equal(g.coord[..., 1], 50.0 * j)
    assert np.array_equal(g.coord[..., 3], 50.0 * i)
    assert len(g.steps) == 3 and sorted(g.properties) == ["PERMX", "PORO"]
    xtgeo = pytest.importorskip("xtgeo")
    x = xtgeo.grid_from_file(case["EGRID"])
    assert (x.ncol, x.nrow, x.nlay) == g.dims and x.nactive == g.nactive
    t = geoshade.load(case["GRDECL"])
    assert np.array_equal(t.zcorn, g.zcorn) and np.array_equal(t.actnum, g.actnum)
    for name in ("PORO", "PERMX"):
        assert np.array_equal(t.properties[name][t.active], g.properties[name][g.active])


def test_report_steps_cache_holds_no_more_than_its_bytes(case, monkeypatch):
    import geoshade
    from geoshade.io.grids.ecl_restart import UnrstIndex

    g = geoshade.load(case["EGRID"])
    r = UnrstIndex(case["UNRST"], g)
    one = r(0, "SWAT").nbytes
    monkeypatch.setattr(UnrstIndex, "cache_bytes", 2 * one)
    for k in range(3):
        a = r.cached(k, "SWAT")
        assert np.array_equal(a, r(k, "SWAT"), equal_nan=True)
        assert sum(v.nbytes for v in r._cache.values()) <= 2 * one
    assert len(r._cache) == 2
    monkeypatch.setattr(UnrstIndex, "cache_bytes", one // 2)
    r2 = UnrstIndex(case["UNRST"], g)
    r2.cached(1, "SWAT")
    assert not r2.__dict__.get("_cache")  # a step larger than the budget is not kept
