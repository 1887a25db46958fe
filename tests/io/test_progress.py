"""The progress protocol in io: readers report bytes or steps through ``load(progress=...)``,
never draw a bar, and ``progress`` is not a hint."""

from __future__ import annotations

import sys
import warnings

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.grids.grdecl_writer import write_grdecl
from tests.io.test_ecl import _write_case


class Recorder:
    """A progress callback that records its calls."""

    def __init__(self):
        self.calls: list[tuple[int, int]] = []

    def __call__(self, done, total):
        self.calls.append((done, total))

    def check_complete(self, total: int) -> None:
        assert self.calls, "no progress was reported"
        assert self.calls[-1] == (total, total)
        dones = [d for d, _ in self.calls]
        assert dones == sorted(dones) and all(0 <= d <= t for d, t in self.calls)


@pytest.fixture
def no_tqdm(monkeypatch):
    """io and compute never draw a bar: importing tqdm fails."""
    monkeypatch.setitem(sys.modules, "tqdm", None)


def test_grdecl_reports_bytes_over_its_includes(tmp_path, no_tqdm):
    inc = tmp_path / "inc"
    inc.mkdir()
    write_grdecl(synthetic_grid(6, 5, 4, seed=1), inc / "g.grdecl")
    main = tmp_path / "main.grdecl"
    main.write_text("-- a case\nINCLUDE\n 'inc/g.grdecl' /\n")
    rec = Recorder()
    g = load(main, progress=rec)
    assert g.dims == (6, 5, 4)
    rec.check_complete(main.stat().st_size + (inc / "g.grdecl").stat().st_size)


def test_deck_reports_bytes(tmp_path, no_tqdm):
    write_grdecl(synthetic_grid(3, 2, 2), tmp_path / "g.inc")
    deck = tmp_path / "C.DATA"
    deck.write_text("RUNSPEC\nDIMENS\n 3 2 2 /\nGRID\nINCLUDE\n 'g.inc' /\nEND\n")
    rec = Recorder()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        load(deck, progress=rec)
    rec.check_complete(deck.stat().st_size + (tmp_path / "g.inc").stat().st_size)


def test_egrid_case_reports_report_steps(tmp_path, no_tqdm):
    egrid = _write_case(tmp_path, synthetic_grid(5, 4, 3, seed=4), nsteps=3)
    rec = Recorder()
    g = load(egrid, progress=rec)
    assert len(g.steps) == 3
    rec.check_complete(3)
    assert [d for d, _ in rec.calls] == [1, 2, 3]


def test_progress_is_not_a_hint(tmp_path):
    """Readers without progress get none, and no 'does not apply' error."""
    f = tmp_path / "v.npy"
    np.save(f, np.zeros((2, 3, 4), np.uint8))
    rec = Recorder()
    assert load(f, progress=rec).shape_xyz == (4, 3, 2)
    assert rec.calls == []
    g = write_grdecl(synthetic_grid(3, 2, 2), tmp_path / "g.grdecl")  # a reader with progress
    with pytest.raises(InputError, match="does not apply") as err:
        load(g, shape=(1, 2, 3), progress=rec)
    assert "progress" not in str(err.value).split("it takes")[1]  # not listed as a hint


def test_none_means_no_reports_and_false_is_refused(tmp_path, no_tqdm):
    f = write_grdecl(synthetic_grid(3, 2, 2), tmp_path / "g.grdecl")
    assert load(f, progress=None).dims == (3, 2, 2)
    with pytest.raises(TypeError, match="progress"):
        load(f, progress=False)
