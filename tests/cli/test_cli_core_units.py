"""Micro-CT as users have it, from the command line: spacing and unit reach the porosity plot's
axis, the CSV and the JSON; --select auto (Otsu); --roi cylinder and --mask; headers beside raw
files; and the bad inputs are one line."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from geoshade.cli.main import main
from geoshade.errors import MissingExtraError
from tests.compute.test_roi import core_in_air, cylinder_mask


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


@pytest.fixture
def labels(monkeypatch):
    """The x/y labels and title of every matplotlib figure saved."""
    from matplotlib.figure import Figure

    seen: list[tuple[str, str, str]] = []
    save = Figure.savefig

    def spy(self, *a, **k):
        ax = self.axes[0]
        seen.append((ax.get_xlabel(), ax.get_ylabel(), ax.get_title()))
        return save(self, *a, **k)

    monkeypatch.setattr(Figure, "savefig", spy)
    return seen


@pytest.fixture
def air_raw(tmp_path):
    vol, cyl = core_in_air(40, seed=3)
    a = np.asarray(vol.data)
    f = tmp_path / "core.raw"
    a.tofile(f)  # 40³ uint8: the shape is inferred from the size
    return f, a, cyl


def test_spacing_and_unit_reach_plot_csv_and_json(capsys, tmp_path, air_raw, labels):
    f, a, _ = air_raw
    out = [tmp_path / n for n in ("p.png", "p.csv", "p.json")]
    rc, _, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", "--spacing", 2.5, 2.5,
                     4.0, "--unit", "um", "--select", 0, 100, "-o", out[0], "--csv", out[1],
                     "--json", out[2], "--sample", "none")  # every voxel, air too
    assert rc == 0, err
    assert labels[-1][0] == "z (µm)" and labels[-1][1] == "porosity (fraction)"
    rows = list(csv.DictReader(out[1].open()))
    assert list(rows[0]) == ["z", "z_um", "count", "voxels", "porosity"]
    assert [float(r["z_um"]) for r in rows] == [(k + 0.5) * 4.0 for k in range(40)]
    d = json.loads(out[2].read_text())
    assert d["unit"] == "um" and d["spacing"] == 4.0 and d["coordinate"] == "z_um"
    assert d["coordinates"] == [(k + 0.5) * 4.0 for k in range(40)]
    assert d["porosity"] == np.count_nonzero(a <= 100) / a.size
    # along x: the x spacing; a spacing without a unit is still used (no longer dropped)
    rc, _, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", "--spacing", 2.5, 2.5,
                     4.0, "--select", 0, 100, "--axis", "x", "-o", out[0], "--csv", out[1],
                     "--json", out[2])
    assert rc == 0, err
    assert labels[-1][0] == "x (spacing units)"
    assert list(next(csv.DictReader(out[1].open()))) == ["x", "x_coord", "count", "voxels",
                                                          "porosity"]
    d = json.loads(out[2].read_text())
    assert d["spacing"] == 2.5 and d["unit"] == "" and d["coordinates"][1] == 1.5 * 2.5
    # no spacing given: voxel indices
    rc, _, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", "--select", 0, 100,
                     "-o", out[0], "--json", out[2])
    assert rc == 0, err
    assert labels[-1][0] == "z (voxels)" and json.loads(out[2].read_text())["spacing"] is None


def test_unit_overrides_a_header_and_info_shows_it(capsys, tmp_path):
    nrrd = pytest.importorskip("nrrd")
    a = np.arange(6 * 5 * 4, dtype=np.uint16).reshape(4, 5, 6)
    nrrd.write(str(tmp_path / "v.nhdr"), a, {"encoding": "raw", "spacings": [1.5, 1.5, 2.0],
                                             "space units": ["mm"] * 3},
               detached_header=True, index_order="C")
    rc, text, err = run(capsys, "info", tmp_path / "v.nhdr", "--json", "--unit", "um")
    assert rc == 0, err
    d = json.loads(text)
    assert d["unit"] == "um" and d["spacing"] == [1.5, 1.5, 2.0] and d["shape_xyz"] == [6, 5, 4]


def test_info_suggests_otsu_and_multi_otsu(capsys, air_raw):
    filters = pytest.importorskip("skimage.filters")
    f, a, _ = air_raw
    rc, text, err = run(capsys, "info", f, "--dtype", "uint8", "--json")
    assert rc == 0, err
    th = json.loads(text)["threshold"]
    assert th["otsu"] == float(filters.threshold_otsu(a))
    assert th["multiotsu"] == [float(v) for v in filters.threshold_multiotsu(a)]
    assert th["pore_select"] == [float(a.min()), th["otsu"]]
    rc, text, _ = run(capsys, "info", f, "--dtype", "uint8")
    assert f"threshold Otsu {th['otsu']:g}; multi-Otsu" in text
    lo, hi = th["pore_select"]  # what --select auto takes: Otsu inside the sample found in air
    assert f"pores    --select {lo:g} {hi:g} (or --select auto): {th['pore_text']}" in text
    assert "the air around the sample included" in th["pore_text"]


def test_select_auto_with_a_fitted_cylinder(capsys, tmp_path, air_raw, labels):
    filters = pytest.importorskip("skimage.filters")
    f, a, (cx, cy, r) = air_raw
    js, csv_path = tmp_path / "p.json", tmp_path / "p.csv"
    rc, text, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", "--select", "auto",
                        "--roi", "cylinder", "-o", tmp_path / "p.png", "--json", js,
                        "--csv", csv_path)
    assert rc == 0, err
    d = json.loads(js.read_text())
    roi = d["roi"]
    assert roi["kind"] == "cylinder" and roi["fitted"]
    assert abs(roi["cx"] - cx) < 0.3 and abs(roi["cy"] - cy) < 0.3 and abs(roi["r"] - r) < 0.6
    inside = np.broadcast_to(cylinder_mask(a.shape, roi["cx"], roi["cy"], roi["r"]), a.shape)
    t = float(filters.threshold_otsu(a[inside]))
    assert d["select_auto"]["threshold"] == t and d["select"] == [float(a[inside].min()), t]
    sel = inside & (a <= t)
    assert d["porosity"] == sel.sum() / inside.sum() and d["quantity"] == "porosity"
    assert d["voxels"] == inside.sum(axis=(1, 2)).tolist()
    assert text.startswith(f"porosity {d['porosity']:.4f}") and "Otsu" in text
    assert f"dark phase ≤ Otsu {t:,.6g} taken as pore" in labels[-1][2]
    assert "counted inside cylinder:" in labels[-1][2]
    assert d["select_auto"]["text"] in text and d["sample"]["status"] == "roi"


def test_mask_file_and_selected_fraction(capsys, tmp_path, air_raw, labels):
    f, a, (cx, cy, r) = air_raw
    m = np.broadcast_to(cylinder_mask(a.shape, cx, cy, r), a.shape).astype(np.uint8)
    (tmp_path / "mask.raw").write_bytes(m.tobytes())
    js, csv_path = tmp_path / "g.json", tmp_path / "g.csv"
    rc, text, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", "--select", 150, 255,
                        "--mask", tmp_path / "mask.raw", "-o", tmp_path / "g.png", "--json", js,
                        "--csv", csv_path)
    assert rc == 0, err
    d = json.loads(js.read_text())
    sel = (m != 0) & (a >= 150)
    assert d["porosity"] == sel.sum() / (m != 0).sum()
    assert d["quantity"] == "selected fraction" and text.startswith("selected fraction ")
    assert list(next(csv.DictReader(csv_path.open())))[-1] == "selected_fraction"
    assert labels[-1][1] == "selected fraction (fraction)"


@pytest.mark.gl
def test_render_with_roi_records_it_in_the_stats(capsys, tmp_path, air_raw):
    filters = pytest.importorskip("skimage.filters")
    f, a, (cx, cy, r) = air_raw
    stats = tmp_path / "s.json"
    rc, _, err = run(capsys, "core", "render", f, "--dtype", "uint8", "--select", "auto",
                     "--roi", f"cylinder:{cx},{cy},{r}", "--size", "96x72", "--frames", 1,
                     "-o", tmp_path / "o.png", "--stats", stats)
    assert rc == 0, err
    s = json.loads(stats.read_text())
    inside = np.broadcast_to(cylinder_mask(a.shape, cx, cy, r), a.shape)
    t = float(filters.threshold_otsu(a[inside]))
    assert s["select"] == [float(a[inside].min()), t] and s["select_auto"]["threshold"] == t
    assert s["roi"]["text"] == f"cylinder:{cx:g},{cy:g},{r:g}"
    assert s["voxels_selected"] == int((inside & (a <= t)).sum())  # the air is not drawn


@pytest.mark.parametrize("argv, message", [
    (("--select", 0, 9, "--roi", "sphere:1,2,3"),
     "roi: expected 'cylinder' (fitted to the sample), 'cylinder:CX,CY,R' (voxels) or 'sample' "
     "(detected in air), got "
     "'sphere:1,2,3'"),
    (("--select", 0, 9, "--roi", "cylinder:1,2,-4"), "roi: cylinder radius must be > 0 voxels"),
    (("--select", "auto", "9"), "--select: expected two finite numbers LO HI or 'auto'"),
    (("--select", "1", "2", "3"), "--select: expected two finite numbers LO HI or 'auto'"),
])
def test_bad_roi_and_select_are_one_line(capsys, tmp_path, air_raw, argv, message):
    f, _, _ = air_raw
    rc, _, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", *argv,
                     "-o", tmp_path / "p.png")
    assert rc == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "p.png").exists()


def test_size_that_fits_no_cube_and_bad_header_are_one_line(capsys, tmp_path):
    f = tmp_path / "odd.raw"
    np.zeros(2 * 300**3 // 300, np.uint8).tofile(f)  # 600×300 values: no cube
    rc, _, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", "--select", 0, 1, "-o",
                     tmp_path / "p.png")
    assert rc == 2 and len(err.strip().splitlines()) == 1
    assert "odd.raw: shape: 180000 bytes = 180000 uint8 values, not a cube" in err
    assert "give --shape NX NY NZ" in err
    h = tmp_path / "bad.mhd"
    h.write_text("NDims = 3\nDimSize = 4 4\nElementType = MET_UCHAR\nElementDataFile = x.raw\n")
    rc, _, err = run(capsys, "info", h)
    assert rc == 2 and "bad.mhd: DimSize: expected 3 integers, got '4 4'" in err
    assert len(err.strip().splitlines()) == 1


def _hide(monkeypatch, *names):
    import sys

    for name in names:
        for key in [k for k in sys.modules if k == name or k.startswith(name + ".")]:
            monkeypatch.setitem(sys.modules, key, None)
        monkeypatch.setitem(sys.modules, name, None)


def test_missing_extras_are_one_line(capsys, tmp_path, air_raw, monkeypatch):
    f, _, _ = air_raw
    (tmp_path / "v.nhdr").write_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 40 40 40\n"
                                     "encoding: raw\ndata file: core.raw\n\n")
    _hide(monkeypatch, "skimage", "nrrd")
    rc, _, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", "--select", "auto",
                     "-o", tmp_path / "p.png")
    assert rc == MissingExtraError.exit_code and len(err.strip().splitlines()) == 1
    assert err.strip().endswith("needs skimage, which is not installed: pip install "
                                "'geoshade[threshold]'")
    rc, _, err = run(capsys, "info", tmp_path / "v.nhdr")
    assert rc == MissingExtraError.exit_code
    assert err.strip() == ("geoshade: error: reading NRRD volume needs nrrd, which is not "
                           "installed: pip install 'geoshade[nrrd]'")
    rc, text, err = run(capsys, "info", f, "--dtype", "uint8")  # info still describes it
    assert rc == 0, err
    assert "threshold suggesting a threshold (Otsu) needs skimage" in text
