"""GRDECL reading (streaming parser); Reek against xtgeo."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import geoshade.io.grids.grdecl as gr
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io.grids.grdecl import read_grdecl
from geoshade.io.grids.grdecl_writer import write_grdecl

# one cell column 2x1x2: 3x2 pillars, 32 ZCORN values, 4 cells
COORD = " ".join(f"{i} {j} 0 {i} {j} 10" for j in range(2) for i in range(3))


def _write(tmp_path, text, name="g.grdecl"):
    f = tmp_path / name
    f.write_text(text)
    return f


def _small(tmp_path, zcorn="8*1 8*2 8*2 8*3", extra="", name="g.grdecl"):
    return _write(tmp_path, f"SPECGRID\n 2 1 2 1 F /\nCOORD\n{COORD} /\nZCORN\n{zcorn} /\n"
                            f"{extra}", name)


def test_syntax_comments_repeats_terminators(tmp_path):
    f = _small(tmp_path, zcorn="-- a comment / with a slash\n 8*1 4*2 2.0 2.0D0\n 2E0 .2e1\n"
                                "8*2 8*3",
               extra="ACTNUM\n 1 0 2*1 / rest of line is a comment 5 6\n"
                     "PORO\n 0.1 0.2 -- c\n 2*0.3 /\nFIPNUM\n 4*2 /\n")
    g = read_grdecl(f)
    assert g.dims == (2, 1, 2)
    assert g.zcorn.dtype == np.float32 and g.coord.dtype == np.float64
    assert np.all(g.zcorn[:, :, 0] == 1) and np.all(g.zcorn[:, :, 1:3] == 2)
    assert np.all(g.zcorn[:, :, 3] == 3)
    assert g.actnum.ravel(order="F").tolist() == [1, 0, 1, 1] and g.nactive == 3
    assert g.properties["PORO"].ravel(order="F").tolist() == pytest.approx([0.1, 0.2, 0.3, 0.3])
    assert g.properties["FIPNUM"].dtype == np.int32
    # COORD: pillar (i, j) holds its 6 numbers, memory in file order
    assert g.coord[2, 1].tolist() == [2, 1, 0, 2, 1, 10]
    assert g.coord.transpose(1, 0, 2).flags.c_contiguous


def test_numpy_and_numba_paths_and_tiny_chunks_agree(tmp_path, monkeypatch):
    g = synthetic_grid(7, 5, 4, seed=3)
    f = write_grdecl(g, tmp_path / "s.grdecl")
    text = f.read_text()
    # comments, CRLF, tokens right at chunk ends
    f2 = _write(tmp_path, "-- head\r\n" + text.replace("ZCORN\n", "ZCORN -- z / comment\n"),
                "s2.grdecl")
    ref = read_grdecl(f)
    monkeypatch.setattr(gr, "CHUNK_BYTES", 7)
    monkeypatch.setattr(gr, "SCRATCH_VALUES", 5)
    monkeypatch.setattr(gr, "SMALL_VALUES", 0)  # always the numba scanner
    for other in (read_grdecl(f), read_grdecl(f2)):
        for name in ("coord", "zcorn", "actnum"):
            assert np.array_equal(getattr(other, name), getattr(ref, name)), name
        for k, v in ref.properties.items():
            assert np.array_equal(other.properties[k], v), k
        assert [len(x.faces) for x in other.faults] == [len(x.faces) for x in ref.faults]


def test_include_nested_relative_and_quoted(tmp_path):
    sub = tmp_path / "inc"
    (sub / "deeper").mkdir(parents=True)
    (sub / "deeper" / "z.inc").write_text("ZCORN\n 8*1 16*2 8*3 /\n")
    (sub / "a.inc").write_text("COORD\n" + COORD + " /\nINCLUDE\n 'deeper/z.inc' /\n")
    f = _write(tmp_path, "SPECGRID\n 2 1 2 1 F /\nINCLUDE\n 'inc/a.inc' /\n")
    g = read_grdecl(f)
    assert g.dims == (2, 1, 2) and float(g.zcorn.max()) == 3.0
    assert len(g.meta["files"]) == 3


def test_box_and_unknown_keyword_warning(tmp_path):
    f = _small(tmp_path, extra="BOX\n 2 2 1 1 1 2 /\nPERMX\n 5 6 /\nENDBOX\n"
                               "FOO\n 1 2 3 /\nNOECHO\nBAR\n 'x' /\n")
    with pytest.warns(UserWarning) as rec:
        g = read_grdecl(f)
    msgs = [str(w.message) for w in rec]
    assert f"{f}: keyword FOO is not used by the grid reader; skipped" in msgs
    assert any("keyword BAR" in m for m in msgs) and not any("NOECHO" in m for m in msgs)
    p = g.properties["PERMX"]
    assert np.isnan(p[0]).all() and p[1, 0].tolist() == [5, 6]


def _err(path) -> str:
    with pytest.raises(InputError) as ei, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        read_grdecl(path)
    msg = str(ei.value)
    assert "\n" not in msg
    return msg


@pytest.mark.parametrize("small", [True, False])
def test_errors_name_file_keyword_and_expected(tmp_path, monkeypatch, small):
    if not small:
        monkeypatch.setattr(gr, "SMALL_VALUES", 0)
    f = _small(tmp_path, zcorn="8*1 8*2 8*2 7*3")
    assert _err(f) == f"{f}: ZCORN: expected 32 values (2·nx·2·ny·2·nz), got 31"
    f = _small(tmp_path, zcorn="8*1 8*2 8*2 8*3 4")
    assert _err(f) == f"{f}: ZCORN: expected 32 values (2·nx·2·ny·2·nz), got 33"
    f = _small(tmp_path, zcorn="8*1 8*2 8*2 9*3")
    assert _err(f) == (f"{f}: ZCORN: repeat '9*3' at value 25 overruns the 32 values "
                       "(2·nx·2·ny·2·nz)")
    f = _small(tmp_path, extra="PORO\n 0.1 0.2 abc 0.4 /\n")
    assert _err(f) == (f"{f}: PORO: non-numeric token 'abc' at value 3; expected 4 numbers "
                       "(nx·ny·nz)")
    f = _small(tmp_path, extra="ACTNUM\n 1 1 1 /\n")
    assert "ACTNUM: expected 4 values (nx·ny·nz), got 3" in _err(f)
    f = _write(tmp_path, f"SPECGRID\n 2 1 2 1 F /\nCOORD\n{COORD} 7 /\n")
    assert "COORD: expected 36 values (6·(nx+1)·(ny+1)), got 37" in _err(f)
    f = _write(tmp_path, f"SPECGRID\n 2 1 2 1 F /\nCOORD\n{COORD}\n")
    assert "COORD: no '/' terminator before the end of the file" in _err(f)


def test_structural_errors(tmp_path):
    f = _write(tmp_path, f"COORD\n{COORD} /\n")
    assert _err(f) == f"{f}: COORD comes before SPECGRID/DIMENS: the grid size is unknown"
    f = _write(tmp_path, "SPECGRID\n 2 1 2 1 F /\nINCLUDE\n 'nope/missing.inc' /\n")
    msg = _err(f)
    assert msg.startswith(f"{f}: INCLUDE 'nope/missing.inc': no such file")
    f = _write(tmp_path, "SPECGRID\n 2 1 2 1 F /\n")
    assert "no COORD or ZCORN keyword" in _err(f)
    f = _write(tmp_path, "SPECGRID\n 2 x 2 /\n")
    assert "SPECGRID: expected 3 positive integers NX NY NZ" in _err(f)
    f = _small(tmp_path, extra="FAULTS\n 'F' 1 3 1 1 1 1 X /\n/\n")
    assert "FAULTS F: box 1-3, 1-1, 1-1 is outside the grid (2, 1, 2)" in _err(f)


def test_faults_keyword(tmp_path):
    f = _small(tmp_path, extra="FAULTS\n'F1' 1 1 1 1 1 2 I / comment\n'F1' 2 2 1 1 2 2 Z- /\n"
                               " 'F2' 1 2 1 1 1 1 J /\n/\n")
    g = read_grdecl(f)
    assert [x.name for x in g.faults] == ["F1", "F2"]
    assert g.faults[0].faces.tolist() == [[0, 0, 0, 0], [0, 0, 1, 0], [1, 0, 1, 5]]
    assert g.faults[1].faces.tolist() == [[0, 0, 0, 1], [1, 0, 0, 1]]


# --- Reek against xtgeo ----------------------------------------------------------------------
@pytest.fixture(scope="module")
def reek(shared_data):
    d = shared_data / "reek_cornerpoint" / "include" / "grid"
    if not (d / "reek.grid").is_file():
        pytest.skip("Reek GRDECL is absent")
    return d


def xtgeo_zcorn(xg, dims) -> np.ndarray:
    """xtgeo's per-node (ncol+1, nrow+1, nlay+1, 4) ZCORN -> our (2nx, 2ny, 2nz)."""
    nx, ny, nz = dims
    zx = xg._zcornsv
    out = np.empty((2 * nx, 2 * ny, 2 * nz), np.float32)
    for a in (0, 1):
        for b in (0, 1):
            q = (1 - a) + 2 * (1 - b)  # the cell's quadrant around its node: SW SE NW NE
            for c in (0, 1):
                out[a::2, b::2, c::2] = zx[a:a + nx, b:b + ny, c:c + nz, q]
    return out


