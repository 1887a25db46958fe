"""TIFF stacks and folders of TIFF slices."""

from __future__ import annotations

import numpy as np
import pytest
import tifffile
import zarr

from geoshade.errors import InputError
from geoshade.io import load, read_tiff, read_tiff_folder
from geoshade.io.volumes.tiff import list_slices

#: tifffile's lazy zarr stores need zarr >= 3
ZARR3 = int(zarr.__version__.split(".")[0]) >= 3


def _needs_zarr3(lazy, path):
    """On zarr 2, lazy=True must fail with a clear message instead of reading."""
    if lazy and not ZARR3:
        with pytest.raises(InputError, match=r"lazy TIFF reading needs .*zarr >= 3"):
            (read_tiff if path.is_file() else read_tiff_folder)(path, lazy=True)
        pytest.skip("lazy TIFF reading needs zarr >= 3")


def _stack(dtype=np.uint16, shape=(4, 5, 6)):
    return np.random.default_rng(3).integers(0, 250, size=shape).astype(dtype)


def test_imagej_stack_spacing_and_unit(tmp_path):
    a = _stack()
    f = tmp_path / "ij.tif"
    tifffile.imwrite(
        f, a, imagej=True, resolution=(1 / 0.5, 1 / 0.5), metadata={"spacing": 2.0, "unit": "um"}
    )
    vol = read_tiff(f)
    np.testing.assert_array_equal(vol.data, a)
    assert vol.shape_xyz == (6, 5, 4)
    assert vol.spacing == (0.5, 0.5, 2.0)
    assert vol.unit == "um"
    assert isinstance(vol.data, np.memmap) or isinstance(vol.data.base, np.memmap)
    # tifffile stores a plain 3D ImageJ stack as channels: the reader says it took C as z
    assert any("taken as z" in s for s in vol.meta.get("assumed", []))


def test_imagej_zyx_no_assumptions(tmp_path):
    a = _stack(np.uint8)
    f = tmp_path / "zyx.tif"
    tifffile.imwrite(
        f,
        a,
        imagej=True,
        resolution=(4.0, 4.0),
        metadata={"spacing": 0.25, "unit": "micron", "axes": "ZYX"},
    )
    vol = load(f)
    np.testing.assert_array_equal(vol.data, a)
    assert vol.spacing == (0.25, 0.25, 0.25)
    assert vol.unit == "um"
    assert "assumed" not in vol.meta


def test_resolution_unit_tag(tmp_path):
    a = _stack(np.int16)
    f = tmp_path / "cm.tiff"
    tifffile.imwrite(
        f, a, resolution=(4.0, 8.0), resolutionunit="CENTIMETER", photometric="minisblack"
    )
    vol = read_tiff(f)
    np.testing.assert_array_equal(vol.data, a)
    assert vol.spacing == (0.25, 0.125, 0.25)
    assert vol.unit == "cm"
    assert any("z spacing" in s for s in vol.meta["assumed"])


def test_no_metadata_assumes_one(tmp_path):
    a = _stack(np.float32)
    f = tmp_path / "plain.tif"
    tifffile.imwrite(f, a, photometric="minisblack")
    vol = read_tiff(f)
    np.testing.assert_array_equal(vol.data, a)
    assert vol.spacing == (1.0, 1.0, 1.0)
    assert vol.meta["assumed"]


def test_big_endian(tmp_path):
    a = _stack(np.uint16)
    f = tmp_path / "be.tif"
    tifffile.imwrite(f, a, byteorder=">", photometric="minisblack")
    vol = read_tiff(f)
    assert vol.dtype.name == "uint16"
    np.testing.assert_array_equal(vol.data, a)


@pytest.mark.parametrize("lazy", [False, True])
def test_compressed(tmp_path, lazy):
    a = _stack(np.uint16, (5, 6, 7))
    f = tmp_path / "z.tif"
    tifffile.imwrite(f, a, compression="zlib", photometric="minisblack")
    _needs_zarr3(lazy, f)
    vol = read_tiff(f, lazy=lazy)
    assert vol.meta["storage"] == ("lazy" if lazy else "memory")
    assert vol.is_lazy == lazy
    assert tuple(vol.data.shape) == (5, 6, 7)
    np.testing.assert_array_equal(vol.read_box(), a)
    np.testing.assert_array_equal(vol.read_box([1, 2, 3, 4, 3, 2]), a[3:5, 2:5, 1:5])


def test_colour_rejected(tmp_path):
    f = tmp_path / "rgb.tif"
    tifffile.imwrite(f, np.zeros((3, 8, 9, 3), np.uint8), photometric="rgb")
    with pytest.raises(InputError) as e:
        read_tiff(f)
    assert "rgb.tif" in str(e.value) and "colour" in str(e.value)
    assert "expected grey values" in str(e.value)


def test_single_2d_image_rejected(tmp_path):
    f = tmp_path / "flat.tif"
    tifffile.imwrite(f, np.zeros((8, 9), np.uint8))
    with pytest.raises(InputError) as e:
        read_tiff(f)
    msg = str(e.value)
    assert "flat.tif" in msg and "single 2D image (9×8)" in msg and "expected a 3D stack" in msg


