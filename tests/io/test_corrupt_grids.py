"""Corruption suite of the corner-point grid inputs (issue 12: classes 2, 3, 4, and 8 for grids).

Small grids are written with resfo (EGRID, INIT, UNRST, laid out as OPM writes them) and with
:mod:`geoshade.io.grids.grdecl_writer` (GRDECL), then copies are damaged by seeded generators:
truncated at many offsets, record markers flipped, header counts changed (one too many or few,
negative, huge), short GRIDHEAD/INTEHEAD, formatted files under binary names, NaN/inf/3e38 in
ZCORN and COORD, cells turned upside down, huge SPECGRID/DIMENS/GRIDHEAD, unbounded filter
expressions.  Each case runs the CLI (``geoshade info``; ``geoshade grid render`` in the
``gl`` tests) and must fail cleanly (:func:`tests.corruption.clean_failure`), or, where the
policy is a warning (a truncated UNRST, inverted cells), give that one warning and the right
numbers.  The counts are printed (``-s``) and every case tried must come out clean.
"""

from __future__ import annotations

import itertools
import json
import random
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
import resfo

import geoshade.io.grids.grdecl as gr
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.io import load
from geoshade.io.grids.grdecl_writer import write_grdecl
from geoshade.models.grid import MAX_COORDINATE
from tests.corruption import Tally, clean_failure, run_cli

SEED = 12
DIMS = (10, 8, 4)  # ZCORN: 2560 values, three data blocks in the binary files
NSTEPS = 3


# --- writers -----------------------------------------------------------------------------------
def _kw(name: str) -> str:
    return f"{name:<8}"


def _grid(seed: int = SEED):
    return synthetic_grid(*DIMS, seed=seed, inactive_fraction=0.1)


def _egrid_entries(g, zcorn=None, coord=None, head=None):
    nx, ny, nz = g.dims
    gh = np.zeros(100, np.int32)
    gh[:4] = (1, nx, ny, nz)
    z = np.asarray(g.zcorn).reshape(-1, order="F") if zcorn is None else zcorn
    c = np.asarray(g.coord).transpose(1, 0, 2).reshape(-1) if coord is None else coord
    return [(_kw("FILEHEAD"), np.zeros(100, np.int32)),
            (_kw("MAPUNITS"), np.array([b"METRES  "])),
            (_kw("MAPAXES"), np.array([0, 1, 0, 0, 1, 0], np.float32)),
            (_kw("GRIDUNIT"), np.array([b"METRES  ", b"        "])),
            (_kw("GRIDHEAD"), gh if head is None else head),
            (_kw("COORD"), np.asarray(c, np.float32)),
            (_kw("ZCORN"), np.asarray(z, np.float32)),
            (_kw("ACTNUM"), np.asarray(g.actnum).reshape(-1, order="F").astype(np.int32)),
            (_kw("ENDGRID"), np.zeros(0, np.int32))]


def _intehead(g, step=0):
    ih = np.zeros(411, np.int32)
    ih[8:12] = (*g.dims, g.nactive)
    ih[64:67] = (1, step + 1, 2001)
    return ih


def _init_entries(g, head=None):
    act = g.active.reshape(-1, order="F")
    poro = g.properties["PORO"].reshape(-1, order="F")
    return [(_kw("INTEHEAD"), _intehead(g) if head is None else head),
            (_kw("LOGIHEAD"), np.zeros(121, np.int32)),
            (_kw("DOUBHEAD"), np.zeros(229, np.float64)),
            (_kw("PORV"), np.where(act, poro * 1000, 0).astype(np.float32)),
            (_kw("PORO"), poro[act].astype(np.float32)),
            (_kw("PERMX"), g.properties["PERMX"].reshape(-1, order="F")[act].astype(np.float32)),
            (_kw("FIPNUM"), g.properties["FIPNUM"].reshape(-1, order="F")[act].astype(np.int32)),
            (_kw("TABDIMS"), np.zeros(100, np.int32)),
            (_kw("TAB"), np.linspace(0, 1, 1500))]


def _swat(g, k):
    return np.linspace(0, 1, g.nactive, dtype=np.float32) * (k + 1) / (NSTEPS + 1)


def _unrst_entries(g, nsteps=NSTEPS):
    out = []
    for k in range(nsteps):  # the record sequence of an OPM restart step
        out += [(_kw("SEQNUM"), np.array([10 * k], np.int32)), (_kw("INTEHEAD"), _intehead(g, k)),
                (_kw("LOGIHEAD"), np.zeros(121, np.int32)),
                (_kw("DOUBHEAD"), np.zeros(229, np.float64)), (_kw("STARTSOL"), resfo.MESS),
                (_kw("PRESSURE"), np.full(g.nactive, 200.0 + k, np.float32)),
                (_kw("SWAT"), _swat(g, k)), (_kw("ENDSOL"), resfo.MESS)]
    return out


