"""Well trajectory files for ``--wells``: geoshade's format, RMS ASCII (equal to xtgeo's read)
and CSV, chosen by suffix and content; every error one line naming the file and line."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io.grids.welltraj import read_csv_wells, read_rms_well, read_wells, well_format
from geoshade.models.wells import Trajectory

RMS = """1.0
Unknown
OP 1 456000.0 5930000.0 25.0
3
MD UNK lin
Zonelog DISC 1 Upper 2 Lower
Poro UNK lin
456000.0 5930000.0 1500.0 1525.0 1 0.25
456010.0 5930002.5 1600.0 1626.0 2 -999
-999 5930004.0 1650.0 1677.0 2 0.2
456030.0 5930006.0 1700.0 1730.0 -999 0.1
"""


def test_rms_ascii_equals_xtgeo(tmp_path):
    xtgeo = pytest.importorskip("xtgeo")
    f = tmp_path / "OP_1.rmswell"
    f.write_text(RMS)
    ours = read_wells(f)
    assert len(ours) == 1 and isinstance(ours[0], Trajectory)
    w = ours[0]
    ref = xtgeo.well_from_file(f, fformat="rms_ascii")
    df = ref.get_dataframe()
    keep = df[["X_UTME", "Y_UTMN", "Z_TVDSS"]].notna().all(axis=1).to_numpy()
    assert w.name == ref.name == "OP 1"
    np.testing.assert_array_equal(w.points, df[["X_UTME", "Y_UTMN", "Z_TVDSS"]].to_numpy()[keep])
    np.testing.assert_array_equal(w.md, df["MD"].to_numpy()[keep])


def test_rms_written_by_xtgeo_reads_back(tmp_path):
    xtgeo = pytest.importorskip("xtgeo")
    import pandas as pd

    df = pd.DataFrame({"X_UTME": [1.0, 2.0, 3.0], "Y_UTMN": [4.0, 5.0, 6.0],
                       "Z_TVDSS": [1000.0, 1100.0, 1200.5], "GR": [10.0, 20.0, np.nan]})
    f = tmp_path / "W2.w"
    xtgeo.Well(rkb=0.0, xpos=1.0, ypos=4.0, wname="W2", df=df).to_file(f)
    w = read_wells(f)[0]
    assert w.name == "W2" and w.points.tolist() == df.iloc[:, :3].to_numpy().tolist()
    assert np.isnan(w.md).all()


def test_rms_found_by_content_without_its_suffix(tmp_path):
    f = tmp_path / "op1.txt"
    f.write_text(RMS)
    assert well_format(f) == "rms" and read_wells(f)[0].points.shape == (3, 3)


def test_csv_with_and_without_header(tmp_path):
    plain = tmp_path / "a.csv"
    plain.write_text("A, 0, 0, 1000, 1000\nB, 5, 5, 900\nA, 0, 1, 1100, 1101\n")
    with_header = tmp_path / "b.txt"
    with_header.write_text("md;Well;X;Y;TVD;comment\n1000;A;0;0;1000;top\n1101;A;0;1;1100;\n"
                           ";B;5;5;900;\n")
    for f in (plain, with_header):
        wells = read_wells(f)
        assert [w.name for w in wells] == ["A", "B"]
        assert wells[0].points.tolist() == [[0, 0, 1000], [0, 1, 1100]]
        assert wells[0].md.tolist() == [1000, 1101] and np.isnan(wells[1].md).all()
    assert well_format(with_header) == "csv"


def test_geoshade_format_takes_an_md_column(tmp_path):
    f = tmp_path / "w.txt"
    f.write_text("WELL A\n0 0 1000 1005\n0 0 1100 1106\nWELL B\n1 1 900\n")
    a, b = read_wells(f)
    assert isinstance(a, Trajectory) and a.md.tolist() == [1005, 1106]
    assert b.points.tolist() == [[1, 1, 900]] and not isinstance(b, Trajectory)


@pytest.mark.parametrize("name, text, message", [
    ("e.txt", "", ": no wells; expected 'WELL name' lines"),
    ("g.txt", "hello world\n", ":1: expected a 'WELL name' line before 'hello world'"),
    ("m.txt", "WELL A\n0 0 1 2\n0 0 2\n", ":1: well A mixes points with and without md"),
    ("p.txt", "WELL A\n0 x 1\n", ":2: expected a point as 3 numbers 'x y z' (or 4"),
    ("c.csv", "A,0,0\n", ":1: expected name, x, y, z[, md], got 3 values"),
    ("d.csv", "A,0,0,zz\n", ":1: expected numbers x, y, z"),
    ("h.csv", "well,x,y\nA,0,0\n", ":1: the header well, x, y has no column for z"),
    ("q.csv", "A,0,0,1,q\n", ":1: expected a number for md, got 'q'"),
    ("r.rmswell", "1.0\nUnknown\nW1 1 2\n1\nMD UNK lin\n1 2 3\n", ":6: expected 4 values"),
    ("s.rmswell", "1.0\nUnknown\nW1\n0\n", ":3: expected the well header 'name x y [rkb]'"),
    ("t.rmswell", "1.0\nUnknown\nW1 1 2\nmany\n", ":4: expected the number of logs"),
    ("u.rmswell", "1.0\nUnknown\nW1 1 2\n0\n-999 2 3\n", "well W1 has no trajectory point"),
    ("v.rmswell", "1.0\nUnknown\nW1 1 2\n0\n1 2 3\n1 b 3\n", ":6: expected numbers"),
])
def test_errors_are_one_line_naming_file_and_line(tmp_path, name, text, message):
    f = tmp_path / name
    f.write_text(text)
    with pytest.raises(InputError) as err:
        read_wells(f)
    line = str(err.value)
    assert "\n" not in line and line.startswith(str(f)) and message in line


def test_readers_directly(tmp_path):
    f = tmp_path / "x.csv"
    f.write_text("name,x,y,z\nA,1,2,3\n")
    assert read_csv_wells(f)[0].points.tolist() == [[1, 2, 3]]
    r = tmp_path / "y.w"
    r.write_text(RMS)
    assert read_rms_well(r).name == "OP 1"


def test_rms_file_with_several_wells_equals_xtgeo_per_well(tmp_path):
    """Wells written one by one by xtgeo, then concatenated into one file: every well is read
    (the second one was refused before), each equal to xtgeo's reading of its own file."""
    xtgeo = pytest.importorskip("xtgeo")
    import pandas as pd

    rng = np.random.default_rng(3)
    parts = []
    for n, logs in enumerate(({"MD": 1}, {}, {"GR": 1, "MD": 1})):   # different log lists
        m = 4 + n
        cols = {"X_UTME": 100.0 * n + rng.random(m), "Y_UTMN": 50.0 + rng.random(m),
                "Z_TVDSS": 1000.0 + 10 * np.arange(m)}
        cols.update({k: 1000.0 + 10 * np.arange(m) + 0.5 for k in logs})
        f = tmp_path / f"W{n}.w"
        xtgeo.Well(rkb=10.0, xpos=float(cols["X_UTME"][0]), ypos=50.0, wname=f"WELL {n}",
                   df=pd.DataFrame(cols)).to_file(f)
        parts.append(f)
    both = tmp_path / "all.w"
    both.write_text("".join(f.read_text() for f in parts))
    ours = read_wells(both)
    assert [w.name for w in ours] == ["WELL 0", "WELL 1", "WELL 2"]
    for w, f in zip(ours, parts, strict=True):
        df = xtgeo.well_from_file(f, fformat="rms_ascii").get_dataframe()
        np.testing.assert_array_equal(w.points, df[["X_UTME", "Y_UTMN", "Z_TVDSS"]].to_numpy())
        md = df["MD"].to_numpy() if "MD" in df else np.full(len(df), np.nan)
        np.testing.assert_array_equal(w.md, md)


def test_rms_several_wells_errors_name_the_line(tmp_path):
    f = tmp_path / "two.w"
    f.write_text(RMS + "1.0\nUnknown\nB 0 0\nx\n")
    with pytest.raises(InputError) as ei:
        read_wells(f)
    assert str(ei.value) == f"{f}:15: expected the number of logs (an integer), got 'x'"
    f.write_text(RMS + "1.0\nUnknown\n")
    with pytest.raises(InputError, match="the well starting at line 12 has 2 lines"):
        read_wells(f)
