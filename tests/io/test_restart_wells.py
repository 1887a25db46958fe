"""Simulation wells from restart files (``geoshade.io.grids.restart_wells``): equal to resfo's
IWEL/ICON/ZWEL per report step on an OPM Flow run and on files written with resfo; damaged
records one line each; only the shown step's well arrays are read."""

from __future__ import annotations

import numpy as np
import pytest
import resfo

import geoshade
from geoshade.errors import InputError
from geoshade.io.grids import ecl_records
from geoshade.io.grids.restart_wells import (
    RestartWellIndex,
    describe_restart_wells,
    format_restart_wells,
    has_restart_wells,
    restart_wells,
)
from tests.io.opm_wells_case import EXPECTED, opm_case

TYPES = {1: "producer", 2: "oil injector", 3: "water injector", 4: "gas injector"}


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    return opm_case(tmp_path_factory)


def resfo_wells(unrst) -> list[dict]:
    """The oracle: every report step's wells decoded from resfo's arrays, item by item."""
    steps: list[dict] = []
    for kw, arr in resfo.read(str(unrst)):
        kw = kw.strip()
        if kw == "SEQNUM":
            steps.append({})
        elif kw in ("INTEHEAD", "IWEL", "ZWEL", "ICON") and kw not in steps[-1]:
            steps[-1][kw] = list(arr)
    out = []
    for s in steps:
        wells = {}
        if "IWEL" in s:
            nw, ncw, niw, nzw, nic = (int(s["INTEHEAD"][i]) for i in (16, 17, 24, 27, 32))
            for w in range(nw):
                iw = s["IWEL"][w * niw:(w + 1) * niw]
                name = s["ZWEL"][w * nzw].decode().strip()
                conns = []
                for c in range(int(iw[4])):
                    ic = s["ICON"][(w * ncw + c) * nic:(w * ncw + c + 1) * nic]
                    if ic[0] > 0:
                        conns.append((ic[1] - 1, ic[2] - 1, ic[3] - 1, ic[5] > 0))
                wells[name] = (TYPES.get(int(iw[6]), "unknown"), iw[10] > 0,
                               (iw[0] - 1, iw[1] - 1), conns)
        out.append(wells)
    return out


def as_dict(step) -> dict:
    return {w.name: (w.type, w.open, tuple(w.head.tolist()),
                     [(*c, bool(o)) for c, o in zip(w.cells.tolist(), w.cell_open, strict=True)])
            for w in step}


def test_opm_run_wells_equal_resfo_per_step(case):
    grid = geoshade.load(case)
    index = restart_wells(grid)
    assert index is not None and len(index) == len(grid.steps) == 5
    oracle = resfo_wells(case.with_suffix(".UNRST"))
    for k in range(len(index)):
        got = as_dict(index[k])
        want = {n: (t, bool(o), tuple(map(int, h)), [(*(int(v) for v in c[:3]), bool(c[3]))
                                                     for c in cs])
                for n, (t, o, h, cs) in oracle[k].items()}
        assert got == want, k
        assert index[k].names() == list(oracle[k])   # the file's order


def test_opm_run_status_changes_with_the_step(case):
    index = restart_wells(geoshade.load(case))
    assert len(index[0]) == 0   # the first report is before the schedule's wells
    for k, wells in EXPECTED.items():
        got = as_dict(index[k])
        assert {n: (t, o, [(*c[:3], c[3]) for c in cs]) for n, (t, o, _, cs) in got.items()} \
            == wells, k
    assert index[3]["WINJ"].open is False and index[4]["winj"].open is True
    assert index[2]["GINJ"].cell_open.tolist() == [True, False]
    assert index[1].date == "2015-02-01" and index[3].seqnum == 3


def test_index_is_made_once_and_kept_in_meta(case):
    grid = geoshade.load(case)
    assert restart_wells(grid) is restart_wells(grid)
    assert has_restart_wells(grid)


