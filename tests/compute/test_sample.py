"""Samples in air and label images: porosity counts the pores of the sample, never the air around
it; a label image is never given a guessed pore phase.  Oracles: a synthetic cylinder in air
whose sample, pores and air are known voxel by voxel (numpy), scikit-image's Otsu, and the real
Berea (segmented) and snow (grey-scale) volumes where present."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from geoshade import core
from geoshade.compute.voxels.porosity import porosity as compute_porosity
from geoshade.compute.voxels.roi import fit_cylinder
from geoshade.compute.voxels.sample import SampleWarning, detect_sample
from geoshade.errors import InputError
from geoshade.models import VoxelVolume

filters = pytest.importorskip("skimage.filters")

DATA = Path(__file__).resolve().parents[3] / "shared" / "data"
BEREA = DATA / "microct_dpm_berea" / "berea_pore.raw"
SNOW = DATA / "microct_spam_snow" / "snow.tif"


def sample_in_air(nx=64, ny=60, nz=40, cx=33.0, cy=29.5, r=22.0, seed=0, dtype="uint16",
                  zr=None):
    """A grey-scale tomogram of a cylindrical sample in air, with known answers.

    Solid ~30000, pores and air ~8000 (as dark as each other), Gaussian noise of 600 that never
    crosses between the two; spherical pores lie wholly inside the cylinder (one voxel from its
    side at least).  ``zr=(z0, z1)``: the sample ends inside the volume, air in the slices
    outside ``[z0, z1)``.  Returns the volume and the bool arrays ``sample`` (the cylinder, voxel
    centres within r) and ``pores``.
    """
    rng = np.random.default_rng(seed)
    z, y, x = np.mgrid[0:nz, 0:ny, 0:nx] + 0.5
    sample = np.broadcast_to((x[0] - cx) ** 2 + (y[0] - cy) ** 2 <= r * r, (nz, ny, nx))
    if zr is not None:
        sample = sample & ((z >= zr[0]) & (z < zr[1]))
    pores = np.zeros((nz, ny, nx), bool)
    for _ in range(60):
        pr = rng.uniform(1.5, 3.5)
        d = rng.uniform(0, r - pr - 1.5)
        a = rng.uniform(0, 2 * np.pi)
        px, py, pz = cx + d * np.cos(a), cy + d * np.sin(a), rng.uniform(0, nz)
        pores |= (x - px) ** 2 + (y - py) ** 2 + (z - pz) ** 2 <= pr * pr
    pores &= sample
    a = np.where(sample & ~pores, 30000.0, 8000.0) + rng.normal(0, 600, (nz, ny, nx))
    return VoxelVolume(np.clip(a, 0, 65535).astype(dtype), name="in-air"), sample, pores


@pytest.fixture(scope="module")
def in_air():
    return sample_in_air()


def test_the_sample_is_found_voxel_for_voxel(in_air):
    vol, sample, _ = in_air
    s = detect_sample(vol)
    assert s.status == "in air"
    np.testing.assert_array_equal(s.roi.footprint, sample[0])
    assert s.fraction == sample[0].mean()
    t = s.threshold
    assert 10000 < t < 28000  # between the dark (air, pores) and the solid


def test_porosity_counts_the_pores_of_the_sample_not_the_air(in_air):
    vol, sample, pores = in_air
    a = np.asarray(vol.data)
    with pytest.warns(SampleWarning, match=r"% of the selected voxels lie outside the detected"):
        res = core.porosity(vol, "auto")
    t = float(filters.threshold_otsu(a))  # Otsu of the box: air and pores vs solid
    assert res.select_auto["threshold"] == t and res.select_auto["side"] == "dark"
    assert res.select_auto["within"] == "the box, the air around the sample included"
    assert res.range == (float(a.min()), t)
    assert (a[pores] <= t).all() and (a[sample & ~pores] > t).all()  # the oracle is exact
    assert res.count == pores.sum() and res.total == sample.sum()
    assert res.porosity == pores.sum() / sample.sum()
    air_selected = np.count_nonzero(~sample & (a >= res.range[0]) & (a <= t))
    assert res.outside == air_selected
    assert res.outside_fraction == air_selected / (air_selected + pores.sum())
    d = res.to_dict()
    assert d["sample"]["status"] == "in air" and d["outside"] == air_selected
    assert d["warning"].startswith("in-air: ") and d["notes"] == res.notes()
    assert res.notes()[0].startswith(f"dark phase ≤ Otsu {t:,.6g} taken as pore")
    assert res.notes()[1].startswith("counted inside the detected sample")
    assert "air outside the sample" in res.notes()[2]
    assert core.porosity_line(res).startswith(f"porosity {res.porosity:.4f} (")
    assert "voxels of the sample" in core.porosity_line(res)
    # the profile: per slice, pores of the slice / sample voxels of the slice
    np.testing.assert_array_equal(res.voxels, sample.sum(axis=(1, 2)))
    np.testing.assert_array_equal(res.counts, pores.sum(axis=(1, 2)))


def test_sample_none_counts_every_voxel_and_the_dask_path_is_the_same(in_air):
    vol, sample, pores = in_air
    a = np.asarray(vol.data)
    res = core.porosity(vol, (0, 20000), sample="none")
    assert res.porosity == np.count_nonzero(a <= 20000) / a.size
    assert res.sample["status"] == "off" and res.outside is None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SampleWarning)
        mem = core.porosity(vol, (0, 20000), axis="x")
        lazy = core.porosity(vol, (0, 20000), axis="x", scheduler="synchronous")
    assert mem.count == lazy.count == pores.sum() and mem.outside == lazy.outside
    np.testing.assert_array_equal(mem.counts, lazy.counts)
    np.testing.assert_array_equal(mem.voxels, lazy.voxels)
    # the compute function with the sample given, in a box, through dask chunks of 7
    import dask.array as da

    s = detect_sample(vol).roi
    box = [5, 3, 2, 50, 51, 30]
    ref = compute_porosity(a, 0, 20000, box=box, sample=s, axis="y")
    got = compute_porosity(da.from_array(a, chunks=7), 0, 20000, box=box, sample=s, axis="y",
                           scheduler="synchronous")
    x0, y0, z0, nx, ny, nz = box
    sub = (slice(z0, z0 + nz), slice(y0, y0 + ny), slice(x0, x0 + nx))
    want = (a[sub] <= 20000) & sample[sub]
    np.testing.assert_array_equal(ref.counts, want.sum(axis=(0, 2)))
    np.testing.assert_array_equal(got.counts, ref.counts)
    assert got.outside == ref.outside == np.count_nonzero((a[sub] <= 20000) & ~sample[sub])


def test_an_roi_is_the_sample_and_no_warning(in_air):
    vol, sample, pores = in_air
    with warnings.catch_warnings():
        warnings.simplefilter("error", SampleWarning)
        res = core.porosity(vol, "auto", roi="cylinder")
    assert res.roi["fitted"] and res.sample["status"] == "roi" and res.outside is None
    assert abs(res.roi["cx"] - 33.0) < 0.2 and abs(res.roi["cy"] - 29.5) < 0.2
    assert abs(res.roi["r"] - 22.0) < 0.3 and res.roi["note"] == ""
    assert abs(res.porosity - pores.sum() / sample.sum()) < 0.01


def test_a_cube_cut_from_inside_the_sample_has_no_air(in_air):
    vol, _, pores = in_air
    a = np.asarray(vol.data)[:, 18:42, 20:46].copy()  # wholly inside the cylinder
    cut = VoxelVolume(a, name="cut")
    assert detect_sample(cut).status == "no air"
    c = fit_cylinder(a, name="cut")  # keeps the whole volume, and says so
    assert c.note.startswith("no air around the sample")
    ny, nx = a.shape[1:]
    yy, xx = np.mgrid[0:ny, 0:nx] + 0.5
    assert ((xx - c.cx) ** 2 + (yy - c.cy) ** 2 <= c.r ** 2).all()
    res = core.porosity(cut, (0, 20000), roi="cylinder")
    assert res.total == a.size and res.count == pores[:, 18:42, 20:46].sum()
    assert "no air around the sample" in res.notes()[0]


def test_a_fit_touching_the_edge_says_so():
    vol, _, _ = sample_in_air(nx=50, ny=50, cx=25.0, cy=25.0, r=24.6)
    c = fit_cylinder(vol.data)
    assert "touches the edge of the 50×50 slices" in c.note
    assert "touches the edge" in core.porosity(vol, (0, 20000), roi="cylinder").notes()[0]


@pytest.mark.parametrize("zr", [(7, 33), (0, 29), (13, 40)])
def test_a_sample_that_ends_inside_the_volume(zr):
    """Air above and below the sample: those slices are not sample (found by bisection)."""
    vol, sample, pores = sample_in_air(zr=zr, seed=4)
    a = np.asarray(vol.data)
    s = detect_sample(vol)
    assert s.status == "in air" and s.z == zr and s.roi.to_dict()["z"] == list(zr)
    np.testing.assert_array_equal(s.roi.footprint, sample[zr[0]])
    inside = np.broadcast_to(s.roi.inside(slice(0, 40), slice(0, 60), slice(0, 64)), a.shape)
    np.testing.assert_array_equal(inside, sample)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SampleWarning)
        res = core.porosity(vol, (0, 20000), axis="y")
        lazy = core.porosity(vol, (0, 20000), axis="y", scheduler="synchronous")
    assert res.porosity == pores.sum() / sample.sum() and res.total == sample.sum()
    np.testing.assert_array_equal(res.counts, pores.sum(axis=(0, 2)))
    np.testing.assert_array_equal(lazy.counts, res.counts)
    assert f"z {zr[0]}..{zr[1] - 1}" in res.notes()[0]


def _labels(values, fractions, shape=(20, 20, 20), dtype="uint8"):
    n = int(np.prod(shape))
    counts = np.round(np.asarray(fractions) * n).astype(int)
    counts[-1] = n - counts[:-1].sum()
    a = np.repeat(np.asarray(values, dtype), counts)
    np.random.default_rng(1).shuffle(a)
    return VoxelVolume(a.reshape(shape), name="IMG.raw")


def test_auto_on_a_label_image_is_refused_in_one_line_naming_the_values():
    vol = _labels([0, 255], [0.864, 0.136])
    with pytest.raises(InputError) as e:
        core.porosity(vol, "auto")
    msg = str(e.value)
    assert msg == ("IMG.raw: select auto: a label image (0: 86.4 %, 255: 13.6 %) — which value "
                   "is pore? use --select 255 255 or --select 0 0")
    with pytest.raises(InputError, match="a label image"):
        core.auto_select(vol)
    t = core.thresholds(vol)
    assert t.pore_select() is None and t.labels == [(0.0, 6912), (255.0, 1088)]
    assert t.to_dict()["labels"][1] == {"value": 255.0, "voxels": 1088, "fraction": 0.136}
    # an explicit label: its fraction, every voxel counted (no air detected in labels)
    res = core.porosity(vol, (255, 255))
    assert res.porosity == 0.136 and res.sample["status"] == "label image"
    # float labels too; a grey image with 17 values is not a label image
    fl = VoxelVolume(np.asarray(vol.data, np.float32), name="f")
    with pytest.raises(InputError, match=r"a label image \(0: 86.4 %, 255: 13.6 %\)"):
        core.porosity(fl, "auto")
    grey = VoxelVolume((np.arange(17 * 8 * 8) % 17).astype(np.uint8).reshape(17, 8, 8))
    assert core.thresholds(grey).labels is None


def _berea():
    if not BEREA.is_file():
        pytest.skip(f"real data absent: {BEREA}")
    from geoshade import load

    return load(BEREA, shape=(110, 110, 110), dtype="uint8")


def test_berea_segmented_pore_fraction_never_the_grains():
    vol = _berea()
    a = np.asarray(vol.data)
    with pytest.raises(InputError, match=r"a label image \(0: 17.8 %, 1: 82.2 %\)"):
        core.porosity(vol, "auto")
    res = core.porosity(vol, (0, 0))
    assert res.porosity == np.count_nonzero(a == 0) / a.size
    assert round(res.porosity, 3) == 0.178
    inv = VoxelVolume(np.where(a == 0, 255, 0).astype(np.uint8), name="inverse")
    with pytest.raises(InputError, match=r"\(0: 82.2 %, 255: 17.8 %\) — which value is pore\? "
                                         r"use --select 255 255 or --select 0 0"):
        core.porosity(inv, "auto")
    assert core.porosity(inv, (255, 255)).porosity == res.porosity
    cube = core.porosity(vol, (0, 0), box=[20, 20, 20, 60, 60, 60])
    assert cube.total == 60 ** 3 and cube.sample["status"] == "label image"


def test_snow_is_a_cube_from_inside_a_sample():
    if not SNOW.is_file():
        pytest.skip(f"real data absent: {SNOW}")
    from geoshade import load

    vol = load(SNOW)
    a = np.asarray(vol.data)
    assert detect_sample(vol).status == "no air"
    res = core.porosity(vol, "auto")
    t = float(filters.threshold_otsu(a))
    assert res.select_auto["threshold"] == t and res.select_auto["within"] == "the box"
    assert res.porosity == np.count_nonzero(a <= t) / a.size and res.warning is None
    c = core.region(vol, roi="cylinder")[1]
    assert c.note.startswith("no air around the sample")
    assert core.porosity(vol, "auto", roi="cylinder").porosity == res.porosity
