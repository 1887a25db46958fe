"""OME-Zarr (issue 15): ``core ingest`` stores are NGFF 0.5 multiscale images that the
OME-Zarr libraries open (ome-zarr's reader, ome-zarr-models' validator) level for level, bit for
bit; OME-Zarr images written by ome-zarr read in geoshade (load, info, render); unsupported or
damaged metadata are one line."""

from __future__ import annotations

import json

import numpy as np
import pytest
import zarr

from geoshade.cli.main import main
from geoshade.io import load
from geoshade.io.stores.ingest import ingest
from geoshade.io.stores.zarr_io import read_level, store_levels

ome_zarr = pytest.importorskip("ome_zarr")
from ome_zarr.io import parse_url  # noqa: E402
from ome_zarr.reader import Reader  # noqa: E402
from ome_zarr.writer import write_image  # noqa: E402


def _vol(shape=(21, 18, 23), dtype=np.uint16, seed=15):
    return np.random.default_rng(seed).integers(0, 3000, shape).astype(dtype)


def _ingest(tmp_path, a, name="core.zarr", **kw):
    a.tofile(tmp_path / "v.raw")
    nz, ny, nx = a.shape
    return ingest(tmp_path / "v.raw", tmp_path / name, shape=(nx, ny, nz), dtype=a.dtype.name,
                  **kw)


def _ome_levels(path):
    """The levels and metadata as ome-zarr's reader returns them (numpy, level 0 first)."""
    reader = Reader(parse_url(str(path)))
    node = next(iter(reader()))
    return [np.asarray(d) for d in node.data], node.metadata


def _run(capsys, *argv):
    rc = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def _one_line(err):
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("geoshade: error:"), err
    assert "Traceback" not in err
    return lines[0]


# --- geoshade's stores are OME-Zarr ---------------------------------------------------------
@pytest.mark.parametrize("method", ["nearest", "mean"])
def test_ingest_store_is_ngff_and_reads_back_bit_for_bit(tmp_path, method):
    a = _vol()
    sp, og = (0.5, 0.75, 2.0), (10.0, -4.0, 3.0)
    rep = _ingest(tmp_path, a, chunks=(8, 8, 8), levels=3, spacing=sp, origin=og, unit="um",
                  downsample=method)
    levels, meta = _ome_levels(rep.path)
    assert parse_url(str(rep.path)).version == "0.5"
    assert len(levels) == store_levels(rep.path) == 3
    for k, lev in enumerate(levels):  # every level, through both readers, bit for bit
        ours = read_level(rep.path, k).read_box()
        assert lev.dtype == ours.dtype == a.dtype and lev.shape == ours.shape
        np.testing.assert_array_equal(lev, ours)
    np.testing.assert_array_equal(levels[0], a)
    if method == "nearest":
        for k in (1, 2):
            np.testing.assert_array_equal(levels[k], a[:: 2**k, :: 2**k, :: 2**k])
    assert [ax["name"] for ax in meta["axes"]] == ["z", "y", "x"]
    assert {ax["type"] for ax in meta["axes"]} == {"space"}
    assert {ax["unit"] for ax in meta["axes"]} == {"micrometer"}
    sp_zyx, og_zyx = np.array(sp[::-1]), np.array(og[::-1])
    for k, (scale, trans) in enumerate(meta["coordinateTransformations"]):
        f = 2**k
        assert scale == {"type": "scale", "scale": list(sp_zyx * f)}
        centre = 0.5 * f if method == "mean" else 0.5  # the level's first voxel centre
        np.testing.assert_allclose(trans["translation"], og_zyx + centre * sp_zyx)
    # geoshade's own attributes are kept beside the NGFF ones
    attrs = zarr.open_group(str(rep.path), mode="r").attrs.asdict()
    assert attrs["ingest"]["complete"] is True and attrs["spacing"] == list(sp)
    assert "multiscales" not in attrs  # NGFF 0.5 keeps it under "ome" only
    vol = load(rep.path)
    assert vol.spacing == sp and vol.origin == og and vol.unit == "um"


def test_ingest_store_validates_with_ome_zarr_models(tmp_path):
    v05 = pytest.importorskip("ome_zarr_models.v05")
    rep = _ingest(tmp_path, _vol((9, 10, 11), np.uint8), chunks=(4, 4, 4), levels=2,
                  spacing=(1, 1, 1), unit="mm")
    img = v05.Image.from_zarr(zarr.open_group(str(rep.path), mode="r"))
    ms = img.attributes.ome.multiscales[0]
    assert [d.path for d in ms.datasets] == ["0", "1"]
    assert [ax.unit for ax in ms.axes] == ["millimeter"] * 3


