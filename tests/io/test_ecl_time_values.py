"""ECLIPSE readers, units and time (issue 31 item 5): report steps keep their hour, a date naming
several steps asks which, a non-unified restart file opened itself is the step shown, ECLIPSE's
undefined value (-1e20) is no value, bounds leave out inactive cells' zero corners."""

from __future__ import annotations

import numpy as np
import pytest
import resfo

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io.grids.ecl import load_case
from geoshade.io.grids.ecl_info import describe_case_parts
from geoshade.models.steps import DEFAULT_STEP, resolve_step


def _kw(name: str) -> str:
    return f"{name:<8}"


def _case(folder, g, steps, init_extra=(), unified=True, zero_inactive=False):
    """EGRID + INIT + restarts of ``g``; ``steps``: (day, month, year, hour, minute, seconds)."""
    nx, ny, nz = g.dims
    head = np.zeros(100, np.int32)
    head[:4] = (1, nx, ny, nz)
    z = np.asarray(g.zcorn, np.float32).copy()
    if zero_inactive:  # ECLIPSE writes 0 for an inactive cell's corners
        dead = np.repeat(np.repeat(np.repeat(~g.active, 2, 0), 2, 1), 2, 2)
        z[dead] = 0
    resfo.write(folder / "T.EGRID", [
        (_kw("GRIDHEAD"), head),
        (_kw("COORD"), np.asarray(g.coord).transpose(1, 0, 2).reshape(-1).astype(np.float32)),
        (_kw("ZCORN"), z.reshape(-1, order="F")),
        (_kw("ACTNUM"), np.asarray(g.actnum).reshape(-1, order="F").astype(np.int32)),
        (_kw("ENDGRID"), np.zeros(0, np.int32))])
    ih = np.zeros(411, np.int32)
    ih[8:12] = (nx, ny, nz, g.nactive)
    resfo.write(folder / "T.INIT", [(_kw("INTEHEAD"), ih), *init_extra])
    entries = []
    for n, (d, m, y, hh, mm, ss) in enumerate(steps):
        h = ih.copy()
        h[64:67], h[206:208], h[410] = (d, m, y), (hh, mm), ss * 1_000_000
        recs = [(_kw("INTEHEAD"), h), (_kw("SWAT"), np.full(g.nactive, n / 100, np.float32))]
        if unified:
            entries += [(_kw("SEQNUM"), np.array([n], np.int32)), *recs]
        else:
            resfo.write(folder / f"T.X{n:04d}", recs)
    if unified:
        resfo.write(folder / "T.UNRST", entries)
    return folder / "T.EGRID"


HOURLY = [(1, 1, 2015, h, 0, 0) for h in range(24)] + [(2, 1, 2015, 0, 0, 0)]


def test_report_steps_keep_their_hour(tmp_path):
    case = load_case(_case(tmp_path, synthetic_grid(3, 2, 2), HOURLY))
    heads = [v for k, v in resfo.read(tmp_path / "T.UNRST") if k.strip() == "INTEHEAD"]
    assert [int(h[206]) for h in heads[:24]] == list(range(24))  # the oracle: resfo's INTEHEAD
    assert case.step_dates[:2] == ["2015-01-01 00:00", "2015-01-01 01:00"]
    assert case.step_dates[-1] == "2015-01-02 00:00" and len(set(case.step_dates)) == 25
    seconds = load_case(_case(tmp_path, synthetic_grid(3, 2, 2),
                              [(1, 1, 2015, 0, 0, 0), (1, 1, 2015, 0, 0, 30)]))
    assert seconds.step_dates == ["2015-01-01 00:00:00", "2015-01-01 00:00:30"]


def test_daily_steps_stay_dates(tmp_path):
    case = load_case(_case(tmp_path, synthetic_grid(3, 2, 2),
                           [(1, m, 2015, 0, 0, 0) for m in (1, 2)]))
    assert case.step_dates == ["2015-01-01", "2015-02-01"]