def _case(folder: Path, g=None, fmt=resfo.Format.UNFORMATTED) -> Path:
    """CASE.EGRID, CASE.INIT, CASE.UNRST in ``folder``; the EGRID's path."""
    g = _grid() if g is None else g
    folder.mkdir(parents=True, exist_ok=True)
    resfo.write(folder / "CASE.EGRID", _egrid_entries(g), fmt)
    resfo.write(folder / "CASE.INIT", _init_entries(g), fmt)
    resfo.write(folder / "CASE.UNRST", _unrst_entries(g), fmt)
    return folder / "CASE.EGRID"


def _records(path: Path) -> list[tuple[str, int, int]]:
    """(keyword, start, end) of every record of an intact file, from resfo."""
    starts = [(e.read_keyword().strip(), e.start) for e in resfo.lazy_read(str(path))]
    ends = [s for _, s in starts[1:]] + [path.stat().st_size]
    return [(kw, s, e) for (kw, s), e in zip(starts, ends, strict=True)]


def _cut_points(path: Path, rng: random.Random, n_random: int = 20) -> list[int]:
    """Offsets to truncate at: around every record boundary, inside headers, and at random."""
    size = path.stat().st_size
    cuts = {0, 1, 3, size - 1}
    for _, start, _ in _records(path):
        cuts.update(start + d for d in (0, 1, 7, 13, 23, 24, 25, 29) if start + d < size)
    cuts.update(rng.randrange(1, size) for _ in range(n_random))
    return sorted(c for c in cuts if 0 <= c < size)


def _put(path: Path, offset: int, value: int) -> None:
    """Overwrite the big-endian int32 at ``offset``."""
    b = bytearray(path.read_bytes())
    b[offset:offset + 4] = int(value).to_bytes(4, "big", signed=True)
    path.write_bytes(bytes(b))


def _copy(src: Path, dst: Path) -> Path:
    if dst.exists():
        shutil.rmtree(dst)
    shutil.copytree(src, dst)
    return dst / "CASE.EGRID"


class _Suite:
    """A Tally plus the messages of the cases that did not come out clean."""

    def __init__(self, name: str):
        self.tally, self.failures = Tally(name), []

    def case(self, what: str, fn) -> str | None:
        try:
            out = fn()
        except AssertionError as err:
            self.tally(False)
            self.failures.append(f"{what}: {str(err).splitlines()[0][:300]}")
            return None
        self.tally(True)
        return out

    def check(self, capsys) -> None:
        with capsys.disabled():
            print(f"\n{self.tally}")
        assert not self.failures, "\n".join(self.failures[:10])
        assert self.tally.tried and self.tally.clean == self.tally.tried


