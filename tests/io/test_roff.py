"""ROFF grids and parameters (RMS) through roffio, against xtgeo reading the same files.

The files are made here, small and deterministic: a faulted synthetic grid written by xtgeo
(``splitEnz`` 4 at every node), the same grid with the splits of unfaulted nodes merged to 1
(written with roffio), ASCII copies, and parameters (float with undefined values, discrete with
codes) written by xtgeo.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.grids.grdecl_writer import write_grdecl
from geoshade.io.grids.roff import read_roff, read_roff_parameters
from tests.corruption import clean_failure, run_cli

xtgeo = pytest.importorskip("xtgeo")
roffio = pytest.importorskip("roffio")

DIMS = (7, 6, 4)


def _xtgeo_grid(folder: Path):
    g = synthetic_grid(*DIMS, seed=3, inactive_fraction=0.15)
    src = write_grdecl(g, folder / "src.grdecl")
    return g, xtgeo.grid_from_file(src, fformat="grdecl")


def _ascii(binary: Path, out: Path) -> Path:
    """An ASCII copy of a ROFF file.  roffio writes booleans as True/False, which its own (and
    RMS's) reader do not take: written as 1/0, as RMS does."""
    roffio.write(out, roffio.read(binary), roff_format=roffio.Format.ASCII)
    text = out.read_text()
    out.write_text(re.sub(r"(?m)^False$", "0", re.sub(r"(?m)^True$", "1", text)))
    return out


def _merged_splits(src: Path, out: Path) -> Path:
    """``src`` with splitEnz 1 wherever the four values of a node agree."""
    d = roffio.read(src)
    z4 = np.asarray(d["zvalues"]["data"]).reshape(-1, 4)
    same = (z4 == z4[:, :1]).all(axis=1)
    keep = np.ones(z4.shape, bool)
    keep[same, 1:] = False
    d["zvalues"]["data"] = z4[keep].astype(np.float32)
    d["zvalues"]["splitEnz"] = np.where(same, 1, 4).astype(np.uint8).tobytes()
    roffio.write(out, d)
    return out


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("roff")
    g, xg = _xtgeo_grid(d)
    xg.to_file(d / "geo.roff", fformat="roff")
    poro = xtgeo.GridProperty(xg, name="PORO", values=np.ma.masked_invalid(
        np.where(g.properties["PORO"] > 0.25, np.nan, g.properties["PORO"])))
    poro.to_file(d / "geo--poro.roff", fformat="roff")
    facies = xtgeo.GridProperty(xg, name="FACIES", discrete=True,
                                values=np.ma.masked_equal(g.properties["FIPNUM"] % 3, 2),
                                codes={0: "sand", 1: "shale", 2: "coal"})
    facies.to_file(d / "geo--facies.roff", fformat="roff")
    _merged_splits(d / "geo.roff", d / "merged.roff")
    _ascii(d / "geo.roff", d / "geo_ascii.roffasc")
    return d


def _xtgeo_corners(path: Path) -> np.ndarray:
    """(nx, ny, nz, 8, 3) corners as xtgeo reads them (its corner numbering is ours)."""
    xc = xtgeo.grid_from_file(path).get_xyz_corners()
    return np.stack([np.stack([np.asarray(xc[3 * c + q].values.data) for q in range(3)], -1)
                     for c in range(8)], -2)


@pytest.mark.parametrize("name", ["geo.roff", "merged.roff", "geo_ascii.roffasc"])
def test_roff_grid_equals_xtgeo(files, name):
    path = files / name
    grid = load(path, properties=[])
    xg = xtgeo.grid_from_file(path)
    assert grid.dims == DIMS == tuple(xg.dimensions)
    assert np.array_equal(grid.corners(), _xtgeo_corners(path))
    assert np.array_equal(grid.active, np.asarray(xg.get_actnum().values.data) != 0)
    assert grid.meta["format"] == "ROFF" and not grid.properties
    assert grid.nactive == xg.nactive < grid.ncells


def test_split_kinds_and_the_grdecl_agree(files):
    """Splits 4 everywhere, merged to 1, and ASCII: one grid; the same as the GRDECL source."""
    a = read_roff(files / "geo.roff", properties=[])
    split = np.frombuffer(roffio.read(files / "merged.roff")["zvalues"]["splitEnz"], np.uint8)
    assert 0 < np.count_nonzero(split == 4) < np.count_nonzero(split == 1)  # faults only
    for other in ("merged.roff", "geo_ascii.roffasc"):
        b = read_roff(files / other, properties=[])
        assert np.array_equal(a.zcorn, b.zcorn) and np.array_equal(a.coord, b.coord)
        assert np.array_equal(a.actnum, b.actnum)
    src = load(files / "src.grdecl")
    assert np.array_equal(a.zcorn, src.zcorn) and np.array_equal(a.actnum != 0, src.active)
    # xtgeo wrote map coordinates (the GRDECL's MAPAXES applied) in float32: within 1 m
    xy1 = np.concatenate([src.coord[..., [0, 1]], np.ones((*src.coord.shape[:2], 1))], -1)
    mapped = xy1 @ src.map_transform().T
    assert np.allclose(a.coord[..., :2], mapped[..., :2], rtol=0, atol=1.0)


def test_roff_properties_equal_xtgeo(files):
    grid = load(files / "geo.roff")  # GRID--NAME.roff beside it (the FMU convention)
    assert sorted(grid.properties) == ["FACIES", "PORO"]
    assert grid.meta["files"] == [str(files / "geo--facies.roff"), str(files / "geo--poro.roff")]
    xg = xtgeo.grid_from_file(files / "geo.roff")
    for name, f in (("PORO", "geo--poro.roff"), ("FACIES", "geo--facies.roff")):
        xp = xtgeo.gridproperty_from_file(files / f, fformat="roff", grid=xg)
        ours, theirs = grid.properties[name], np.ma.asarray(xp.values)
        assert ours.shape == theirs.shape == DIMS
        undefined = np.isnan(ours) if ours.dtype.kind == "f" else ours == -999
        assert np.array_equal(undefined, np.ma.getmaskarray(theirs)), name
        assert undefined.any(), name
        assert np.array_equal(ours[~undefined], theirs.data[~undefined].astype(ours.dtype))
    assert grid.properties["FACIES"].dtype == np.int32
    assert grid.properties["PORO"].dtype == np.float32
    assert grid.meta["codes"] == {"FACIES": {0: "sand", 1: "shale", 2: "coal"}}
    only = load(files / "geo.roff", properties=[files / "geo--poro.roff"])
    assert list(only.properties) == ["PORO"]
    props, codes = read_roff_parameters(files / "geo--facies.roff", DIMS)
    assert np.array_equal(props["FACIES"], grid.properties["FACIES"]) and "FACIES" in codes


def test_a_parameter_file_opens_its_grid(files):
    grid = load(files / "geo--poro.roff")
    assert grid.meta["source"] == str(files / "geo.roff")
    assert sorted(grid.properties) == ["FACIES", "PORO"]


def test_info_on_a_roff_grid(capsys, files):
    rc, out, err = run_cli(capsys, ["info", "--json", files / "geo.roff"])
    assert rc == 0, err
    d = json.loads(out)
    assert d["dims"] == list(DIMS) and d["format"] == "ROFF"
    assert sorted(d["properties"]) == ["FACIES", "PORO"]


def _damaged(folder: Path, files: Path) -> list[tuple[str, Path, str]]:
    """(what, file to open, what its one line must say)."""
    good = roffio.read(files / "geo.roff")
    out = []

    def write(name: str, change) -> Path:
        d = {t: dict(v) for t, v in good.items()}
        change(d)
        roffio.write(folder / name, d)
        return folder / name

    out.append(("no zvalues", write("a.roff", lambda d: d.pop("zvalues")),
                "zvalues data: not found"))
    out.append(("short cornerLines", write("b.roff", lambda d: d["cornerLines"].update(
        data=d["cornerLines"]["data"][:-6])), "cornerLines data: expected 336 values, got 330"))

    def split2(d):
        s = bytearray(d["zvalues"]["splitEnz"])
        s[5] = 2
        d["zvalues"]["splitEnz"] = bytes(s)
    out.append(("split 2", write("c.roff", split2),
                "splitEnz: value 2 at node i=1 j=2 k=5 (pillar i, j; level k from the top)"))
    out.append(("zero size", write("d.roff", lambda d: d["dimensions"].update(nX=np.int32(0))),
                "dimensions: 0×6×4 is not positive"))
    cut = folder / "e.roff"
    cut.write_bytes((files / "geo.roff").read_bytes()[:5000])
    out.append(("truncated", cut, "damaged ROFF file"))
    junk = folder / "f.roff"
    junk.write_bytes(b"not a roff file at all")
    out.append(("not ROFF", junk, "damaged ROFF file"))
    wrong = folder / "g--poro.roff"
    xtgeo.GridProperty(ncol=3, nrow=2, nlay=1, name="PORO", values=np.zeros((3, 2, 1))).to_file(
        wrong, fformat="roff")
    out.append(("a parameter without its grid", wrong, "a ROFF parameter file, not a grid"))
    (folder / "h.roff").write_bytes((files / "geo.roff").read_bytes())
    (folder / "h--poro.roff").write_bytes(wrong.read_bytes())
    out.append(("parameters of another grid", folder / "h.roff",
                "dimensions: the parameters are for a 3×2×1 grid; expected 7×6×4"))
    return out


def test_damaged_roff_files_give_one_line(capsys, tmp_path, files):
    for what, path, expect in _damaged(tmp_path, files):
        with pytest.raises(InputError) as ei:
            load(path)
        assert "\n" not in str(ei.value) and expect in str(ei.value), (what, str(ei.value))
        clean_failure(capsys, ["info", path], inputs=[tmp_path], watch=[tmp_path],
                      names=None if "another grid" in what else path.name, expect=expect)


@pytest.mark.gl
def test_param_files_of_any_name(files, tmp_path, capsys):
    """``--param`` / ``load(params=...)``: a ROFF parameter file not named GRID--name.roff (the
    copy below), and a GRDECL property file, added to a grid; values equal xtgeo's."""
    import shutil

    import geoshade
    from geoshade.cli.main import main

    d = tmp_path / "case"
    d.mkdir()
    shutil.copy(files / "geo.roff", d / "model.roff")            # no siblings: no properties
    shutil.copy(files / "geo--poro.roff", d / "porosity_v2.roff")
    bare = geoshade.load(d / "model.roff")
    assert "PORO" not in bare.properties
    g = geoshade.load(d / "model.roff", params=[d / "porosity_v2.roff"])
    ref = xtgeo.gridproperty_from_file(files / "geo--poro.roff", fformat="roff").values
    np.testing.assert_array_equal(np.isnan(g.properties["PORO"]), np.ma.getmaskarray(ref))
    np.testing.assert_allclose(g.properties["PORO"][~np.ma.getmaskarray(ref)],
                               ref.compressed(), rtol=1e-6)
    nx, ny, nz = g.dims
    ntg = np.arange(nx * ny * nz, dtype=np.float32) / (nx * ny * nz)
    inc = d / "ntg.inc"
    inc.write_text("NTG\n" + " ".join(f"{v:.6f}" for v in ntg) + " /\n")
    g2 = geoshade.load(d / "model.roff", params=[d / "porosity_v2.roff", inc])
    np.testing.assert_allclose(g2.properties["NTG"].ravel(order="F"), ntg, atol=1e-6)
    assert g2.meta["param_files"] == [str(d / "porosity_v2.roff"), str(inc)]
    # the CLI: info lists them, grid render colours by one
    assert main(["info", str(d / "model.roff"), "--param", str(d / "porosity_v2.roff"),
                 "--param", str(inc)]) == 0
    out = capsys.readouterr().out
    assert "PORO" in out and "NTG" in out
    stats = tmp_path / "s.json"
    assert main(["grid", "render", str(d / "model.roff"), "--param", str(inc), "--property",
                 "NTG", "--size", "160x120", "-o", str(tmp_path / "p.png"),
                 "--stats", str(stats)]) == 0
    st = json.loads(stats.read_text())
    assert st["property"] == "NTG" and st["color_range"] == pytest.approx(
        [float(ntg.min()), float(ntg.max())], abs=1e-6)
    capsys.readouterr()


def test_param_file_errors_are_one_line(files, tmp_path, capsys):
    import geoshade
    from geoshade.cli.main import main

    g = geoshade.load(files / "geo.roff", properties=[])
    nx, ny, nz = g.dims
    wrong = tmp_path / "wrong.grdecl"
    wrong.write_text("PORO\n 3*0.1 /\n")
    with pytest.raises(InputError, match=rf"wrong.grdecl: PORO: expected {nx * ny * nz} values "
                                         r"\(nx·ny·nz\), got 3"):
        geoshade.load(files / "geo.roff", params=[wrong])
    odd = tmp_path / "odd.grdecl"
    odd.write_text("MYPROP\n 3*0.1 /\n")
    with pytest.raises(InputError, match=rf"odd.grdecl: no cell property of {nx}×{ny}×{nz}"):
        geoshade.load(files / "geo.roff", params=[odd])
    other = tmp_path / "small.grdecl"
    other.write_text("SPECGRID\n 2 2 1 1 F /\nPORO\n 4*0.1 /\n")
    with pytest.raises(InputError, match=r"small\.grdecl: SPECGRID: \(2, 2, 1\) differs"):
        geoshade.load(files / "geo.roff", params=[other])
    with pytest.raises(InputError, match=r"nowhere\.roff: no such file"):
        geoshade.load(files / "geo.roff", params=[tmp_path / "nowhere.roff"])
    vol = tmp_path / "v.npy"
    np.save(vol, np.zeros((2, 2, 2), np.uint8))
    with pytest.raises(InputError, match=r"applies to corner-point grids; this is a VoxelVolume"):
        geoshade.load(vol, params=[wrong])
    assert main(["info", str(files / "geo.roff"), "--param", str(wrong)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
