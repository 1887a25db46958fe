"""One unit source for every part (issue 24, item 2): the case's unit system (INTEHEAD item 3 of
the INIT, or the deck's RUNSPEC) decides the colour bar, the pick read-out and the stats JSON of
the grid and the iso views, the xarray export and a sector's INIT.

Cases are written with resfo (EGRID/INIT/UNRST) for each of METRIC, FIELD, LAB and PVT-M; the
expected units are the ECLIPSE manual's (PRESSURE: bar, psia, atm, atm).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import resfo

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid

#: unit system -> (INTEHEAD code, GRIDUNIT, PRESSURE unit, RS unit, length symbol)
SYSTEMS = {
    "METRIC": (1, "METRES", "bar", "sm³/sm³", "m"),
    "FIELD": (2, "FEET", "psia", "Mscf/stb", "ft"),
    "LAB": (3, "CM", "atm", "scc/scc", "cm"),
    "PVT-M": (4, "METRES", "atm", "sm³/sm³", "m"),
}
SIZE = (320, 240)


def _kw(name: str) -> str:
    return f"{name:<8}"


def write_case(folder: Path, system: str, nsteps: int = 3) -> Path:
    """CASE.EGRID/INIT/UNRST of a small grid in ``system``; the EGRID's path."""
    code, gridunit, *_ = SYSTEMS[system]
    g = synthetic_grid(6, 5, 3, seed=3)
    nx, ny, nz = g.dims
    folder.mkdir(parents=True, exist_ok=True)
    gh = np.zeros(100, np.int32)
    gh[:4] = (1, nx, ny, nz)
    act = g.active.reshape(-1, order="F")
    resfo.write(folder / "CASE.EGRID", [
        (_kw("FILEHEAD"), np.zeros(100, np.int32)),
        (_kw("GRIDUNIT"), np.array([gridunit.ljust(8).encode(), b"        "])),
        (_kw("GRIDHEAD"), gh),
        (_kw("COORD"), np.asarray(g.coord).transpose(1, 0, 2).reshape(-1).astype(np.float32)),
        (_kw("ZCORN"), np.asarray(g.zcorn).reshape(-1, order="F").astype(np.float32)),
        (_kw("ACTNUM"), np.asarray(g.actnum).reshape(-1, order="F").astype(np.int32)),
        (_kw("ENDGRID"), np.zeros(0, np.int32))])

    def head(step):
        ih = np.zeros(411, np.int32)
        ih[2] = code
        ih[8:12] = (nx, ny, nz, g.nactive)
        ih[64:67] = (1, step + 1, 2001)
        return ih

    poro = g.properties["PORO"].reshape(-1, order="F")[act].astype(np.float32)
    resfo.write(folder / "CASE.INIT", [
        (_kw("INTEHEAD"), head(0)), (_kw("LOGIHEAD"), np.zeros(121, np.int32)),
        (_kw("DOUBHEAD"), np.zeros(229, np.float64)), (_kw("PORO"), poro),
        (_kw("PERMX"), np.geomspace(1, 1000, g.nactive).astype(np.float32))])
    ramp = np.linspace(0, 1, g.nactive, dtype=np.float32)
    steps = []
    for k in range(nsteps):
        steps += [(_kw("SEQNUM"), np.array([k], np.int32)), (_kw("INTEHEAD"), head(k)),
                  (_kw("LOGIHEAD"), np.zeros(121, np.int32)),
                  (_kw("DOUBHEAD"), np.zeros(229, np.float64)),
                  (_kw("STARTSOL"), resfo.MESS),
                  (_kw("PRESSURE"), (3000 + 100 * k + 500 * ramp).astype(np.float32)),
                  (_kw("SWAT"), (ramp * (k + 1) / (nsteps + 1)).astype(np.float32)),
                  (_kw("RS"), (0.5 + ramp).astype(np.float32)),
                  (_kw("ENDSOL"), resfo.MESS)]
    resfo.write(folder / "CASE.UNRST", steps)
    return folder / "CASE.EGRID"


def _label(st) -> str:
    return st["annotations"]["colorbar"]["label"]


def _centre_pick(view):
    """A pick on a pixel the model covers (the bare picture differs from its background)."""
    img, _ = view.draw()
    covered = np.any(img[..., :3] != img[0, 0, :3], axis=-1)
    ys, xs = np.nonzero(covered)
    order = np.argsort(np.hypot(xs - xs.mean(), ys - ys.mean()))
    for n in order[:200:5]:
        p = view.pick(float(xs[n]), float(ys[n]))
        if p is not None:
            return p
    raise AssertionError("no pick hit the model")