def _load(path):
    """``geoshade.io.load`` in this process, its warnings not shown (they are checked through
    the CLI)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(path)


def _info_fails(capsys, egrid: Path, damaged: Path, expect: str | None = None) -> str:
    folder = egrid.parent
    return clean_failure(capsys, ["info", egrid], inputs=[folder], watch=[folder],
                         names=damaged.name, expect=expect)


# --- class 3: damaged ECLIPSE binaries ---------------------------------------------------------
@pytest.fixture(scope="module")
def good_case(tmp_path_factory) -> Path:
    return _case(tmp_path_factory.mktemp("good") / "case")


def test_good_case_reads(capsys, good_case):
    rc, out, err = run_cli(capsys, ["info", "--json", good_case])
    assert rc == 0 and not err.strip(), err
    d = json.loads(out)
    assert d["steps"] == NSTEPS and {"PORO", "PERMX", "FIPNUM", "PORV"} <= set(d["properties"])


@pytest.mark.parametrize("name", ["CASE.EGRID", "CASE.INIT"])
def test_truncated_egrid_and_init(capsys, tmp_path, good_case, name):
    """Every cut of an EGRID is an error (ENDGRID is required); every cut of an INIT inside a
    record is an error, a cut between two records is a shorter valid file (its complete
    properties are read, unchanged)."""
    suite = _Suite(f"truncated {name}")
    src = good_case.parent / name
    data = src.read_bytes()
    boundaries = {s for _, s, _ in _records(src)}
    ref = _load(good_case)
    for t in _cut_points(src, random.Random(SEED)):
        egrid = _copy(good_case.parent, tmp_path / "c")
        (egrid.parent / name).write_bytes(data[:t])
        if name == "CASE.INIT" and t in boundaries and t > 0:
            def shorter(egrid=egrid):
                rc, _out, err = run_cli(capsys, ["info", egrid])
                assert rc == 0 and not err.strip(), err
                g = _load(egrid)
                for k, v in g.properties.items():
                    assert np.array_equal(v, ref.properties[k], equal_nan=True), k
            suite.case(f"{name} cut at record boundary {t}", shorter)
            continue
        suite.case(f"{name} cut at {t}",
                   lambda egrid=egrid: _info_fails(capsys, egrid, egrid.parent / name))
    suite.check(capsys)


def _damage_cases(good_case: Path):
    """(what, file name, damage function(path), expected text or None) over the three files."""
    rng = random.Random(SEED + 1)
    cases = []
    for name in ("CASE.EGRID", "CASE.INIT"):
        recs = _records(good_case.parent / name)
        for kw, start, end in recs:
            length = int.from_bytes((good_case.parent / name).read_bytes()[start + 12:start + 16],
                                    "big", signed=True)
            cases += [
                (f"{name} {kw} start marker", name, lambda p, s=start: _put(p, s, 17), None),
                (f"{name} {kw} end marker", name, lambda p, s=start: _put(p, s + 20, 2**20), None),
                (f"{name} {kw} type", name,
                 lambda p, s=start: p.write_bytes(p.read_bytes()[:s + 16] + b"XYZW"
                                                  + p.read_bytes()[s + 20:]), None),
            ]
            for new in sorted({length + 1, length - 1, -1, -length, 2**31 - 1, length + 1000}
                              - {length}):
                cases.append((f"{name} {kw} count {length}->{new}", name,
                              lambda p, s=start, v=new: _put(p, s + 12, v), None))
            if end - start > 24 + 8:  # a data block marker, at random inside the record's data
                cases.append((f"{name} {kw} data marker", name,
                              lambda p, s=start: _put(p, s + 24, 4 * 999), kw))
                if end - start > 24 + 4008 + 8:
                    cases.append((f"{name} {kw} second block marker", name,
                                  lambda p, s=start: _put(p, s + 24 + 4008, 7), kw))
        noise = random.Random(rng.random())
        cases.append((f"{name} random bytes", name,
                       lambda p, r=noise: p.write_bytes(r.randbytes(p.stat().st_size)), None))
    return cases


def _data_kinds() -> dict[str, str]:
    """Records whose data damage the reader must see (the ones it reads)."""
    return {"CASE.EGRID": "GRIDHEAD COORD ZCORN ACTNUM MAPAXES GRIDUNIT MAPUNITS",
            "CASE.INIT": "INTEHEAD PORV PORO PERMX FIPNUM"}


def test_damaged_records(capsys, tmp_path, good_case):
    """Flipped record markers, changed header counts and types, random bytes: one line each."""
    suite = _Suite("damaged EGRID/INIT records")
    used = _data_kinds()
    for what, name, damage, in_data in _damage_cases(good_case):
        if in_data is not None and in_data not in used[name].split():
            continue  # damage inside an array the reader never reads (TAB, FILEHEAD)
        egrid = _copy(good_case.parent, tmp_path / "c")
        damage(egrid.parent / name)
        suite.case(what, lambda egrid=egrid, name=name, kw=in_data:
                   _info_fails(capsys, egrid, egrid.parent / name, expect=kw))
    suite.check(capsys)


def test_short_heads_formatted_names_and_empty_files(capsys, tmp_path, good_case):
    suite = _Suite("short heads, formatted under binary names, empty files")
    g = _grid()
    cases = []
    for n in (0, 1, 2, 3):
        cases.append((f"GRIDHEAD of {n}", "CASE.EGRID", lambda p, n=n: resfo.write(
            p, _egrid_entries(g, head=np.array([1, *DIMS], np.int32)[:n])), "GRIDHEAD"))
    for n in (0, 5, 11):
        cases.append((f"INIT INTEHEAD of {n}", "CASE.INIT", lambda p, n=n: resfo.write(
            p, _init_entries(g, head=_intehead(g)[:n])), "INTEHEAD"))
    for n in (11, 40, 66):  # a report step needs the date at 64-66
        def short_unrst(p, n=n):
            entries = _unrst_entries(g)
            entries[1] = (entries[1][0], entries[1][1][:n])
            resfo.write(p, entries)
        cases.append((f"UNRST INTEHEAD of {n}", "CASE.UNRST", short_unrst, "INTEHEAD"))
    for bad in ((0, *DIMS), (1, 0, 8, 4), (1, -10, 8, 4), (1, 100000, 100000, 100000),
                (1, 2**31 - 1, 2, 2), (1, 10, 8, 5)):
        cases.append((f"GRIDHEAD {bad}", "CASE.EGRID", lambda p, b=bad: resfo.write(
            p, _egrid_entries(g, head=np.array(b, np.int32))), "GRIDHEAD"))
    writers = {"CASE.EGRID": _egrid_entries, "CASE.INIT": _init_entries,
               "CASE.UNRST": _unrst_entries}
    for name, entries in writers.items():
        cases.append((f"formatted {name}", name, lambda p, e=entries: resfo.write(
            p, e(g), resfo.Format.FORMATTED), "formatted"))
        cases.append((f"empty {name}", name, lambda p: p.write_bytes(b""), "empty"))
        cases.append((f"text {name}", name, lambda p: p.write_text("SPECGRID\n 1 1 1 /\n"),
                      None))
    cases.append(("INIT without INTEHEAD", "CASE.INIT",
                  lambda p: resfo.write(p, _init_entries(g)[1:]), "INTEHEAD"))
    cases.append(("EGRID without ENDGRID", "CASE.EGRID",
                  lambda p: resfo.write(p, _egrid_entries(g)[:-1]), "ENDGRID"))
    cases.append(("EGRID without ZCORN", "CASE.EGRID", lambda p: resfo.write(
        p, [e for e in _egrid_entries(g) if e[0] != _kw("ZCORN")]), "ZCORN"))
    cases.append(("ZCORN of strings", "CASE.EGRID", lambda p: resfo.write(
        p, [(k, np.array([b"abcdefgh"] * 2560) if k == _kw("ZCORN") else v)
            for k, v in _egrid_entries(g)]), "ZCORN"))
    cases.append(("UNRST without SEQNUM", "CASE.UNRST",
                  lambda p: resfo.write(p, _unrst_entries(g)[1:2]), "SEQNUM"))
    for what, name, damage, expect in cases:
        egrid = _copy(good_case.parent, tmp_path / "c")
        damage(egrid.parent / name)
        suite.case(what, lambda egrid=egrid, name=name, e=expect:
                   _info_fails(capsys, egrid, egrid.parent / name, expect=e))
    suite.check(capsys)


# --- class 3/4: a truncated or miscounted UNRST keeps its complete steps -----------------------
def _complete_steps(records, cut: int) -> int:
    """Report steps whose every record lies wholly before ``cut`` (the truth, from resfo)."""
    starts = [i for i, (kw, _, _) in enumerate(records) if kw == "SEQNUM"] + [len(records)]
    return sum(1 for _, b in itertools.pairwise(starts) if records[b - 1][2] <= cut)


def _check_steps(capsys, egrid: Path, ref, expected: int, warned: bool) -> None:
    rc, out, err = run_cli(capsys, ["info", "--json", egrid])
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err, err
    if expected == 0:  # no complete step: an error
        assert rc == 2 and len(lines) == 1 and lines[0].startswith("geoshade: error:"), err
        assert "CASE.UNRST" in lines[0], lines[0]
        return
    assert rc == 0, err
    if warned:
        assert len(lines) == 1 and lines[0].startswith("geoshade: warning:"), err
        assert "CASE.UNRST" in lines[0], lines[0]
        assert f"report step {expected}" in lines[0], lines[0]
        assert f"read the {expected} complete report step" in lines[0], lines[0]
    else:
        assert not lines, err
    d = json.loads(out)
    assert d["steps"] == expected, (d["steps"], expected, err)
    assert d["step_dates"] == ref.step_dates[:expected]
    g = _load(egrid)
    for k in range(expected):
        for kw in ("SWAT", "PRESSURE"):
            assert np.array_equal(g.steps[k][kw], ref.steps[k][kw], equal_nan=True), (k, kw)


def test_truncated_unrst_keeps_complete_steps(capsys, tmp_path, good_case):
    """Cut anywhere: the steps read equal the steps wholly in the file (by resfo's record
    offsets), with one warning naming the first incomplete step; none complete is an error;
    a cut exactly between two steps is a shorter valid file."""
    suite = _Suite("truncated UNRST")
    src = good_case.parent / "CASE.UNRST"
    data, records = src.read_bytes(), _records(src)
    step_starts = {s for kw, s, _ in records if kw == "SEQNUM"} | {len(data)}
    ref = _load(good_case)
    for t in _cut_points(src, random.Random(SEED + 2), n_random=30):
        egrid = _copy(good_case.parent, tmp_path / "c")
        (egrid.parent / "CASE.UNRST").write_bytes(data[:t])
        expected = _complete_steps(records, t)
        suite.case(f"UNRST cut at {t}", lambda egrid=egrid, e=expected, w=t not in step_starts:
                   _check_steps(capsys, egrid, ref, e, w))
    suite.check(capsys)


def test_miscounted_unrst_keeps_steps_before(capsys, tmp_path, good_case):
    """A wrong count (or marker) in a step's header: the steps before it, one warning."""
    suite = _Suite("miscounted UNRST")
    src = good_case.parent / "CASE.UNRST"
    records = _records(src)
    ref = _load(good_case)
    seq = [i for i, (kw, _, _) in enumerate(records) if kw == "SEQNUM"]
    for i, (kw, start, _) in enumerate(records):
        step = sum(1 for q in seq if q <= i) - 1
        length = int.from_bytes(src.read_bytes()[start + 12:start + 16], "big", signed=True)
        for new in (length + 1, length - 1, length + 3000, -3):
            if new == length or (kw in ("STARTSOL", "ENDSOL") and new < 0):
                continue
            egrid = _copy(good_case.parent, tmp_path / "c")
            _put(egrid.parent / "CASE.UNRST", start + 12, new)
            # the damaged record's step is lost; for SEQNUM the step it opens
            suite.case(f"UNRST {kw} (step {step}) count {length}->{new}",
                       lambda egrid=egrid, e=step: _check_steps(capsys, egrid, ref, e, True))
    suite.check(capsys)