def test_not_a_tiff_and_missing(tmp_path):
    f = tmp_path / "fake.tif"
    f.write_bytes(b"hello, not a tiff")
    with pytest.raises(InputError, match=r"fake\.tif: not a readable TIFF file"):
        read_tiff(f)
    with pytest.raises(InputError, match=r"none\.tif: no such file"):
        read_tiff(tmp_path / "none.tif")


def _slices(folder, a, names=None, **kw):
    folder.mkdir(exist_ok=True)
    names = names or [f"slice_{z}.tif" for z in range(a.shape[0])]
    for z, name in enumerate(names):
        tifffile.imwrite(folder / name, a[z], **kw)
    return folder


@pytest.mark.parametrize("lazy", [False, True])
def test_folder_round_trip_natural_order(tmp_path, lazy):
    a = _stack(np.uint16, (12, 5, 6))
    # unpadded numbers: lexicographic order (1, 10, 11, 2, ...) would be wrong
    d = _slices(tmp_path / "stack", a, resolution=(2.0, 2.0), resolutionunit="CENTIMETER")
    _needs_zarr3(lazy, d)
    vol = read_tiff_folder(d, lazy=lazy)
    assert vol.shape_xyz == (6, 5, 12)
    np.testing.assert_array_equal(vol.read_box(), a)
    assert vol.spacing == (0.5, 0.5, 0.5)
    assert vol.unit == "cm"
    assert vol.meta["first"] == "slice_0.tif" and vol.meta["last"] == "slice_11.tif"
    assert vol.is_lazy == lazy
    np.testing.assert_array_equal(load(d, lazy=lazy).read_box(), a)


def test_folder_ignores_other_files_and_numbers_from_one(tmp_path):
    a = _stack(np.uint8, (3, 4, 5))
    d = _slices(tmp_path / "s", a, names=["scan2_0001.TIF", "scan2_0002.tiff", "scan2_0003.tif"])
    (d / "notes.txt").write_text("not a slice")
    np.testing.assert_array_equal(read_tiff_folder(d).data, a)


def test_folder_gap_named(tmp_path):
    a = _stack(np.uint8, (4, 4, 5))
    d = _slices(tmp_path / "gap", a, names=["im_010.tif", "im_011.tif", "im_013.tif", "im_014.tif"])
    with pytest.raises(InputError) as e:
        read_tiff_folder(d)
    msg = str(e.value)
    assert "gap" in msg and "im_011.tif" in msg and "im_013.tif" in msg
    assert "slice 12 is missing" in msg
    with pytest.raises(InputError, match="slice 12 is missing"):
        load(d)


def test_folder_different_size_names_first_offender(tmp_path):
    a = _stack(np.uint8, (4, 4, 5))
    d = _slices(tmp_path / "sz", a)
    tifffile.imwrite(d / "slice_2.tif", np.zeros((4, 6), np.uint8))
    tifffile.imwrite(d / "slice_3.tif", np.zeros((3, 6), np.uint8))
    with pytest.raises(InputError) as e:
        read_tiff_folder(d)
    msg = str(e.value)
    assert "slice_2.tif" in msg and "slice_3.tif" not in msg
    assert "6×4 uint8" in msg and "5×4 uint8" in msg and "slice_0.tif" in msg


def test_folder_different_dtype(tmp_path):
    a = _stack(np.uint8, (3, 4, 5))
    d = _slices(tmp_path / "dt", a)
    tifffile.imwrite(d / "slice_1.tif", np.zeros((4, 5), np.uint16))
    with pytest.raises(InputError, match=r"slice_1\.tif: slice is 5×4 uint16 .* 5×4 uint8"):
        read_tiff_folder(d)


def test_folder_name_problems(tmp_path):
    a = _stack(np.uint8, (2, 4, 5))
    d = _slices(tmp_path / "nonum", a, names=["first.tif", "second.tif"])
    with pytest.raises(InputError, match=r"first\.tif: slice file name has no number"):
        list_slices(d)
    d = _slices(tmp_path / "dup", a, names=["a_1.tif", "b_01.tif"])
    with pytest.raises(InputError, match=r"a_1\.tif and b_01\.tif have the same number 1"):
        list_slices(d)
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match=r"empty: no \.tif/\.tiff slices"):
        read_tiff_folder(tmp_path / "empty")


def test_folder_of_stacks_rejected(tmp_path):
    d = tmp_path / "stacks"
    d.mkdir()
    for i in range(2):
        tifffile.imwrite(d / f"s{i}.tif", np.zeros((3, 4, 5), np.uint8), photometric="minisblack")
    with pytest.raises(InputError, match=r"s0\.tif: expected one 2D slice, got a stack of 3"):
        read_tiff_folder(d)


def test_single_slice_folder(tmp_path):
    d = _slices(tmp_path / "one", _stack(np.uint8, (1, 4, 5)), names=["only.tif"])
    assert read_tiff_folder(d).shape_xyz == (5, 4, 1)
