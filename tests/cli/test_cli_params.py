"""``--param FILE`` (repeatable) on every command that opens a corner-point grid."""

from __future__ import annotations

import json

import numpy as np
import pytest

import geoshade
from geoshade.cli.main import build_parser, main
from geoshade.cli.params import param_hint
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.io.grids.grdecl_writer import write_grdecl


@pytest.mark.parametrize("argv", [["grid", "render", "C.grdecl", "-o", "x.png"],
                                  ["grid", "export", "C.grdecl", "-o", "S.grdecl"],
                                  ["info", "C.grdecl"], ["view", "C.grdecl"],
                                  ["iso", "render", "C.DATA", "--level", "0.5", "-o", "x.png"]])
def test_every_grid_command_takes_param(argv):
    args = build_parser().parse_args([*argv, "--param", "a.roff", "--param", "b.inc"])
    assert param_hint(args) == {"params": ["a.roff", "b.inc"]}
    assert param_hint(build_parser().parse_args(argv)) == {}


@pytest.mark.gl
def test_grdecl_property_file_on_a_grdecl_grid(tmp_path, capsys):
    g = synthetic_grid(5, 4, 3)
    case = write_grdecl(g, tmp_path / "C.grdecl")
    nx, ny, nz = g.dims
    facies = (np.arange(nx * ny * nz) % 3).astype(np.int32)
    (tmp_path / "facies.inc").write_text("SATNUM\n" + " ".join(map(str, facies)) + " /\n")
    out = tmp_path / "S.grdecl"
    assert main(["grid", "export", str(case), "--param", str(tmp_path / "facies.inc"),
                 "--filter", "SATNUM == 2", "-o", str(out)]) == 0
    capsys.readouterr()
    sector = geoshade.load(out)
    assert (sector.properties["SATNUM"][sector.active] == 2).all()
    assert int(sector.active.sum()) == int((facies == 2).sum())
    stats = tmp_path / "s.json"
    assert main(["grid", "render", str(case), "--param", str(tmp_path / "facies.inc"),
                 "--property", "SATNUM", "--size", "160x120", "-o", str(tmp_path / "f.png"),
                 "--stats", str(stats)]) == 0
    assert json.loads(stats.read_text())["property"] == "SATNUM"
    capsys.readouterr()
