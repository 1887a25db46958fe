"""The real micro-CT volumes in ``<repo>/../shared/data`` (skipped when absent)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import describe, format_description, load, read_raw, read_tiff, write_zarr

pytestmark = pytest.mark.data


@pytest.fixture
def berea(shared_data):
    f = shared_data / "microct_dpm_berea" / "berea_pore.raw"
    if not f.is_file():
        pytest.skip(f"{f} is absent")
    return f


@pytest.fixture
def snow(shared_data):
    f = shared_data / "microct_spam_snow" / "snow.tif"
    if not f.is_file():
        pytest.skip(f"{f} is absent")
    return f


def test_berea_raw(berea):
    vol = read_raw(berea, shape=(110, 110, 110), dtype="uint8")
    assert vol.shape_xyz == (110, 110, 110)
    assert isinstance(vol.data, np.memmap)
    values, counts = np.unique(np.asarray(vol.data), return_counts=True)
    assert values.tolist() == [0, 1]
    assert counts[0] / counts.sum() == pytest.approx(0.178, abs=0.0005)  # pore fraction


def test_berea_wrong_shape_says_what_fits(berea):
    with pytest.raises(InputError) as e:
        load(berea, shape=(100, 100, 100), dtype="uint8")
    msg = str(e.value)
    assert "berea_pore.raw" in msg
    assert "file has 1331000 bytes = 110×110×110 uint8" in msg
    assert "--shape 100 100 100" in msg and "expects 1000000" in msg
    with pytest.raises(InputError, match="give --shape NX NY NZ and --dtype"):
        load(berea)


def test_berea_describe(berea):
    d = describe(load(berea, shape=(110, 110, 110), dtype="uint8"))
    json.dumps(d)
    assert d["shape_xyz"] == [110, 110, 110] and d["bytes"] == 1331000
    assert (d["min"], d["max"]) == (0, 1)
    assert d["mean"] == pytest.approx(0.822, abs=0.0005)  # grain fraction
    assert d["assumed"]  # raw files carry no voxel size
    assert "110 × 110 × 110" in format_description(d)


def test_snow_tiff(snow, tmp_path):
    vol = read_tiff(snow)
    assert vol.shape_xyz == (100, 100, 100)
    assert vol.dtype == np.uint16
    assert vol.meta["storage"] == "memmap"
    d = describe(vol)
    assert (d["min"], d["max"]) == (6237, 40103)
    # the file carries ImageJ metadata but no calibration: spacing 1 is assumed, and said so
    assert vol.spacing == (1.0, 1.0, 1.0)
    assert vol.meta["assumed"]
    back = load(write_zarr(vol, tmp_path / "snow.zarr", chunks=(32, 32, 32)))
    np.testing.assert_array_equal(
        back.read_box([10, 20, 30, 40, 50, 60]), vol.read_box([10, 20, 30, 40, 50, 60])
    )