@pytest.mark.parametrize("system", list(SYSTEMS))
def test_grid_and_iso_take_the_case_unit_system(ctx, tmp_path, system):
    _code, _gu, pressure, rs, length = SYSTEMS[system]
    grid = geoshade.load(write_case(tmp_path / system, system))
    assert grid.meta["unit_system"] == system
    with geoshade.view(grid, property="PRESSURE", step=1, size=SIZE, ctx=ctx,
                       annotations=True) as v:
        _, st = v.draw()
        assert _label(st) == f"PRESSURE [{pressure}]"
        assert (st["unit"], st["unit_system"]) == (pressure, system)
        p = _centre_pick(v)
        assert p.unit == pressure and p.length_unit == length
        assert f" {pressure} " in p.text() + " "
        v.update(property="RS")
        _, st = v.draw()
        assert _label(st) == f"RS [{rs}]"
    with geoshade.view(grid, as_="iso", keyword="SWAT", level=0.2, color_by="PRESSURE",
                       size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
        assert _label(st) == f"PRESSURE [{pressure}]"
        assert (st["unit"], st["unit_system"]) == (pressure, system)
        p = _centre_pick(v)
        assert (p.name, p.unit) == ("PRESSURE", pressure)
        assert p.as_dict()["unit"] == pressure
        v.update(color_by="RS")
        _, st = v.draw()
        assert _label(st) == f"RS [{rs}]"


@pytest.mark.parametrize("system", ["FIELD", "PVT-M"])
def test_exports_keep_the_unit_system(tmp_path, system):
    pytest.importorskip("xarray")
    _code, _gu, pressure, rs, _length = SYSTEMS[system]
    grid = geoshade.load(write_case(tmp_path / "in", system))
    ds = geoshade.to_xarray(grid)
    assert ds["PRESSURE"].attrs["units"] == pressure and ds["RS"].attrs["units"] == rs
    from geoshade.grid.export import export_sector

    sec = export_sector(grid, tmp_path / "SECTOR.EGRID", slice="k=1")
    init = next(f for f in sec.files if str(f).upper().endswith(".INIT"))
    head = next(e.read_array() for e in resfo.lazy_read(str(init))
                if e.read_keyword().strip() == "INTEHEAD")
    assert int(head[2]) == SYSTEMS[system][0]


def test_a_deck_with_field_in_runspec(ctx, tmp_path):
    """A deck: FIELD in RUNSPEC gives psia in the grid and the iso views."""
    deck = tmp_path / "FIELDCASE.DATA"
    nx, ny, nz = 4, 3, 2
    n = nx * ny * nz
    pressure = " ".join(f"{3000 + 10 * c}" for c in range(n))
    swat = " ".join(f"{c / n:.3f}" for c in range(n))
    deck.write_text(
        "RUNSPEC\nDIMENS\n 4 3 2 /\nFIELD\nOIL\nWATER\nGRID\n"
        f"DX\n {n}*100 /\nDY\n {n}*100 /\nDZ\n {n}*20 /\nTOPS\n {nx * ny}*8000 /\n"
        f"PORO\n {n}*0.2 /\nPERMX\n {n}*100 /\nSOLUTION\nPRESSURE\n {pressure} /\n"
        f"SWAT\n {swat} /\n")
    grid = geoshade.load(deck)
    assert grid.meta["unit_system"] == "FIELD"
    prop = "PRESSURE" if "PRESSURE" in grid.property_names() else None
    if prop is None:
        pytest.skip("this deck reader keeps no SOLUTION arrays")
    with geoshade.view(grid, property=prop, size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
        assert _label(st) == "PRESSURE [psia]"
    with geoshade.view(grid, as_="iso", keyword="SWAT", level=0.5, color_by=prop,
                       size=SIZE, ctx=ctx, annotations=True) as v:
        _, st = v.draw()
        assert _label(st) == "PRESSURE [psia]"


@pytest.mark.gl
def test_cli_iso_and_grid_agree_on_a_field_case(tmp_path, capsys):
    """The issue's case: ``iso render --color-by PRESSURE`` and ``grid render`` of one FIELD
    case both say psia (iso said bar)."""
    import json

    from tests.corruption import run_cli

    egrid = write_case(tmp_path / "case", "FIELD")
    labels = {}
    for part, extra in (("iso", ["--color-by", "PRESSURE", "--level", "0.2"]),
                        ("grid", ["--property", "PRESSURE"])):
        stats = tmp_path / f"{part}.json"
        rc, _out, err = run_cli(capsys, [part, "render", egrid, *extra, "-o",
                                         tmp_path / f"{part}.png", "--size", "320x240",
                                         "--stats", stats, "--pick", "160,120"])
        assert rc == 0, err
        st = json.loads(stats.read_text())
        labels[part] = st["annotations"]["colorbar"]["label"]
        assert st["unit_system"] == "FIELD"
        if st.get("pick") and st["pick"].get("value") is not None:
            assert st["pick"]["unit"] == "psia"
    assert labels == {"iso": "PRESSURE [psia]", "grid": "PRESSURE [psia]"}
