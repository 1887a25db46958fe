"""Regions of interest (cylinder, fitted cylinder, mask) and suggested thresholds: porosity inside
an ROI equals numpy with a mask built here independently; Otsu equals scikit-image's."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade import core
from geoshade.compute.voxels.porosity import porosity
from geoshade.compute.voxels.roi import (
    Cylinder,
    MaskRoi,
    RoiMasked,
    fit_cylinder,
    masked_data,
    outside_value,
    parse_roi,
)
from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.errors import InputError
from geoshade.models import VoxelVolume


def cylinder_mask(shape_zyx, cx, cy, r):
    """(1, ny, nx) bool: voxel centres (i + 0.5, j + 0.5) within r of (cx, cy), by numpy."""
    _, ny, nx = shape_zyx
    yy, xx = np.meshgrid(np.arange(ny) + 0.5, np.arange(nx) + 0.5, indexing="ij")
    return (np.hypot(xx - cx, yy - cy) <= r)[None]


def core_in_air(n=48, seed=3, cx=None, cy=None, r=None, dtype="uint8", air=None):
    """A synthetic core (grains and pores) inside a cylinder along z, air (dark) around it."""
    vol = synthetic_core(n, porosity=0.2, seed=seed, dtype=dtype)
    cx = n / 2 + 1.5 if cx is None else cx
    cy = n / 2 - 2.0 if cy is None else cy
    r = 0.38 * n if r is None else r
    a = np.array(vol.data)
    out = ~cylinder_mask(a.shape, cx, cy, r)[0]
    a[:, out] = a.min() if air is None else air  # air: as dark as the darkest pore
    return VoxelVolume(a, spacing=vol.spacing, unit=vol.unit, name="core-in-air"), (cx, cy, r)


def _expected(a, inside, lo, hi, box, axis):
    x0, y0, z0, nx, ny, nz = box
    sub = a[z0:z0 + nz, y0:y0 + ny, x0:x0 + nx]
    ins = np.broadcast_to(inside, a.shape)[z0:z0 + nz, y0:y0 + ny, x0:x0 + nx]
    sel = (sub >= lo) & (sub <= hi) & ins
    axes = {"x": (0, 1), "y": (0, 2), "z": (1, 2)}[axis]
    counts = sel.sum(axis=axes)
    voxels = ins.sum(axis=axes)
    return sel.sum() / ins.sum(), counts, voxels


@pytest.mark.parametrize("dtype", ["uint8", "uint16", "float32"])
@pytest.mark.parametrize("axis", ["z", "x", "y"])
def test_cylinder_porosity_equals_numpy_with_the_same_mask(dtype, axis):
    vol, (cx, cy, r) = core_in_air(40, seed=2, dtype=dtype)
    a = np.asarray(vol.data)
    lo, hi = float(np.percentile(a, 5)), float(np.percentile(a, 40))
    inside = cylinder_mask(a.shape, cx, cy, r)
    for box in ([0, 0, 0, 40, 40, 40], [3, 5, 2, 30, 33, 21]):
        r_ = porosity(vol, lo, hi, box=box, axis=axis, roi=Cylinder(cx, cy, r), slab_bytes=1)
        want, counts, voxels = _expected(a, inside, lo, hi, box, axis)
        assert r_.porosity == want
        assert r_.counts.tolist() == counts.tolist()
        assert r_.per_slice().tolist() == voxels.tolist()
        with np.errstate(invalid="ignore"):
            prof = np.where(voxels > 0, counts / np.maximum(voxels, 1), np.nan)
        np.testing.assert_array_equal(r_.profile, prof)
        # the dask graph and core.porosity on a cluster-less scheduler give the same numbers
        lz = porosity(vol, lo, hi, box=box, axis=axis, roi=Cylinder(cx, cy, r),
                      scheduler="threads")
        assert lz.porosity == want and lz.counts.tolist() == counts.tolist()
        via_api = core.porosity(vol, (lo, hi), box=box, axis=axis,
                                roi=f"cylinder:{cx},{cy},{r}", scheduler="synchronous")
        assert via_api.porosity == want and via_api.roi["r"] == r


def test_cylinder_porosity_does_not_count_the_air():
    vol, (cx, cy, r) = core_in_air(48, seed=3)
    a = np.asarray(vol.data)
    lo, hi = 0, 120
    whole = core.porosity(vol, (lo, hi), sample="none")
    inside = core.porosity(vol, (lo, hi), roi=f"cylinder:{cx},{cy},{r}")
    m = np.broadcast_to(cylinder_mask(a.shape, cx, cy, r), a.shape)
    assert inside.porosity == np.count_nonzero(m & (a <= hi)) / np.count_nonzero(m)
    assert whole.porosity > inside.porosity + 0.3  # the air counted as pores, no sample
    assert inside.to_dict()["roi"]["text"].startswith("cylinder:")
    # without an ROI the sample is detected in air: its footprint is the cylinder but for a
    # pixel of its surface where a pore column is as dark as the air in most slices
    with pytest.warns(UserWarning, match=r"of the selected voxels lie outside the detected"):
        found = core.porosity(vol, (lo, hi))
    assert found.sample["status"] == "in air" and found.roi is None
    assert abs(found.total - inside.total) <= 2 * a.shape[0]
    assert abs(found.porosity - inside.porosity) < 2e-3


def test_mask_volume_porosity_equals_numpy(tmp_path):
    rng = np.random.default_rng(1)
    a = rng.integers(0, 256, (12, 10, 14), dtype=np.uint8)
    m = (rng.random((12, 10, 14)) < 0.6).astype(np.uint8) * 7
    res = core.porosity(VoxelVolume(a), (0, 90), mask=VoxelVolume(m), axis="y")
    sel = (a <= 90) & (m != 0)
    assert res.porosity == sel.sum() / (m != 0).sum()
    assert res.counts.tolist() == sel.sum(axis=(0, 2)).tolist()
    assert res.per_slice().tolist() == (m != 0).sum(axis=(0, 2)).tolist()
    # a headerless raw mask of one uint8 per voxel, read with the volume's shape
    f = tmp_path / "mask.raw"
    m.tofile(f)
    res2 = core.porosity(VoxelVolume(a), (0, 90), mask=str(f), axis="y")
    assert res2.porosity == res.porosity and res2.roi["source"] == str(f)
    with pytest.raises(InputError, match=r"mask: a mask of 14×10×11 voxels .* does not match"):
        core.porosity(VoxelVolume(a), (0, 90), mask=VoxelVolume(m[:11]))
    (tmp_path / "short.raw").write_bytes(b"\0" * 17)
    with pytest.raises(InputError, match=r"short.raw: mask: a headerless raw mask holds one"):
        core.porosity(VoxelVolume(a), (0, 90), mask=str(tmp_path / "short.raw"))
    with pytest.raises(InputError, match="either a cylinder"):
        core.porosity(VoxelVolume(a), (0, 90), mask=VoxelVolume(m), roi="cylinder:1,1,1")


def test_fit_cylinder_finds_the_core_in_air_deterministically():
    for n, seed, (cx, cy, r) in ((48, 3, (25.5, 22.0, 18.0)), (64, 9, (30.0, 34.5, 24.0))):
        vol, _ = core_in_air(n, seed=seed, cx=cx, cy=cy, r=r)
        c = fit_cylinder(vol.data)
        assert c.fitted and abs(c.cx - cx) < 0.25 and abs(c.cy - cy) < 0.25
        assert abs(c.r - r) < 0.5
        assert fit_cylinder(vol.data) == c  # deterministic
    # the air brighter than nothing: a uniform volume, and a sample filling the slices
    with pytest.raises(InputError, match="one value only; give --roi cylinder:CX,CY,R"):
        fit_cylinder(np.zeros((4, 8, 8), np.uint8))
    full = synthetic_core(24, seed=1, dtype="uint8").data  # no air: the whole volume is kept
    c = fit_cylinder(full)
    assert (c.cx, c.cy, c.r) == (12, 12, np.hypot(12, 12)) and c.note.startswith("no air")
    labels = (synthetic_core(24, seed=1, dtype="uint8").data > 100).astype(np.uint8)
    with pytest.raises(InputError, match="cannot fit a cylinder to a label image"):
        fit_cylinder(labels)


@pytest.mark.parametrize("cx, cy, r", [(20.0, 24.0, 26.0), (40.0, 10.0, 20.0), (24, 24, 25.5)])
def test_fit_cylinder_cut_by_the_field_of_view(cx, cy, r):
    """A core wider than the slices on one or more sides: a circle through its edge inside."""
    vol, _ = core_in_air(48, seed=3, cx=cx, cy=cy, r=r)
    c = fit_cylinder(vol.data)
    assert abs(c.cx - cx) < 0.5 and abs(c.cy - cy) < 0.5 and abs(c.r - r) < 0.5


@pytest.mark.parametrize("text, message", [
    ("sphere:1,2,3", "roi: expected 'cylinder' (fitted to the sample), 'cylinder:CX,CY,R'"),
    ("cylinder:1,2", "roi: expected 'cylinder'"),
    ("cylinder:1,2,x", "roi: expected 'cylinder'"),
    ("cylinder:1,2,0", "roi: cylinder radius must be > 0 voxels, got 0"),
])
def test_bad_roi_text_is_one_line(text, message):
    with pytest.raises(InputError) as e:
        parse_roi(text)
    assert str(e.value).startswith(message) and "\n" not in str(e.value)


def test_cylinder_outside_the_volume_is_refused():
    vol = VoxelVolume(np.zeros((2, 8, 8), np.uint8))
    with pytest.raises(InputError, match="holds no voxel centre of the 8×8"):
        core.porosity(vol, (0, 1), roi="cylinder:30,30,2")


def test_masked_data_reads_the_roi_per_block():
    rng = np.random.default_rng(3)
    a = rng.integers(0, 256, (9, 11, 13), dtype=np.uint8)
    c = Cylinder(6.0, 5.5, 4.2)
    inside = cylinder_mask(a.shape, 6.0, 5.5, 4.2)
    for lo, hi in ((10, 80), (0, 200), (0, 255)):
        dt, fill = outside_value(a.dtype, lo, hi)
        want = np.where(inside, a.astype(dt), fill)
        assert not ((want >= lo) & (want <= hi))[~np.broadcast_to(inside, a.shape)].any()
        m = masked_data(a, c, lo, hi)
        assert isinstance(m, RoiMasked)
        np.testing.assert_array_equal(m[2:7, 1:10, 3:13], want[2:7, 1:10, 3:13])
        da = pytest.importorskip("dask.array")
        d = masked_data(da.from_array(a, chunks=(4, 5, 6)), c, lo, hi)
        np.testing.assert_array_equal(d.compute(), want)
    mr = MaskRoi((a > 100).astype(np.uint8), "m")
    np.testing.assert_array_equal(mr.inside(slice(1, 3), slice(0, 4), slice(2, 9)),
                                  a[1:3, 0:4, 2:9] > 100)


# --- thresholds ------------------------------------------------------------------------------
filters = pytest.importorskip("skimage.filters", reason="thresholds need geoshade[threshold]")


@pytest.mark.parametrize("dtype", ["uint8", "int16", "uint16", "float32"])
def test_suggested_threshold_equals_scikit_image(dtype):
    vol = synthetic_core(32, porosity=0.25, seed=4, dtype=dtype)
    a = np.asarray(vol.data)
    t = core.thresholds(vol)
    assert t.otsu == float(filters.threshold_otsu(a))
    if dtype in ("uint8", "float32"):  # <= 256 bins: scikit-image's own histogram
        assert t.multiotsu == [float(v) for v in filters.threshold_multiotsu(a)]
    assert t.vmin == float(a.min()) and t.vmax == float(a.max())
    # over a box and inside a cylinder: the voxels measured only
    c = Cylinder(15.0, 17.0, 11.0)
    box = [2, 3, 4, 28, 26, 20]
    tb = core.thresholds(vol, box=box, roi=c)
    x0, y0, z0, nx, ny, nz = box
    sub = a[z0:z0 + nz, y0:y0 + ny, x0:x0 + nx]
    ins = np.broadcast_to(cylinder_mask(a.shape, 15.0, 17.0, 11.0), a.shape)
    ins = ins[z0:z0 + nz, y0:y0 + ny, x0:x0 + nx]
    assert tb.otsu == float(filters.threshold_otsu(sub[ins]))


def test_multi_otsu_of_a_wide_16_bit_range_is_skimage_on_256_bins():
    from geoshade.compute.voxels.threshold import MULTI_BINS, _merged, value_histogram

    vol = synthetic_core(24, porosity=0.3, seed=8, dtype="uint16")
    h = value_histogram(vol).trimmed()
    assert h.counts.size > MULTI_BINS
    m = _merged(h, MULTI_BINS)
    assert m.counts.sum() == h.counts.sum() == vol.data.size
    want = filters.threshold_multiotsu(hist=(m.counts, m.centers))
    assert core.thresholds(vol).multiotsu == [float(v) for v in want]


def test_auto_select_is_the_pore_side_and_the_fraction_is_named():
    vol, (cx, cy, r) = core_in_air(40, seed=5)
    a = np.asarray(vol.data)
    res = core.porosity(vol, "auto", roi=f"cylinder:{cx},{cy},{r}")
    ins = np.broadcast_to(cylinder_mask(a.shape, cx, cy, r), a.shape)
    t = float(filters.threshold_otsu(a[ins]))
    assert res.range == (float(a[ins].min()), t)
    assert res.select_auto["method"] == "otsu" and res.select_auto["threshold"] == t
    assert res.quantity == "porosity" and res.to_dict()["quantity"] == "porosity"
    assert res.porosity == np.count_nonzero(ins & (a <= t)) / np.count_nonzero(ins)
    grains = core.porosity(vol, (t + 1, 255), roi=f"cylinder:{cx},{cy},{r}")
    assert grains.quantity == "selected fraction" and not grains.pores
    everything = core.porosity(vol, (0, 255))
    assert everything.quantity == "selected fraction"  # takes every voxel: not a pore space