def test_only_the_shown_steps_well_arrays_are_read(case, monkeypatch):
    grid = geoshade.load(case)
    index = restart_wells(grid)
    read: list[tuple[str, int]] = []
    original = ecl_records.Record.read

    def spy(self, kinds=None):
        read.append((self.keyword, self.start))
        return original(self, kinds)

    monkeypatch.setattr(ecl_records.Record, "read", spy)
    index[3]
    assert sorted(k for k, _ in read) == ["ICON", "INTEHEAD", "IWEL", "SEQNUM", "ZWEL"]
    step3 = index._steps[3].records
    assert {s for _, s in read} == {r.start for r in step3.values()}
    index[3]   # cached
    assert len(read) == 5


def test_describe_and_format_for_info(case):
    d = describe_restart_wells(geoshade.load(case))
    assert [w["name"] for w in d["wells"]] == ["PROD", "GINJ", "WINJ"]
    winj = d["wells"][2]
    assert (winj["type"], winj["first_step"], winj["last_step"], winj["open"]) == \
        ("water injector", 1, 4, True)
    lines = format_restart_wells(d)
    assert lines[0] == "  sim wells 3 in the restart file:"
    assert lines[2].startswith("    GINJ  gas injector, open at step 4, 1 of 2 completions open")


def test_a_case_without_restart_file_has_no_restart_wells():
    from geoshade.compute.grid.synthetic import synthetic_grid

    g = synthetic_grid(4, 3, 2)
    assert restart_wells(g) is None and not has_restart_wells(g)
    assert describe_restart_wells(g) is None and format_restart_wells(None) == []


@pytest.mark.data
def test_reek_run_lists_wells_without_well_records(shared_data):
    """The OPM run of Reek has NWELLS > 0 in INTEHEAD from the second step on but no
    IWEL/ICON/ZWEL: no wells, said once, no error."""
    unrst = shared_data / "reek_cornerpoint" / "opm_flow_run" / "2_R001_REEK-0.UNRST"
    index = RestartWellIndex(unrst, dims=(40, 64, 14))
    assert len(index) == 37 and not index.has_wells()
    assert len(index[10]) == 0 and "INTEHEAD lists 5 wells" in index[10].note
    assert len(index[0]) == 0 and index[0].note == ""


# --- files written with resfo -------------------------------------------------------------------
def head(nwells, ncwmax, niwelz=155, nzwelz=3, niconz=26, date=(1, 2, 2020)):
    h = np.zeros(411, np.int32)
    h[[16, 17, 24, 27, 32]] = (nwells, ncwmax, niwelz, nzwelz, niconz)
    h[[64, 65, 66]] = date
    return h


def well_records(wells, ncwmax=3, niwelz=155, nzwelz=3, niconz=26):
    """IWEL, ZWEL, ICON of ``wells``: (name, type, status, (hi, hj), [(i, j, k, status)])."""
    nw = len(wells)
    iwel = np.zeros((nw, niwelz), np.int32)
    zwel = np.full((nw, nzwelz), b"        ", "S8")
    icon = np.zeros((nw, ncwmax, niconz), np.int32)
    for w, (name, typ, status, (hi, hj), conns) in enumerate(wells):
        iwel[w, [0, 1, 4, 6, 10]] = (hi, hj, len(conns), typ, status)
        zwel[w, 0] = name.ljust(8).encode()
        for c, (i, j, k, st) in enumerate(conns):
            icon[w, c, [0, 1, 2, 3, 5]] = (c + 1, i, j, k, st)
    return [("IWEL    ", iwel.ravel()), ("ZWEL    ", zwel.ravel()), ("ICON    ", icon.ravel())]


def write_unrst(path, steps, first=0, **kw):
    records = []
    for k, wells in enumerate(steps, first):
        records += [("SEQNUM  ", np.array([k], np.int32)),
                    ("INTEHEAD", head(len(wells), kw.get("ncwmax", 3)))]
        if wells:
            records += well_records(wells, **kw)
        records += [("PRESSURE", np.ones(24, np.float32))]
    resfo.write(str(path), records)
    return path


STEPS = [
    [],
    [("P1", 1, 1, (2, 3), [(2, 3, 1, 1), (2, 3, 2, 1)]),
     ("GI", 4, 1, (1, 1), [(1, 1, 4, 1)])],
    [("P1", 1, -1000, (2, 3), [(2, 3, 1, 0), (2, 3, 2, 1)]),
     ("GI", 4, 1, (1, 1), [(1, 1, 4, 1)]),
     ("WI", 3, 1, (4, 2), [])],
]