@pytest.mark.data
def test_reek_grdecl_equals_xtgeo(reek):
    xtgeo = pytest.importorskip("xtgeo")
    g = read_grdecl(reek / "reek.grid")
    xg = xtgeo.grid_from_file(reek / "reek.grid", fformat="grdecl")
    assert g.dims == tuple(xg.dimensions) == (40, 64, 14)
    assert g.nactive == xg.nactive == 35820
    assert np.array_equal(g.actnum != 0, xg._actnumsv != 0)
    assert np.array_equal(g.zcorn, xtgeo_zcorn(xg, g.dims))
    # xtgeo keeps COORD in float32 precision; by default it applies MAPAXES
    local = xtgeo.grid_from_file(reek / "reek.grid", fformat="grdecl", relative_to="origin")
    c = np.asarray(g.coord)
    assert np.array_equal(c.astype(np.float32), local._coordsv.astype(np.float32))
    m = g.map_transform()
    for off in (0, 3):
        xy = c[..., off:off + 2] @ m[:2, :2].T + m[:2, 2]
        assert np.allclose(xy, xg._coordsv[..., off:off + 2], rtol=0, atol=1.0)  # f32 at 6e6
    # cell corners of an active cell
    corners = g.corners((slice(5, 6), slice(7, 8), slice(3, 4)))[0, 0, 0]
    xc = np.array(xg.get_xyz_cell_corners((6, 8, 4))).reshape(8, 3)
    xc[:, :2] -= m[:2, 2]
    assert np.allclose(corners, xc, atol=1e-3)
    for name in ("PORO", "PERMX", "PERMZ"):
        src = reek / ("reek.poro" if name == "PORO" else "reek.perm")
        mine = read_grdecl_props(src, g)[name]
        xp = xtgeo.gridproperty_from_file(src, fformat="grdecl", name=name, grid=xg)
        assert np.array_equal(mine[g.active], np.asarray(xp.values, np.float32)[g.active])


