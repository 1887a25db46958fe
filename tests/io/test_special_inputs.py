"""Files a reader finds by itself -- a deck's INCLUDE, an ECLIPSE case's INIT/UNRST, a wells
file -- that are FIFOs (named pipes) or folders: one line naming the file, never a hang."""

from __future__ import annotations

import os
import signal

import pytest
import resfo

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.io.grids.grdecl_writer import write_grdecl
from tests.corruption import run_cli
from tests.io.test_corrupt_grids import _egrid_entries, _grid, _init_entries


@pytest.fixture(autouse=True)
def no_hang():
    """A read that blocks on a FIFO fails the test after 20 s instead of hanging the suite."""
    def boom(*_):
        raise TimeoutError("blocked on a special file")

    old = signal.signal(signal.SIGALRM, boom)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


def one_line(capsys, argv) -> str:
    rc, _out, err = run_cli(capsys, argv)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc == 2 and len(lines) == 1, err
    return lines[0]


@pytest.mark.parametrize("kind", ["fifo", "folder"])
def test_an_include_that_is_not_a_file(capsys, tmp_path, kind):
    write_grdecl(synthetic_grid(4, 3, 2), tmp_path / "grid.inc")
    special = tmp_path / "poro.inc"
    os.mkfifo(special) if kind == "fifo" else special.mkdir()
    deck = tmp_path / "CASE.DATA"
    deck.write_text("RUNSPEC\nGRID\nINCLUDE\n 'grid.inc' /\nINCLUDE\n 'poro.inc' /\n")
    line = one_line(capsys, ["info", deck])
    assert "poro.inc" in line and ("FIFO" in line if kind == "fifo" else "folder" in line)


@pytest.mark.parametrize("sibling", ["INIT", "UNRST"])
def test_an_eclipse_sibling_that_is_a_fifo(capsys, tmp_path, sibling):
    g = _grid()
    egrid = tmp_path / "CASE.EGRID"
    resfo.write(egrid, _egrid_entries(g))
    if sibling == "UNRST":
        resfo.write(tmp_path / "CASE.INIT", _init_entries(g))
    os.mkfifo(tmp_path / f"CASE.{sibling}")
    line = one_line(capsys, ["info", egrid])
    assert f"CASE.{sibling}" in line and "FIFO" in line


def test_a_wells_file_that_is_a_fifo(capsys, tmp_path):
    case = write_grdecl(synthetic_grid(4, 3, 2), tmp_path / "case.grdecl")
    os.mkfifo(tmp_path / "wells.txt")
    line = one_line(capsys, ["grid", "render", case, "--wells", tmp_path / "wells.txt",
                             "-o", tmp_path / "out.png"])
    assert "wells.txt" in line and "FIFO" in line
    assert not (tmp_path / "out.png").exists()