# --- class 2: non-finite geometry, inverted cells ----------------------------------------------
BAD_VALUES = ("nan", "NaN", "-nan", "inf", "-Infinity", "3e38", "3.0E+38", "1e20", "-2E11")


def _grdecl_tokens(g, zcorn_tokens=None, coord_tokens=None) -> str:
    """A GRDECL text without repeats (value q is token q), ZCORN/COORD tokens replaceable."""
    nx, ny, nz = g.dims
    coord = coord_tokens or [f"{v:.6g}" for v in np.asarray(g.coord).transpose(1, 0, 2).ravel()]
    zc = zcorn_tokens or [f"{v:.7g}" for v in np.asarray(g.zcorn).ravel(order="F")]
    act = " ".join(str(int(v)) for v in np.asarray(g.actnum).ravel(order="F"))
    lines = [f"SPECGRID\n {nx} {ny} {nz} 1 F /", "COORD"]
    lines += [" ".join(coord[q:q + 6]) for q in range(0, len(coord), 6)] + ["/", "ZCORN"]
    lines += [" ".join(zc[q:q + 8]) for q in range(0, len(zc), 8)] + ["/", f"ACTNUM\n{act} /"]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("scanner", ["numpy", "numba"])
def test_nonfinite_grdecl_geometry_is_refused(capsys, tmp_path, monkeypatch, scanner):
    """nan/inf/3e38 tokens in ZCORN or COORD: the same one line from both parsing paths,
    naming the keyword, the value's index and its cell (pillar)."""
    if scanner == "numba":
        monkeypatch.setattr(gr, "SMALL_VALUES", 0)
    suite = _Suite(f"non-finite GRDECL geometry ({scanner})")
    g = _grid()
    nx = g.dims[0]
    zc = [f"{v:.7g}" for v in np.asarray(g.zcorn).ravel(order="F")]
    co = [f"{v:.6g}" for v in np.asarray(g.coord).transpose(1, 0, 2).ravel()]
    rng = random.Random(SEED + 3)
    for bad in BAD_VALUES:
        for kw in ("ZCORN", "COORD"):
            toks = zc if kw == "ZCORN" else co
            q = rng.randrange(len(toks))
            new = list(toks)
            new[q] = bad
            text = _grdecl_tokens(g, zcorn_tokens=new if kw == "ZCORN" else None,
                                  coord_tokens=new if kw == "COORD" else None)
            f = tmp_path / f"bad_{kw}_{q}.grdecl"
            f.write_text(text)
            if kw == "ZCORN":
                a, b, c = np.unravel_index(q, g.zcorn.shape, order="F")
                where = f"ZCORN: value {float(bad):g} at index {q} (cell i={a // 2 + 1} " \
                        f"j={b // 2 + 1} k={c // 2 + 1}) is not a finite depth"
            else:
                j, i = divmod(q // 6, nx + 1)
                where = f"COORD: value {float(bad):g} at index {q} (pillar i={i + 1} j={j + 1}"
            suite.case(f"{kw}[{q}] = {bad}", lambda f=f, w=where: clean_failure(
                capsys, ["info", f], inputs=[f], watch=[tmp_path], expect=w))
            f.unlink()
    # a repeat of bad values: the first one is named
    new = list(zc)
    new[7:9] = ["2*inf"]
    f = tmp_path / "repeat.grdecl"
    f.write_text(_grdecl_tokens(g, zcorn_tokens=new))
    suite.case("2*inf", lambda: clean_failure(capsys, ["info", f], inputs=[f], watch=[tmp_path],
                                              expect="ZCORN: value inf at index 7 "))
    suite.check(capsys)


def test_nonfinite_egrid_geometry_is_refused(capsys, tmp_path, good_case):
    suite = _Suite("non-finite EGRID geometry")
    g = _grid()
    z = np.asarray(g.zcorn).reshape(-1, order="F").astype(np.float32)
    c = np.asarray(g.coord).transpose(1, 0, 2).reshape(-1).astype(np.float32)
    rng = random.Random(SEED + 4)
    for bad in (np.nan, np.inf, -np.inf, 3e38, 1e20, -2 * MAX_COORDINATE):
        for kw, arr in (("ZCORN", z), ("COORD", c)):
            q = rng.randrange(arr.size)
            a = arr.copy()
            a[q] = bad
            egrid = _copy(good_case.parent, tmp_path / "c")
            resfo.write(egrid, _egrid_entries(g, zcorn=a if kw == "ZCORN" else None,
                                              coord=a if kw == "COORD" else None))
            suite.case(f"{kw}[{q}] = {bad}", lambda egrid=egrid, q=q, kw=kw, v=a[q]: _info_fails(
                capsys, egrid, egrid, expect=f"{kw}: value {float(v):g} at index {q} "))
    suite.check(capsys)


def _inverted(g, cells):
    """A copy of ``g`` with the top and bottom depths of ``cells`` swapped."""
    z = np.array(g.zcorn, order="F")
    for i, j, k in cells:
        top = z[2 * i:2 * i + 2, 2 * j:2 * j + 2, 2 * k].copy()
        z[2 * i:2 * i + 2, 2 * j:2 * j + 2, 2 * k] = z[2 * i:2 * i + 2, 2 * j:2 * j + 2, 2 * k + 1]
        z[2 * i:2 * i + 2, 2 * j:2 * j + 2, 2 * k + 1] = top
    g2 = synthetic_grid(*DIMS, seed=SEED, inactive_fraction=0.1)
    g2.zcorn = z
    return g2


def _inverted_cases(g):
    rng = np.random.default_rng(SEED)
    act = np.argwhere(g.active)
    for n in (1, 3, 17):
        cells = [tuple(int(v) for v in c) for c in act[rng.choice(len(act), n, replace=False)]]
        first = min(cells, key=lambda c: (c[2], c[1], c[0]))
        yield cells, first


def test_inverted_cells_warn_and_are_drawn_as_given(capsys, tmp_path):
    """Inverted cells: one warning naming how many and the first; read as given (GRDECL and
    EGRID), recorded in ``grid.meta["inverted_cells"]``."""
    suite = _Suite("inverted cells")
    g = _grid()
    for cells, first in _inverted_cases(g):
        inv = _inverted(g, cells)
        f = write_grdecl(inv, tmp_path / f"inv{len(cells)}.grdecl")
        egrid = tmp_path / f"e{len(cells)}" / "CASE.EGRID"
        egrid.parent.mkdir()
        resfo.write(egrid, _egrid_entries(inv))
        resfo.write(egrid.parent / "CASE.INIT", _init_entries(inv))
        n = len(cells)
        for path in (f, egrid):
            def check(path=path, n=n, first=first):
                rc, out, err = run_cli(capsys, ["info", "--json", path])
                lines = [ln for ln in err.splitlines() if ln.strip()]
                assert rc == 0 and len(lines) == 1, err
                i, j, k = (v + 1 for v in first)
                assert lines[0] == (f"geoshade: warning: {path}: ZCORN: {n} of {g.nactive} active "
                                    f"cells are inverted (a bottom corner above its top; first: "
                                    f"cell i={i} j={j} k={k}); they are drawn as given"), lines[0]
                assert json.loads(out)["active_cells"] == g.nactive
                assert _load(path).meta["inverted_cells"] == n
            suite.case(f"{len(cells)} inverted in {path.name}", check)
    suite.check(capsys)


# --- class 8: sizes ----------------------------------------------------------------------------
def test_huge_sizes_are_refused_before_allocation(capsys, tmp_path):
    suite = _Suite("huge grid sizes")
    g = _grid()
    text = write_grdecl(g, tmp_path / "good.grdecl").read_text()
    head = "\n".join(ln for ln in text.splitlines() if "SPECGRID" in ln or "1 F /" in ln)
    assert "10 8 4 1 F /" in head
    def refused(path, expect):
        # the memory plan refuses from the header, before the reader runs (exit 6), or the
        # reader from what it is about to allocate
        line = clean_failure(capsys, ["info", path], inputs=[path], watch=[tmp_path],
                             expect=expect)
        assert ("of memory, more than the" in line or "of memory and" in line) and \
            "available (MemAvailable)" in line, line

    def planned(path):
        # a route would fit once made (a store's coarse level): the plan is shown, the file
        # is not read (nothing allocated), exit 0
        rc, out, err = run_cli(capsys, ["info", path])
        assert rc == 0 and "(not read)" in out and "geoshade grid ingest" in out, (rc, err)

    for dims in ("100000 100000 100000", "30000 30000 3000", "1 1 2000000000000"):
        f = tmp_path / f"huge_{dims.replace(' ', 'x')}.grdecl"
        f.write_text(text.replace("10 8 4 1 F /", f"{dims} 1 F /"))
        cells = f"({dims.replace(' ', '×')} cells)"
        deck = tmp_path / f"HUGE_{dims.replace(' ', 'x')}.DATA"
        deck.write_text(f"RUNSPEC\nDIMENS\n {dims} /\nGRID\nINCLUDE\n '{f.name}' /\n")
        if dims == "30000 30000 3000":   # 2.7e12 cells: coarsened 8×8×8 they would fit
            suite.case(f"SPECGRID {dims}", lambda f=f: planned(f))
            suite.case(f"DIMENS {dims}", lambda deck=deck: planned(deck))
            continue
        suite.case(f"SPECGRID {dims}", lambda f=f, c=cells: refused(f, f"{f.name} {c}"))
        suite.case(f"DIMENS {dims}", lambda deck=deck, c=cells: refused(
            deck, f"{deck.name} {c}"))
    f = tmp_path / "faults.grdecl"
    f.write_text("FAULTS\n 'F' 1 100000 1 100000 1 100000 X /\n/\n" + text)
    suite.case("FAULTS box before SPECGRID", lambda: refused(f, "FAULTS F"))
    deck = tmp_path / "WELLS.DATA"
    deck.write_text("RUNSPEC\nDIMENS\n 10 8 4 /\nGRID\nINCLUDE\n 'good.grdecl' /\nSCHEDULE\n"
                    "WELSPECS\n 'W1' 'G' 1 1 1* OIL /\n/\n"
                    "COMPDAT\n 'W1' 2* 1 2000000000 OPEN /\n/\n")
    suite.case("COMPDAT K2 2e9", lambda: clean_failure(
        capsys, ["info", deck], inputs=[deck], watch=[tmp_path], expect="COMPDAT W1"))
    suite.check(capsys)


# --- class 8: filter expressions ---------------------------------------------------------------
FILTERS = {
    "400-digit number": "PORO > " + "9" * 400,
    "1e400": "PORO > 1e400",
    "2000 x not": "not " * 2000 + "PORO > 0",
    "300 x not": "not " * 300 + "PORO > 0",
    "5000 x -": "PORO > " + "-" * 5000 + "1",
    "1500 x -": "PORO > " + "-" * 1500 + "1",
    "3000-term sum": "PORO > 1" + " + 1" * 3000,
    "200-term sum": "PORO > 1" + " + 1" * 200,
    "long expression": " or ".join(["PORO > 0.1"] * 300),
    "500 parentheses": "(" * 500 + "PORO > 0" + ")" * 500,
}


def test_filter_bounds_no_gl(capsys, tmp_path):
    from geoshade.compute.grid.filters import MAX_DEPTH, MAX_LENGTH, Filter

    suite = _Suite("filter bounds (Filter)")
    for what, expr in FILTERS.items():
        def check(expr=expr):
            from geoshade.errors import InputError
            try:
                Filter(expr)
            except InputError as err:
                msg = str(err)
                assert "\n" not in msg and msg.startswith("filter '") and len(msg) < 300, msg
                assert any(s in msg for s in (f"at most {MAX_LENGTH}", f"{MAX_DEPTH} levels",
                                              "finite float64", "not a valid expression")), msg
                return
            raise AssertionError(f"accepted: {expr[:40]}")
        suite.case(what, check)
    assert Filter("0.1 < PORO <= 0.3 and not (PERMX < 5 or FIPNUM == 2)").names
    suite.check(capsys)


@pytest.mark.gl
def test_filter_bounds_render(capsys, tmp_path):
    suite = _Suite("filter bounds (grid render)")
    f = write_grdecl(_grid(), tmp_path / "good.grdecl")
    out = tmp_path / "out"
    out.mkdir()
    for what, expr in FILTERS.items():
        suite.case(what, lambda expr=expr: clean_failure(
            capsys, ["grid", "render", f, "--filter", expr, "-o", out / "x.png"],
            inputs=[f], watch=[out], names="filter"))
    suite.check(capsys)


# --- the same cases through grid render (reaches GL on good input) ----------------------------
@pytest.mark.gl
def test_damaged_cases_render_cleanly(capsys, tmp_path, good_case):
    """A sample of every kind above through ``geoshade grid render``: refused before any
    output; a truncated UNRST renders its last complete step with the warning."""
    suite = _Suite("grid render on damaged cases")
    out = tmp_path / "out"
    out.mkdir()
    g = _grid()
    damages = [
        ("EGRID cut", "CASE.EGRID", lambda p: p.write_bytes(p.read_bytes()[:3000])),
        ("INIT PORO count", "CASE.INIT",
         lambda p: _put(p, next(s for k, s, _ in _records(p) if k == "PORO") + 12, 1)),
        ("formatted EGRID", "CASE.EGRID",
         lambda p: resfo.write(p, _egrid_entries(g), resfo.Format.FORMATTED)),
        ("ZCORN nan", "CASE.EGRID", lambda p: resfo.write(p, _egrid_entries(
            g, zcorn=np.where(np.arange(2560) == 99, np.nan, np.asarray(g.zcorn).ravel("F"))))),
        ("GRIDHEAD huge", "CASE.EGRID", lambda p: resfo.write(p, _egrid_entries(
            g, head=np.array([1, 100000, 100000, 100000], np.int32)))),
        ("UNRST empty", "CASE.UNRST", lambda p: p.write_bytes(b"")),
    ]
    for what, name, damage in damages:
        egrid = _copy(good_case.parent, tmp_path / "c")
        damage(egrid.parent / name)
        suite.case(what, lambda egrid=egrid, name=name: clean_failure(
            capsys, ["grid", "render", egrid, "-o", out / "x.png"], inputs=[egrid.parent],
            watch=[egrid.parent, out], names=name))

    def truncated_unrst():
        egrid = _copy(good_case.parent, tmp_path / "t")
        u = egrid.parent / "CASE.UNRST"
        records = _records(u)
        last_seq = [s for k, s, _ in records if k == "SEQNUM"][-1]
        u.write_bytes(u.read_bytes()[:last_seq + 3000])
        png, stats = out / "t.png", out / "t.json"
        rc, _out, err = run_cli(capsys, ["grid", "render", egrid, "--property", "SWAT",
                                         "--size", "96x64", "-o", png, "--stats", stats])
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert rc == 0 and len(lines) == 1 and "report step 2 (SEQNUM 20) is incomplete" in \
            lines[0], err
        s = json.loads(stats.read_text())
        assert s["step"] == NSTEPS - 2 and s["active_cells"] == g.nactive
        png.unlink()
        stats.unlink()
    suite.case("truncated UNRST renders its last complete step", truncated_unrst)

    def inverted():
        cells, _ = next(iter(_inverted_cases(g)))
        f = write_grdecl(_inverted(g, cells), tmp_path / "inv.grdecl")
        png, stats = out / "i.png", out / "i.json"
        rc, _out, err = run_cli(capsys, ["grid", "render", f, "--size", "96x64", "-o", png,
                                         "--stats", stats])
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert rc == 0 and len(lines) == 1 and "1 of" in lines[0] and "inverted" in lines[0], err
        s = json.loads(stats.read_text())
        assert s["shown_cells"] == s["active_cells"] == g.nactive and s["faces_drawn"] > 0
        png.unlink()
        stats.unlink()
    suite.case("inverted cell renders with the warning", inverted)
    suite.check(capsys)


@pytest.mark.gl
def test_the_stats_of_a_render_count_the_inverted_cells(capsys, tmp_path):
    g = _grid()
    cells, _first = next(iter(_inverted_cases(g)))
    f = write_grdecl(_inverted(g, cells), tmp_path / "inv.grdecl")
    stats = tmp_path / "inv.json"
    rc, _, err = run_cli(capsys, ["grid", "render", f, "--size", "64x48", "-o",
                                  tmp_path / "inv.png", "--stats", stats])
    assert rc == 0, err
    assert json.loads(stats.read_text())["inverted_cells"] == len(cells)