def read_grdecl_props(path, grid):
    """A properties-only file with the grid's SPECGRID prepended (include it)."""
    import tempfile
    from pathlib import Path

    d = Path(tempfile.mkdtemp())
    nx, ny, nz = grid.dims
    (d / "p.grdecl").write_text(f"SPECGRID\n {nx} {ny} {nz} 1 F /\nINCLUDE\n '{path}' /\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        b = gr.GridBuilder(d / "p.grdecl")
        b.parse(d / "p.grdecl")
    return b.props


@pytest.mark.data
def test_reek_faults_and_progress(reek, tmp_path):
    (tmp_path / "all.grdecl").write_text(
        f"INCLUDE\n '{reek / 'reek.grid'}' /\nINCLUDE\n '{reek / 'reek.faults'}' /\n"
        f"INCLUDE\n '{reek / 'reek.poro'}' /\n")
    seen = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = read_grdecl(tmp_path / "all.grdecl", progress=lambda d, t: seen.append((d, t)))
    assert [f.name for f in g.faults] == ["F1", "F2", "F3", "F4", "F5", "F6"]
    assert "PORO" in g.properties
    total = sum(p.stat().st_size for p in (tmp_path / "all.grdecl", reek / "reek.grid",
                                           reek / "reek.faults", reek / "reek.poro"))
    assert seen[-1] == (total, total)


def test_small_grids_need_no_numba(tmp_path, monkeypatch):
    """Small arrays (repeats, comments, quotes elsewhere) take the numpy path."""
    monkeypatch.setattr(gr, "_KERNELS", {})

    def no_numba():
        raise AssertionError("the numba scanner was used")

    monkeypatch.setattr(gr, "_kernels", no_numba)
    f = _small(tmp_path, zcorn="-- comment\n 8*1 4*2 2 2 2 2 8*2 8*3",
               extra="ACTNUM\n 2*1 0 1 /\nFOO\n 'a' 1 /\nSWOF\n 0 0 1 0\n 1 1 0 0 /\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = read_grdecl(f)
    assert g.nactive == 3 and float(g.zcorn.sum()) == 8 + 2 * 16 + 3 * 8