def test_unit_without_ngff_name_is_left_out_of_the_axes(tmp_path):
    rep = _ingest(tmp_path, _vol((4, 4, 4), np.uint8), chunks=(4, 4, 4), levels=1, unit="vox")
    _, meta = _ome_levels(rep.path)
    assert all("unit" not in ax for ax in meta["axes"])
    assert load(rep.path).unit == "vox"  # geoshade's own attribute still says it


def test_older_geoshade_stores_still_read(tmp_path):
    """Stores of earlier versions kept a 0.4-style ``multiscales`` at the top of a v3 group."""
    a = _vol((8, 6, 10))
    rep = _ingest(tmp_path, a, chunks=(4, 4, 4), levels=2, spacing=(2, 2, 2))
    zj = rep.path / "zarr.json"
    meta = json.loads(zj.read_text())
    ome = meta["attributes"].pop("ome")
    meta["attributes"]["multiscales"] = [{"version": "0.4", **ome["multiscales"][0]}]
    zj.write_text(json.dumps(meta))
    assert store_levels(rep.path) == 2
    np.testing.assert_array_equal(load(rep.path).read_box(), a)
    lv = read_level(rep.path, 1)
    assert lv.spacing == (4.0, 4.0, 4.0)
    np.testing.assert_array_equal(lv.read_box(), a[::2, ::2, ::2])


def test_write_zarr_ome_is_a_one_level_ngff_image(tmp_path):
    from geoshade.io.stores.zarr_io import verify_store, write_zarr
    from geoshade.models import VoxelVolume

    a = _vol((6, 7, 8), np.uint8)
    p = write_zarr(VoxelVolume(a, spacing=(0.5, 1, 2), origin=(1, 1, 1), unit="mm"),
                   tmp_path / "w.zarr", chunks=(4, 4, 4), ome=True, labels=True)
    levels, meta = _ome_levels(p)
    assert len(levels) == 1
    np.testing.assert_array_equal(levels[0], a)
    assert meta["coordinateTransformations"][0][0]["scale"] == [2.0, 1.0, 0.5]
    v05 = pytest.importorskip("ome_zarr_models.v05")
    v05.Image.from_zarr(zarr.open_group(str(p), mode="r"))
    vol = load(p)
    assert vol.spacing == (0.5, 1.0, 2.0) and vol.origin == (1.0, 1.0, 1.0) and vol.unit == "mm"
    assert vol.meta["labels"] is True and vol.meta["checksums"] == "crc32"
    np.testing.assert_array_equal(vol.read_box(), a)
    assert verify_store(p)["checksums"] is True
    assert sorted(q.name for q in tmp_path.iterdir()) == ["w.zarr"]


# --- OME-Zarr written by others ---------------------------------------------------------------
def _foreign(tmp_path, a, name="f.ome.zarr", **kw):
    root = zarr.open_group(str(tmp_path / name), mode="w", **kw.pop("open", {}))
    write_image(a, root, **kw)
    return tmp_path / name


def test_foreign_ngff_05_reads_with_spacing_unit_and_levels(tmp_path, capsys):
    a = _vol((12, 16, 20))
    p = _foreign(tmp_path, a, axes="zyx", scale={"z": 2.0, "y": 0.5, "x": 0.25},
                 axes_units={n: "millimeter" for n in "zyx"}, scale_factors=(2, 4))
    levels, meta = _ome_levels(p)
    vol = load(p)
    assert vol.spacing == (0.25, 0.5, 2.0) and vol.unit == "mm"
    scale0 = meta["coordinateTransformations"][0][0]["scale"]
    trans0 = meta["coordinateTransformations"][0][1]["translation"]
    # NGFF translations are voxel centres; geoshade's origin is the first voxel's corner
    assert vol.origin == tuple(t - s / 2 for t, s in zip(trans0[::-1], scale0[::-1],
                                                           strict=True))
    np.testing.assert_array_equal(vol.read_box(), a)
    assert vol.meta["levels"] == 3 and vol.meta["ngff"] == "0.5"
    for k, lev in enumerate(levels):  # other levels as overviews, spacing from their scale
        lv = read_level(p, k)
        np.testing.assert_array_equal(lv.read_box(), lev)
        scale = meta["coordinateTransformations"][k][0]["scale"]
        assert lv.spacing == tuple(scale[::-1]) and lv.origin == vol.origin
    rc, out, err = _run(capsys, "info", p)
    assert rc == 0, err
    assert "levels   3 (multiscale, OME-Zarr 0.5)" in out and "0.25 × 0.5 × 2 mm" in out


