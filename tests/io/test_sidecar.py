"""Raw volumes as users have them: shapes inferred for a cube, NRRD (.nhdr/.nrrd written by pynrrd)
and MetaImage (.mhd/.mha written here by hand) headers, given directly or found beside the raw
file; arrays read back bit for bit; bad headers and sizes are one line."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.volumes.raw import fitting_shapes, infer_shape

nrrd = pytest.importorskip("nrrd", reason="NRRD headers need pynrrd (geoshade[nrrd])")


def _volume(dtype, shape_zyx=(5, 6, 7), seed=0):
    rng = np.random.default_rng(seed)
    if np.dtype(dtype).kind == "f":
        return rng.normal(size=shape_zyx).astype(dtype)
    info = np.iinfo(dtype)
    return rng.integers(info.min, info.max, shape_zyx, dtype=dtype, endpoint=True)


def _one_line(exc) -> str:
    text = str(exc.value)
    assert "\n" not in text
    return text


# --- shapes from the file size -----------------------------------------------------------------
@pytest.mark.parametrize("dtype, side", [("uint8", 16), ("uint16", 12), ("float32", 9)])
def test_cube_shape_is_inferred_from_the_size_and_dtype(tmp_path, dtype, side):
    a = _volume(dtype, (side, side, side))
    f = tmp_path / "cube.raw"
    a.tofile(f)
    v = load(f, dtype=dtype)
    assert v.shape_xyz == (side, side, side)
    assert np.array_equal(np.asarray(v.data), a)  # bit for bit
    assert any("a cube" in note for note in v.meta["assumed"])


def test_512_cube_of_uint8_is_inferred_without_reading(tmp_path):
    f = tmp_path / "big.raw"
    with open(f, "wb") as fh:  # a sparse 134,217,728-byte file: 512³ uint8
        fh.truncate(512**3)
    assert infer_shape(f, "uint8")[0] == (512, 512, 512)
    v = load(f, dtype="uint8", spacing=(2.0, 2.0, 2.0), unit="um")
    assert v.shape_xyz == (512, 512, 512) and isinstance(v.data, np.memmap)
    with pytest.raises(InputError) as e:  # as uint16 it is 2**26 values: no cube
        load(f, dtype="uint16")
    line = _one_line(e)
    assert line.startswith(f"{f}: shape: 134217728 bytes = 67108864 uint16 values, not a cube")
    assert "256×256×1024" in line and line.endswith("give --shape NX NY NZ")


def test_shapes_that_fit_are_listed_short():
    fits = fitting_shapes(2 * 300**3)
    assert fits[0] == (300, 300, 600) and all(np.prod(s) == 2 * 300**3 for s in fits)
    assert len(fitting_shapes(2**30)) <= 5


def test_raw_without_dtype_names_the_cubes_its_size_fits(tmp_path):
    f = tmp_path / "c.raw"
    np.zeros(20**3, np.uint16).tofile(f)
    with pytest.raises(InputError) as e:
        load(f)
    line = _one_line(e)
    assert "give --shape NX NY NZ and --dtype" in line and "20×20×20 int16/uint16" in line


# --- NRRD ------------------------------------------------------------------------------------
@pytest.mark.parametrize("dtype", ["uint8", "int16", "uint16", "float32", "float64"])
@pytest.mark.parametrize("endian", ["little", "big"])
def test_nhdr_detached_raw_bit_for_bit(tmp_path, dtype, endian):
    a = _volume(dtype)
    f = tmp_path / "core.nhdr"
    nrrd.write(str(f), a, {"encoding": "raw", "endian": endian, "spacings": [2.5, 2.5, 4.0],
                           "space units": ["um", "um", "um"]},
               detached_header=True, index_order="C")
    v = load(f)
    assert v.shape_xyz == (7, 6, 5) and v.dtype == np.dtype(dtype)
    assert np.array_equal(np.asarray(v.data), a, equal_nan=True)
    assert v.spacing == (2.5, 2.5, 4.0) and v.unit == "um"
    assert isinstance(v.data, np.memmap)  # mapped, not read


def test_nrrd_attached_and_gzip_and_space_directions(tmp_path):
    a = _volume("uint16")
    f = tmp_path / "core.nrrd"
    nrrd.write(str(f), a, {"encoding": "raw", "space": "left-posterior-superior",
                           "space directions": np.diag([0.5, 0.6, 0.7]),
                           "space origin": [1.0, 2.0, 3.0]}, index_order="C")
    v = load(f)
    assert np.array_equal(np.asarray(v.data), a)
    assert v.spacing == (0.5, 0.6, 0.7) and v.origin == (1.0, 2.0, 3.0)
    g = tmp_path / "gz.nhdr"
    nrrd.write(str(g), a, {"encoding": "gzip", "spacings": [1, 1, 2]}, detached_header=True,
               index_order="C")
    vg = load(g, unit="mm")
    assert np.array_equal(np.asarray(vg.data), a) and vg.unit == "mm"


def test_raw_file_with_a_header_beside_it(tmp_path):
    a = _volume("uint16")
    raw = tmp_path / "scan.raw"
    a.tofile(raw)
    nrrd.write(str(tmp_path / "scan.nhdr"), a, {"encoding": "raw", "data file": "scan.raw",
                                                 "spacings": [3.0, 3.0, 3.0],
                                                 "space units": ["um"] * 3},
               detached_header=True, index_order="C")
    v = load(raw)
    assert np.array_equal(np.asarray(v.data), a) and v.spacing == (3.0, 3.0, 3.0)
    assert v.meta["header"].endswith("scan.nhdr")
    # explicit hints win over the header: --spacing/--unit override, --shape ignores it
    assert load(raw, spacing=(1, 1, 1), unit="mm").unit == "mm"
    v2 = load(raw, shape=(7, 6, 5), dtype="uint16")
    assert v2.meta["format"] == "raw"
    with pytest.raises(InputError, match=r"scan\.nhdr beside it gives the shape"):
        load(raw, dtype="uint8")


# --- MetaImage -------------------------------------------------------------------------------
def _write_mhd(path, fields: dict, data_file: str):
    lines = [f"{k} = {v}" for k, v in fields.items()] + [f"ElementDataFile = {data_file}"]
    path.write_text("\n".join(lines) + "\n")


MET = {"uint8": "MET_UCHAR", "int16": "MET_SHORT", "uint16": "MET_USHORT",
       "float32": "MET_FLOAT", "int32": "MET_INT"}


@pytest.mark.parametrize("dtype", list(MET))
@pytest.mark.parametrize("msb", [False, True])
def test_mhd_by_hand_bit_for_bit(tmp_path, dtype, msb):
    a = _volume(dtype, seed=2)
    raw = tmp_path / "core.raw"
    header = b"H" * 17
    raw.write_bytes(header + a.astype(a.dtype.newbyteorder(">" if msb else "<")).tobytes())
    key = "ElementByteOrderMSB" if dtype == "int16" else "BinaryDataByteOrderMSB"
    _write_mhd(tmp_path / "core.mhd", {
        "ObjectType": "Image", "NDims": 3, "DimSize": "7 6 5", "ElementType": MET[dtype],
        key: "True" if msb else "False", "HeaderSize": 17,
        "ElementSpacing": "0.01 0.01 0.02", "Offset": "5 6 7"}, "core.raw")
    for path in (tmp_path / "core.mhd", raw):  # the header, or the raw file beside it
        v = load(path)
        assert np.array_equal(np.asarray(v.data), a)
        assert v.spacing == (0.01, 0.01, 0.02) and v.origin == (5.0, 6.0, 7.0)
        assert v.unit == "mm" and "unit mm" in v.meta["assumed"][0]
    assert load(tmp_path / "core.mhd", unit="um").meta.get("assumed") is None


def test_mha_local_and_header_size_minus_one(tmp_path):
    a = _volume("uint16", seed=3)
    head = "ObjectType = Image\nNDims = 3\nDimSize = 7 6 5\nElementType = MET_USHORT\n" \
           "ElementSpacing = 2 2 2\nElementDataFile = LOCAL\n"
    f = tmp_path / "core.mha"
    f.write_bytes(head.encode() + a.tobytes())
    assert np.array_equal(np.asarray(load(f).data), a)
    raw = tmp_path / "tail.raw"
    raw.write_bytes(b"junk header of any length" + a.tobytes())
    _write_mhd(tmp_path / "tail.mhd", {"NDims": 3, "DimSize": "7 6 5",
                                       "ElementType": "MET_USHORT", "HeaderSize": -1},
               "tail.raw")
    assert np.array_equal(np.asarray(load(tmp_path / "tail.mhd").data), a)


@pytest.mark.parametrize("fields, data_file, message", [
    ({"NDims": 2, "DimSize": "7 6", "ElementType": "MET_UCHAR"}, "d.raw",
     "NDims: expected a 3D volume (3), got 2"),
    ({"NDims": 3, "DimSize": "7 6", "ElementType": "MET_UCHAR"}, "d.raw",
     "DimSize: expected 3 integers, got '7 6'"),
    ({"NDims": 3, "DimSize": "7 6 5", "ElementType": "MET_LONG_LONG"}, "d.raw",
     "ElementType: 'MET_LONG_LONG' is not supported"),
    ({"NDims": 3, "DimSize": "7 6 5", "ElementType": "MET_UCHAR", "CompressedData": "True"},
     "d.raw", "CompressedData: compressed MetaImage data is not supported"),
    ({"NDims": 3, "DimSize": "7 6 5", "ElementType": "MET_UCHAR"}, "missing.raw",
     "ElementDataFile: 'missing.raw' does not exist beside the header"),
    ({"NDims": 3, "DimSize": "7 6 6", "ElementType": "MET_UCHAR"}, "d.raw",
     "file has 210 bytes"),
    ({"NDims": 3, "DimSize": "7 6 5", "ElementType": "MET_UCHAR",
      "BinaryDataByteOrderMSB": "maybe"}, "d.raw", "BinaryDataByteOrderMSB: expected True or"),
])
def test_bad_mhd_is_one_line_naming_the_field(tmp_path, fields, data_file, message):
    (tmp_path / "d.raw").write_bytes(bytes(210))
    _write_mhd(tmp_path / "bad.mhd", fields, data_file)
    with pytest.raises(InputError) as e:
        load(tmp_path / "bad.mhd")
    line = _one_line(e)
    assert message in line and ("bad.mhd" in line or "d.raw" in line)


def test_bad_nrrd_is_one_line(tmp_path):
    f = tmp_path / "bad.nhdr"
    f.write_text("not an nrrd\n")
    with pytest.raises(InputError) as e:
        load(f)
    assert "bad.nhdr: magic: expected an NRRD header" in _one_line(e)
    f.write_text("NRRD0004\ntype: uchar\ndimension: 2\nsizes: 3 4\nencoding: raw\n"
                 "data file: x.raw\n\n")
    with pytest.raises(InputError) as e:
        load(f)
    assert "dimension: expected a 3D volume (3), got 2" in _one_line(e)
    f.write_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 4 5\nencoding: raw\n"
                 "data file: nowhere.raw\n\n")
    with pytest.raises(InputError) as e:
        load(f)
    assert "data file: 'nowhere.raw' does not exist" in _one_line(e)
    f.write_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 4\n\n")
    with pytest.raises(InputError) as e:
        load(f)
    assert "bad.nhdr" in _one_line(e)
