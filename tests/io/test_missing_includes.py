"""A field deck as users have it: 61 named faults in 50 INCLUDE files, some of them missing.

Without ``skip_missing`` every missing INCLUDE is named in one line; with it the rest is read,
one warning names what was skipped, and a grid whose geometry went missing is shown in IJK
index space.  Units come from RUNSPEC.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.describe import describe, format_description
from geoshade.io.grids.deck import read_deck
from geoshade.io.grids.grdecl import read_grdecl

DIMS = (12, 10, 4)
N_FAULTS = 61
PROPS = ("PORO", "PERMX", "PERMY", "PERMZ", "NTG", "SWATINIT")
REGIONS = ("FIPNUM", "SATNUM", "EQLNUM", "PVTNUM")


def _values(arr, fmt="{:.6g}") -> str:
    v = [fmt.format(x) for x in np.ravel(arr, order="F")]
    return "\n".join(" " + " ".join(v[i:i + 10]) for i in range(0, len(v), 10)) + " /\n"


def field_deck(root: Path, missing=()) -> tuple[Path, dict]:
    """Write ``root/model/FIELD.DATA`` and its 50 INCLUDE files under ``root/include``, then
    delete the ``missing`` ones (paths as the deck writes them).  Returns the deck and
    ``{"grid": the grid, "faults": {file: [names]}, "includes": [all 50 names]}``."""
    nx, ny, nz = DIMS
    grid = synthetic_grid(nx, ny, nz, seed=11)
    rng = np.random.default_rng(4)
    files: dict[str, str] = {}
    coord = np.asarray(grid.coord).transpose(1, 0, 2)
    files["grid/coord.inc"] = "COORD\n" + _values(coord.reshape(-1, 6).T, "{:.3f}")
    files["grid/zcorn.inc"] = "ZCORN\n" + _values(grid.zcorn, "{:.3f}")
    files["grid/actnum.inc"] = "ACTNUM\n" + _values(np.asarray(grid.actnum, int), "{}")
    files["grid/mapaxes.inc"] = "MAPAXES\n 0 100 0 0 100 0 /\n"
    faults: dict[str, list[str]] = {}
    names = [f"F_{c}{n}" for c in "ABCDEFGHIJKLM" for n in range(1, 6)][:N_FAULTS]
    for f in range(13):  # 61 faults in 13 files (4 or 5 a file)
        part = names[f * 5:(f + 1) * 5]
        if not part:
            break
        lines = []
        for name in part:
            i = int(rng.integers(1, nx))
            lines.append(f" '{name}' {i} {i} 1 {ny} 1 {nz} X /")
        key = f"faults/faults_{f + 1:02d}.inc"
        files[key] = "FAULTS\n" + "\n".join(lines) + "\n/\n"
        faults[key] = part
    files["edit/multflt.inc"] = "MULTFLT\n" + "".join(f" '{n}' 0.1 /\n" for n in names[:5]) + "/\n"
    for p in PROPS:
        files[f"props/{p.lower()}.inc"] = f"{p}\n" + _values(rng.random(DIMS).astype(np.float32))
    for p in REGIONS:
        files[f"regions/{p.lower()}.inc"] = f"{p}\n" + _values(rng.integers(1, 4, DIMS), "{}")
    files["pvt/pvto.inc"] = "PVDO\n 100 1.01 1.0\n 300 1.00 1.0 /\n"
    files["pvt/pvtw.inc"] = "PVTW\n 200 1.0 4e-5 0.5 0 /\n"
    files["scal/swof.inc"] = "SWOF\n 0.1 0 1 0\n 0.9 1 0 0 /\n"
    files["sol/equil.inc"] = "EQUIL\n 1000 200 2000 0 0 0 /\n"
    files["summary/summary.inc"] = "FOPR\nFWPR\nWBHP\n/\n"
    n_sched = 50 - len(files)
    for w in range(n_sched):
        files[f"schedule/wells_{w + 1:02d}.inc"] = (
            f"WELSPECS\n 'P{w + 1}' 'G' {1 + w % nx} {1 + w % ny} 1* OIL /\n/\n"
            f"COMPDAT\n 'P{w + 1}' 2* 1 {nz} OPEN /\n/\n")
    assert len(files) == 50
    inc = root / "include"
    for name, text in files.items():
        (inc / name).parent.mkdir(parents=True, exist_ok=True)
        (inc / name).write_text(text)
    sections = {"grid": "GRID", "faults": "GRID", "edit": "EDIT", "props": "PROPS",
                "pvt": "PROPS", "scal": "PROPS", "regions": "REGIONS", "sol": "SOLUTION",
                "summary": "SUMMARY", "schedule": "SCHEDULE"}
    body = [f"RUNSPEC\nTITLE\n a field with {N_FAULTS} faults\nDIMENS\n {nx} {ny} {nz} /\n"
            "OIL\nWATER\nFIELD\nSTART\n 1 JAN 2000 /\n"]
    section = ""
    for name in files:  # in the order of the sections above
        want = sections[name.split("/")[0]]
        if want != section:
            body.append(f"{want}\n")
            section = want
        body.append(f"INCLUDE\n '../include/{name}' /\n")
    deck = root / "model" / "FIELD.DATA"
    deck.parent.mkdir(parents=True, exist_ok=True)
    deck.write_text("".join(body) + "END\n")
    for name in missing:
        (inc / name).unlink()
    return deck, {"grid": grid, "faults": faults, "includes": list(files)}


def _quiet(fn, *a, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*a, **kw)


MISSING = ("props/permy.inc", "faults/faults_07.inc", "sol/equil.inc",
           "schedule/wells_12.inc")


def test_complete_field_deck(tmp_path):
    deck, made = field_deck(tmp_path)
    g = _quiet(read_deck, deck)
    assert len(g.faults) == N_FAULTS and len(g.meta["files"]) == 51
    assert set(PROPS) | set(REGIONS) <= set(g.properties)
    np.testing.assert_allclose(g.zcorn, made["grid"].zcorn, atol=1e-3)
    assert g.units == "FEET" and g.meta["unit_system"] == "FIELD"
    assert "missing_includes" not in g.meta and not g.meta.get("index_space")
    assert len(g.meta["wells"]) == len([n for n in made["includes"] if "wells_" in n])


def test_every_missing_include_in_one_line(tmp_path):
    deck, _ = field_deck(tmp_path, MISSING)
    with pytest.raises(InputError) as ei:
        _quiet(read_deck, deck)
    names = ", ".join(f"'../include/{n}'" for n in sorted(MISSING, key=_deck_order))
    assert str(ei.value) == (f"{deck}: 4 INCLUDE files are missing: {names} (looked in "
                             f"{deck.parent}); --skip-missing reads the rest")


def _deck_order(name: str) -> int:
    return ["faults/", "edit/", "props/", "regions/", "sol/", "schedule/"].index(
        name.split("/")[0] + "/")


def test_skip_missing_reads_the_rest(tmp_path):
    deck, made = field_deck(tmp_path, MISSING)
    with pytest.warns(UserWarning) as seen:
        g = read_deck(deck, skip_missing=True)
    skipped = [str(w.message) for w in seen if "missing and skipped" in str(w.message)]
    assert len(skipped) == 1 and skipped[0].startswith(f"{deck}: 4 INCLUDE file(s) missing")
    assert all(n in skipped[0] for n in MISSING)
    lost = set(made["faults"]["faults/faults_07.inc"])
    assert len(g.faults) == N_FAULTS - len(lost) and not lost & {f.name for f in g.faults}
    assert "PERMY" not in g.properties and "PERMX" in g.properties
    assert g.meta["missing_includes"] == [f"../include/{n}" for n in
                                          sorted(MISSING, key=_deck_order)]
    assert g.meta["geometry"] == "corner-point" and "index_space" not in g.meta
    assert g.meta["strict_error"].startswith(f"{deck}: 4 INCLUDE files are missing: ")
    d = describe(g)
    assert d["missing_includes"] == g.meta["missing_includes"] and d["unit_system"] == "FIELD"
    text = format_description(d)
    assert "  missing  4 INCLUDE files: ../include/faults/faults_07.inc" in text
    assert "  units    FIELD (lengths in FEET)" in text
    assert f"  faults   {N_FAULTS - len(lost)}: " in text and "  skipped  " in text


def test_missing_geometry_gives_index_space(tmp_path):
    deck, _ = field_deck(tmp_path, ("grid/zcorn.inc", "props/ntg.inc"))
    with pytest.raises(InputError, match=r"2 INCLUDE files are missing: '../include/grid/"
                                         r"zcorn.inc', '../include/props/ntg.inc'"):
        _quiet(read_deck, deck)
    with pytest.warns(UserWarning) as seen:
        g = load(deck, skip_missing=True)
    notes = [str(w.message) for w in seen if "missing and skipped" in str(w.message)]
    assert len(notes) == 1 and "no ZCORN was read, so the cells are shown in IJK index space " \
                               "(unit cells: x = I, y = J, depth = K)" in notes[0]
    nx, ny, nz = DIMS
    assert g.meta["index_space"] is True and g.meta["geometry"] == "IJK index space"
    assert g.units == "" and g.meta["unit_system"] == "FIELD"
    assert g.bounds().tolist() == [[0, 0, 0], [nx, ny, nz]]
    assert g.zcorn[2 * 3 + 1, 2 * 2, 2 * 1 + 1] == 2.0  # cell (3, 2, 1): depth 1..2
    assert "PORO" in g.properties and len(g.faults) == N_FAULTS
    assert format_description(describe(g)).count("IJK index space") == 1


def test_nested_and_no_size(tmp_path):
    """Missing INCLUDEs looked for in two folders; the size itself in a missing file."""
    inc = tmp_path / "inc"
    inc.mkdir()
    (inc / "grid.inc").write_text("INCLUDE\n 'coord.inc' /\nINCLUDE\n 'zcorn.inc' /\n")
    deck = tmp_path / "A.DATA"
    deck.write_text("RUNSPEC\nINCLUDE\n 'dims.inc' /\nGRID\nINCLUDE\n 'inc/grid.inc' /\n"
                    "PORO\n 8*0.2 /\n")
    with pytest.raises(InputError) as ei:
        _quiet(read_deck, deck)
    assert str(ei.value) == (f"{deck}: 3 INCLUDE files are missing: 'dims.inc' (looked in "
                             f"{tmp_path}), 'coord.inc' (looked in {inc}), 'zcorn.inc' (looked "
                             f"in {inc}); --skip-missing reads the rest")
    with pytest.raises(InputError) as ei:
        _quiet(read_deck, deck, skip_missing=True)
    assert str(ei.value).startswith(f"{deck}: no SPECGRID or DIMENS keyword") and \
        "3 INCLUDE file(s) missing ('dims.inc' (looked in" in str(ei.value)


def test_grdecl_without_geometry(tmp_path):
    """A properties-only GRDECL file: an error naming --skip-missing, index space with it."""
    f = tmp_path / "poro.grdecl"
    f.write_text("SPECGRID\n 2 2 1 1 F /\nPORO\n 0.1 0.2 0.3 0.4 /\n")
    with pytest.raises(InputError) as ei:
        _quiet(read_grdecl, f)
    assert str(ei.value) == (f"{f}: no COORD or ZCORN keyword; a corner-point grid needs "
                             "SPECGRID, COORD and ZCORN (or DX, DY, DZ and TOPS); --skip-missing "
                             "shows the cells in IJK index space")
    g = _quiet(read_grdecl, f, skip_missing=True)
    assert g.meta["index_space"] and g.meta["strict_error"] == str(ei.value)
    assert g.properties["PORO"][1, 1, 0] == pytest.approx(0.4)


@pytest.mark.parametrize("system, units", [("METRIC", "METRES"), ("FIELD", "FEET"),
                                           ("LAB", "CM"), ("", "METRES")])
def test_units_from_runspec(tmp_path, system, units):
    f = tmp_path / "U.DATA"
    f.write_text(f"RUNSPEC\nDIMENS\n 1 1 1 /\n{system}\nGRID\nDX\n 1 /\nDY\n 1 /\nDZ\n 1 /\n"
                 "TOPS\n 0 /\n")
    g = read_deck(f)
    assert g.units == units and g.meta["unit_system"] == (system or "METRIC")
    f.write_text(f"RUNSPEC\nDIMENS\n 1 1 1 /\n{system}\nGRID\nGRIDUNIT\n METRES /\nDX\n 1 /\n"
                 "DY\n 1 /\nDZ\n 1 /\nTOPS\n 0 /\n")
    assert read_deck(f).units == "METRES"


def test_two_unit_systems_refused(tmp_path):
    f = tmp_path / "U.DATA"
    f.write_text("RUNSPEC\nDIMENS\n 1 1 1 /\nFIELD\nMETRIC\n")
    with pytest.raises(InputError, match=r"U.DATA: METRIC: the deck already chose the FIELD "
                                         "unit system"):
        read_deck(f)