def test_foreign_ngff_04_zarr_v2_reads(tmp_path):
    from ome_zarr.format import FormatV04

    a = _vol((6, 10, 14), np.uint8)
    p = _foreign(tmp_path, a, axes="zyx", fmt=FormatV04(), scale_factors=(2,),
                 open={"zarr_format": 2})
    assert (p / ".zattrs").is_file()
    levels, _ = _ome_levels(p)
    vol = load(p)
    assert vol.meta["ngff"] == "0.4" and vol.spacing == (1.0, 1.0, 1.0)
    np.testing.assert_array_equal(vol.read_box(), a)
    np.testing.assert_array_equal(read_level(p, 1).read_box(), levels[1])


def test_foreign_single_channel_5d_reads_as_3d(tmp_path):
    a = _vol((5, 6, 7))
    p = _foreign(tmp_path, a[None, None], axes="tczyx", scale_factors=())
    vol = load(p)
    assert vol.shape_xyz == (7, 6, 5)
    np.testing.assert_array_equal(vol.read_box(), a)


@pytest.mark.gl
def test_foreign_store_renders_from_an_overview_level(tmp_path, capsys, ctx):
    a = _vol((16, 16, 16))
    p = _foreign(tmp_path, a, axes="zyx", scale_factors=(2,))
    st = tmp_path / "s.json"
    rc, _out, err = _run(capsys, "core", "render", p, "--select", 0, 1000, "--level", 1,
                        "--size", "48x40", "--frames", 1, "-o", tmp_path / "r.png",
                        "--stats", st)
    assert rc == 0, err
    lev = _ome_levels(p)[0][1]
    assert json.loads(st.read_text())["voxels_selected"] == int((lev <= 1000).sum())


# --- unsupported or damaged metadata: one line ------------------------------------------------
def _edit_ome(path, fn):
    zj = path / "zarr.json"
    meta = json.loads(zj.read_text())
    fn(meta["attributes"]["ome"]["multiscales"][0])
    zj.write_text(json.dumps(meta))


def test_channels_and_time_points_are_refused(tmp_path, capsys):
    p = _foreign(tmp_path, _vol((2, 1, 4, 5, 6)), axes="tczyx", scale_factors=())
    rc, _, err = _run(capsys, "info", p)
    assert rc == 2 and "2 time points" in _one_line(err) and "f.ome.zarr" in err
    q = _foreign(tmp_path, _vol((3, 4, 5, 6)), name="c.ome.zarr", axes="czyx", scale_factors=())
    rc, _, err = _run(capsys, "core", "porosity", q, "--select", 0, 10, "-o",
                      tmp_path / "p.png")
    assert rc == 2 and "3 channels" in _one_line(err)


def test_2d_image_is_refused(tmp_path, capsys):
    p = _foreign(tmp_path, _vol((8, 9)), axes="yx", scale_factors=())
    rc, _, err = _run(capsys, "info", p)
    assert rc == 2 and "expected axes z, y, x (missing z)" in _one_line(err)


@pytest.mark.parametrize("damage, expect", [
    (lambda m: m.pop("datasets"), "damaged 'multiscales' attribute"),
    (lambda m: m["datasets"][0]["coordinateTransformations"][0].update(scale=[1, 1]),
     "expected 3 numbers"),
    (lambda m: m["datasets"][0]["coordinateTransformations"][0].update(scale=[1, 0, 1]),
     "expected positive numbers"),
    (lambda m: m["datasets"][0]["coordinateTransformations"][0].update(scale=["a", 1, 1]),
     "damaged 'multiscales' attribute"),
    (lambda m: m.update(axes=[{"name": "q"}, {"name": "y"}, {"name": "x"}]), "missing z"),
    (lambda m: m.update(axes=m["axes"][:2]), "damaged 'multiscales' attribute"),
])
def test_damaged_metadata_is_one_line(tmp_path, capsys, damage, expect):
    p = _foreign(tmp_path, _vol((4, 5, 6)), axes="zyx", scale_factors=())
    _edit_ome(p, damage)
    rc, _, err = _run(capsys, "info", p)
    assert rc == 2 and expect in _one_line(err), err


def test_group_without_multiscales_is_one_line(tmp_path, capsys):
    p = _foreign(tmp_path, _vol((4, 5, 6)), axes="zyx", scale_factors=())
    zj = p / "zarr.json"
    meta = json.loads(zj.read_text())
    del meta["attributes"]["ome"]
    zj.write_text(json.dumps(meta))
    rc, _, err = _run(capsys, "info", p)
    line = _one_line(err)
    assert rc == 2 and "no OME-Zarr 'multiscales' attribute" in line and "s0" in line