def test_a_date_naming_several_steps_asks_which(tmp_path):
    case = load_case(_case(tmp_path, synthetic_grid(3, 2, 2), HOURLY))
    n, dates = len(case.steps), case.step_dates
    with pytest.raises(InputError) as ei:
        resolve_step("2015-01-01", n, dates=dates, where=case.name)
    msg = str(ei.value)
    assert "24 steps have that date (steps 0..23 at 00:00 … 23:00); give the time too, e.g. " \
        "'2015-01-01 00:00', or an index" in msg and "\n" not in msg
    assert resolve_step("2015-01-01 05:00", n, dates=dates) == 5
    assert resolve_step("2015-01-01T05:00:00", n, dates=dates) == 5
    assert resolve_step("2015-01-02", n, dates=dates) == 24  # one step that day
    with pytest.raises(InputError, match="no step at that time"):
        resolve_step("2015-01-01 05:30", n, dates=dates)


def test_a_non_unified_file_opened_itself_is_the_step_shown(tmp_path):
    _case(tmp_path, synthetic_grid(3, 2, 2), [(1, m, 2015, 0, 0, 0) for m in (1, 2, 3, 4)],
          unified=False)
    case = load_case(tmp_path / "T.X0002")
    assert len(case.steps) == 4 and case.meta["default_step"] == 2
    assert "opened T.X0002: report 2 (step 2)" in case.meta["notes"][0]
    k = resolve_step(None, 4, reports=case.meta["unrst_seqnum"],
                     default=case.meta.get("default_step", DEFAULT_STEP))
    assert k == 2 and float(np.nanmax(case.steps[k]["SWAT"])) == pytest.approx(0.02)
    assert "default_step" not in load_case(tmp_path / "T.EGRID").meta


def test_grid_options_show_the_opened_step(tmp_path):
    options = pytest.importorskip("geoshade.grid.options")
    _case(tmp_path, synthetic_grid(3, 2, 2), [(1, m, 2015, 0, 0, 0) for m in (1, 2, 3)],
          unified=False)
    case = load_case(tmp_path / "T.X0001")
    assert options.GridOptions.check_step(None, case) == 1
    assert options.GridOptions.check_step(-1, case) == 2


def test_undefined_values_are_no_value(tmp_path):
    g = synthetic_grid(3, 2, 2, seed=3)
    swl = np.full(g.nactive, 0.2, np.float32)
    swl[:3] = -1e20
    case = load_case(_case(tmp_path, g, [(1, 1, 2015, 0, 0, 0)],
                           init_extra=[(_kw("SWL"), swl)]))
    vals = case.properties["SWL"].reshape(-1, order="F")[g.active.reshape(-1, order="F")]
    assert np.isnan(vals[:3]).all() and np.allclose(vals[3:], 0.2)
    init = {k.strip(): v for k, v in resfo.read(tmp_path / "T.INIT")}
    assert float(init["SWL"][0]) == pytest.approx(-1e20)  # the file says -1e20


def test_bounds_leave_out_inactive_zero_corners(tmp_path):
    g = synthetic_grid(4, 3, 2, seed=3)
    act = np.ones(g.dims, np.uint8)
    act[0, :, 0] = 0
    g.actnum = act
    case = load_case(_case(tmp_path, g, [(1, 1, 2015, 0, 0, 0)], zero_inactive=True))
    assert case.bounds()[0, 2] == 0  # every corner: the zeros ECLIPSE wrote
    z = np.asarray(case.zcorn)[np.repeat(np.repeat(np.repeat(case.active, 2, 0), 2, 1), 2, 2)]
    d = describe_case_parts(case)
    assert d["bounds"][0][2] == pytest.approx(float(z.min()))
    assert d["bounds"][1][2] == pytest.approx(float(z.max())) and d["bounds"][0][2] > 0