def test_synthetic_file_equals_resfo_oracle(tmp_path):
    f = write_unrst(tmp_path / "S.UNRST", STEPS)
    index = RestartWellIndex(f, dims=(4, 3, 4))
    oracle = resfo_wells(f)
    for k in range(3):
        got = as_dict(index[k])
        assert got == {n: (t, bool(o), tuple(map(int, h)),
                           [(*(int(v) for v in c[:3]), bool(c[3])) for c in cs])
                       for n, (t, o, h, cs) in oracle[k].items()}
    assert index[2]["P1"].open is False and index[2]["WI"].cells.shape == (0, 3)
    assert index[-1].step == 2 and len(index) == 3


def test_empty_icon_slots_and_dual_porosity_k(tmp_path):
    """Slots with sequence number 0 below IWEL's count are skipped (as resdata does); K in
    NZ+1..2NZ (the fracture cells of a dual-porosity run) is the cell above."""
    f = tmp_path / "D.UNRST"
    recs = well_records([("A", 1, 1, (1, 1), [(1, 1, 1, 1), (1, 1, 6, 1)])])
    icon = recs[2][1].reshape(1, 3, 26)
    icon[0, 2] = 0   # an empty slot
    recs[0][1][4] = 3   # IWEL says 3 connections
    resfo.write(str(f), [("SEQNUM  ", np.array([1], np.int32)), ("INTEHEAD", head(1, 3)),
                         *recs])
    w = RestartWellIndex(f, dims=(2, 2, 4))[0]["A"]
    assert w.cells.tolist() == [[0, 0, 0], [0, 0, 1]]


@pytest.mark.parametrize("damage, message", [
    ("iwel_count", "IWEL (report step 1): expected 310 values (NWELLS·NIWELZ = 2·155), got 300"),
    ("no_zwel", "ZWEL (report step 1): not found; INTEHEAD says the step has wells"),
    ("outside", "ICON (report step 1): well GI connection 1 is in cell I J K = 1 1 9, outside"),
    ("nconn", "IWEL (report step 1): well P1 has 7 connections; expected 0..NCWMAX = 3"),
    ("short_head", "INTEHEAD (report step 1): expected at least 33 values, got 20"),
    ("head_off", "IWEL (report step 1): well GI has its head in column I J = 9 1, outside"),
    ("zwel_type", "ZWEL: values of type INTE; expected CHAR"),
])
def test_damaged_records_are_one_line_naming_file_and_keyword(tmp_path, damage, message):
    f = tmp_path / "BAD.UNRST"
    write_unrst(f, STEPS[:2])
    recs = list(resfo.read(str(f)))
    at = {kw.strip(): n for n, (kw, _) in enumerate(recs) if n >= 3}   # step 1's records
    if damage == "iwel_count":
        recs[at["IWEL"]] = ("IWEL    ", recs[at["IWEL"]][1][:300])
    elif damage == "no_zwel":
        del recs[at["ZWEL"]]
    elif damage == "outside":
        icon = recs[at["ICON"]][1].copy()
        icon[3 * 26 + 3] = 9
        recs[at["ICON"]] = ("ICON    ", icon)
    elif damage == "nconn":
        iwel = recs[at["IWEL"]][1].copy()
        iwel[4] = 7
        recs[at["IWEL"]] = ("IWEL    ", iwel)
    elif damage == "short_head":
        recs[at["INTEHEAD"]] = ("INTEHEAD", recs[at["INTEHEAD"]][1][:20])
    elif damage == "head_off":
        iwel = recs[at["IWEL"]][1].copy()
        iwel[155] = 9
        recs[at["IWEL"]] = ("IWEL    ", iwel)
    elif damage == "zwel_type":
        recs[at["ZWEL"]] = ("ZWEL    ", np.zeros(6, np.int32))
    resfo.write(str(f), recs)
    index = RestartWellIndex(f, dims=(4, 3, 4))
    assert len(index[0]) == 0   # the step before is fine
    with pytest.raises(InputError) as err:
        index[1]
    text = str(err.value)
    assert "\n" not in text and text.startswith(str(f)) and message in text


def test_truncated_file_keeps_the_complete_steps(tmp_path):
    f = write_unrst(tmp_path / "T.UNRST", STEPS)
    data = f.read_bytes()
    f.write_bytes(data[:-200])   # the file ends inside step 2's last record
    index = RestartWellIndex(f, dims=(4, 3, 4))
    assert len(index) == 3 and index.damage is not None
    assert index[1].names() == ["P1", "GI"]
    with pytest.raises(InputError, match=r"SEQNUM \(report step 2\): the step is incomplete"):
        index[2]
    assert len(RestartWellIndex(f, dims=(4, 3, 4), nsteps=2)) == 2


def test_missing_file_and_bad_step(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        RestartWellIndex(tmp_path / "NONE.UNRST")
    index = RestartWellIndex(write_unrst(tmp_path / "S.UNRST", STEPS))
    with pytest.raises(InputError, match=r"step 3 does not exist; the file has 3 report steps"):
        index[3]


def test_lgr_wells_are_skipped(tmp_path):
    f = tmp_path / "L.UNRST"
    glob = well_records([("G", 1, 1, (1, 1), [(1, 1, 1, 1)])])
    local = well_records([("L", 1, 1, (1, 1), [(1, 1, 1, 1)]), ("M", 1, 1, (1, 1), [])])
    resfo.write(str(f), [("SEQNUM  ", np.array([1], np.int32)), ("INTEHEAD", head(1, 3)),
                         ("LGR     ", np.array([b"LOCAL   "])), *local,
                         ("ENDLGR  ", np.zeros(0, np.int32)), *glob])
    assert RestartWellIndex(f)[0].names() == ["G"]


def test_non_unified_restarts_equal_the_unified_file(tmp_path):
    """``.X0001`` … files (with or without SEQNUM) give the steps of the unified file; an
    error names the file of its step; ``restart_wells`` follows ``meta["restart"]``."""
    from geoshade.compute.grid.synthetic import synthetic_grid

    unified = RestartWellIndex(write_unrst(tmp_path / "U.UNRST", STEPS), dims=(4, 3, 4))
    files = []
    for k, wells in enumerate(STEPS):
        f = tmp_path / f"U.X{k:04d}"
        write_unrst(f, [wells], first=k)
        if k == 1:   # this one without SEQNUM: its report number from the suffix
            resfo.write(str(f), [r for r in resfo.read(str(f)) if r[0].strip() != "SEQNUM"])
        files.append(f)
    split = RestartWellIndex(files, dims=(4, 3, 4))
    assert len(split) == 3
    for k in range(3):
        assert as_dict(split[k]) == as_dict(unified[k])
        assert split[k].seqnum == k and split[k].source == str(files[k])
    g = synthetic_grid(4, 3, 4)
    g.meta.update(unrst_path=str(files[0]), unrst_seqnum=[0, 1, 2],
                  restart={"kind": "non-unified", "files": [str(f) for f in files]})
    assert restart_wells(g)[2].names() == ["P1", "GI", "WI"]
    recs = list(resfo.read(str(files[2])))
    resfo.write(str(files[2]), [r if r[0].strip() != "IWEL" else ("IWEL    ", r[1][:9])
                                for r in recs])
    with pytest.raises(InputError, match=r"U\.X0002: IWEL \(report step 2\): expected"):
        RestartWellIndex(files, dims=(4, 3, 4))[2]


def test_info_lists_the_restart_wells(case, capsys):
    import json

    from tests.corruption import run_cli

    rc, out, err = run_cli(capsys, ["info", case])
    assert rc == 0, err
    lines = out.splitlines()
    head = [ln for ln in lines if ln.strip().startswith("sim wells")]
    assert head == ["  sim wells 3 in the restart file:"], lines
    for name, (kind, _open, _cells) in EXPECTED[4].items():
        assert any(ln.split()[0] == name and kind in ln for ln in lines
                   if ln.startswith("    ")), (name, lines)
    rc, out, _ = run_cli(capsys, ["info", "--json", case])
    wells = {w["name"]: w for w in json.loads(out)["sim_wells"]["wells"]}
    assert set(wells) == set(EXPECTED[4]) and wells["PROD"]["type"] == "producer"
