"""The napari plugin (issue 17), headless: the npe2 manifest validates; the reader gives the
right layer data, scale, multiscale levels and layer type through npe2 (and napari's viewer
model); the labels writer round-trips; the selection becomes labels equal to numpy's."""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
from importlib.resources import files

import numpy as np
import pytest
import tifffile

import geoshade
from geoshade.io.stores.ingest import ingest
from geoshade.io.stores.zarr_io import read_level

npe2 = pytest.importorskip("npe2")

MANIFEST = files("geoshade.napari") / "napari.yaml"


@pytest.fixture(scope="module")
def pm():
    """npe2's plugin manager with geoshade registered (from the manifest: the tree may not be
    installed with its entry point)."""
    manager = npe2.PluginManager.instance()
    if "geoshade" not in {m.name for m in manager.iter_manifests()}:
        manager.register(npe2.PluginManifest.from_file(str(MANIFEST)))
    return manager


def _vol(shape=(12, 10, 14), dtype=np.uint16, seed=17):
    return np.random.default_rng(seed).integers(0, 2000, shape).astype(dtype)


@pytest.fixture
def store(tmp_path):
    a = _vol()
    a.tofile(tmp_path / "v.raw")
    nz, ny, nx = a.shape
    rep = ingest(tmp_path / "v.raw", tmp_path / "core.zarr", shape=(nx, ny, nz), dtype="uint16",
                 chunks=(4, 8, 8), levels=3, spacing=(0.5, 0.5, 2.0), origin=(1, 2, 3),
                 unit="um")
    return rep.path, a


def _read(path):
    [(data, kw, kind)] = npe2.read([str(path)], stack=False, plugin_name="geoshade")
    return data, kw, kind


# --- the manifest ----------------------------------------------------------------------------
def test_manifest_validates():
    mf = npe2.PluginManifest.from_file(str(MANIFEST))
    mf.validate_imports()  # every python_name imports
    assert mf.name == "geoshade"
    assert [r.command for r in mf.contributions.readers] == ["geoshade.get_reader"]
    assert mf.contributions.writers[0].layer_types == ["labels"]
    r = subprocess.run([sys.executable, "-m", "npe2", "validate", str(MANIFEST)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "valid!" in r.stdout, r.stdout + r.stderr


def test_entry_point_names_the_manifest():
    import tomllib

    from geoshade import __file__ as pkg

    root = os.path.dirname(os.path.dirname(os.path.dirname(pkg)))
    with open(os.path.join(root, "pyproject.toml"), "rb") as f:
        eps = tomllib.load(f)["project"]["entry-points"]["napari.manifest"]
    assert eps == {"geoshade": "geoshade.napari:napari.yaml"}


def test_plugin_never_imports_napari(tmp_path):
    """napari stays optional: reading, selecting and writing run without importing it."""
    np.save(tmp_path / "v.npy", _vol((3, 4, 5)))
    code = (
        "import sys, numpy as np\n"
        "from geoshade.napari import read_layers, selection_labels, write_labels\n"
        f"[(d, kw, t)] = read_layers({str(tmp_path / 'v.npy')!r})\n"
        f"lab, kw, _ = selection_labels({str(tmp_path / 'v.npy')!r}, 0, 1000)\n"
        f"write_labels({str(tmp_path / 'l.zarr')!r}, lab, kw)\n"
        "assert 'napari' not in sys.modules, 'napari was imported'\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr


# --- the reader ------------------------------------------------------------------------------
def test_multiscale_store_is_one_multiscale_image_layer(pm, store):
    path, a = store
    assert "geoshade" in [r.plugin_name for r in pm.iter_compatible_readers([str(path)])]
    data, kw, kind = _read(path)
    assert kind == "image" and kw["multiscale"] is True and len(data) == 3
    for k, level in enumerate(data):
        np.testing.assert_array_equal(np.asarray(level), read_level(path, k).read_box())
    np.testing.assert_array_equal(np.asarray(data[0]), a)
    assert kw["scale"] == (2.0, 0.5, 0.5)  # z, y, x
    assert kw["translate"] == (3 + 1.0, 2 + 0.25, 1 + 0.25)  # the first voxel's centre
    assert kw["metadata"]["unit"] == "um" and kw["metadata"]["source"] == str(path)
    assert kw["contrast_limits"] == [float(a.min()), float(a.max())]


def test_foreign_ome_zarr_levels_and_scale(pm, tmp_path):
    pytest.importorskip("ome_zarr")
    import zarr
    from ome_zarr.writer import write_image

    a = _vol((8, 16, 20))
    root = zarr.open_group(str(tmp_path / "f.ome.zarr"), mode="w")
    write_image(a, root, axes="zyx", scale={"z": 3.0, "y": 1.5, "x": 1.5}, scale_factors=(2,))
    data, kw, kind = _read(tmp_path / "f.ome.zarr")
    assert kind == "image" and kw["multiscale"] and [d.shape for d in data] == [
        (8, 16, 20), (8, 8, 10)]
    np.testing.assert_array_equal(np.asarray(data[0]), a)
    assert kw["scale"] == (3.0, 1.5, 1.5)


def test_tiff_npy_and_hdf5(pm, tmp_path):
    a = _vol((5, 6, 7))
    tifffile.imwrite(tmp_path / "s.tif", a, imagej=True, resolution=(1 / 0.25, 1 / 0.25),
                     metadata={"spacing": 0.75, "unit": "um", "axes": "ZYX"})
    data, kw, kind = _read(tmp_path / "s.tif")
    np.testing.assert_array_equal(np.asarray(data), a)
    assert kind == "image" and kw["multiscale"] is False
    assert kw["scale"] == pytest.approx((0.75, 0.25, 0.25)) and kw["metadata"]["unit"] == "um"
    np.save(tmp_path / "v.npy", a)
    data, kw, _ = _read(tmp_path / "v.npy")
    np.testing.assert_array_equal(np.asarray(data), a)
    assert kw["scale"] == (1.0, 1.0, 1.0)
    h5py = pytest.importorskip("h5py")
    with h5py.File(tmp_path / "v.h5", "w") as h:
        h.create_dataset("scan", data=a)
    data, _, _ = _read(tmp_path / "v.h5")
    np.testing.assert_array_equal(np.asarray(data), a)


def test_metaimage_sidecar(pm, tmp_path):
    from geoshade.io import formats

    if formats.find("m.mhd") is None:
        pytest.skip("geoshade.io reads no MetaImage .mhd in this tree")
    a = _vol((5, 6, 7))
    a.tofile(tmp_path / "m.raw")
    (tmp_path / "m.mhd").write_text(
        "ObjectType = Image\nNDims = 3\nDimSize = 7 6 5\nElementSpacing = 0.5 0.25 2\n"
        "ElementType = MET_USHORT\nElementByteOrderMSB = False\nElementDataFile = m.raw\n")
    data, kw, kind = _read(tmp_path / "m.mhd")
    np.testing.assert_array_equal(np.asarray(data), a)
    assert kind == "image" and kw["scale"] == (2.0, 0.25, 0.5)


def test_raw_files_are_left_to_other_plugins(pm, tmp_path):
    from geoshade.napari import get_reader

    _vol().tofile(tmp_path / "v.raw")
    assert get_reader(str(tmp_path / "v.raw")) is None  # shape and dtype: napari cannot ask
    assert "geoshade" not in [r.plugin_name for r in
                              pm.iter_compatible_readers([str(tmp_path / "v.raw")])]


def test_damaged_file_is_one_line(pm, tmp_path):
    from geoshade.errors import InputError
    from geoshade.napari import read_layers

    np.save(tmp_path / "bad.npy", _vol())
    with open(tmp_path / "bad.npy", "r+b") as f:  # truncated
        f.truncate(1000)
    with pytest.raises(InputError, match=r"bad\.npy") as err:
        read_layers(str(tmp_path / "bad.npy"))
    assert "\n" not in str(err.value)


# --- selection -> labels -> writer -------------------------------------------------------------
def test_selection_labels_equal_numpy(store):
    from geoshade.napari import selection_labels

    path, a = store
    data, kw, kind = selection_labels(path, 300, 1200, label=3)  # a lazy store: dask labels
    assert kind == "labels" and hasattr(data, "compute")
    np.testing.assert_array_equal(data.compute(), ((a >= 300) & (a <= 1200)) * np.uint8(3))
    assert kw["scale"] == (2.0, 0.5, 0.5) and kw["metadata"]["select"] == [300.0, 1200.0]
    with pytest.raises(geoshade.errors.InputError, match="select"):
        selection_labels(path, 10, 70000)  # beyond uint16


def test_writer_round_trip(pm, tmp_path):
    lab = np.zeros((4, 5, 6), np.int64)
    lab[1:3, 2:4, 3:5] = 2
    out = tmp_path / "sel.zarr"
    meta = {"scale": (2.0, 0.5, 0.25), "translate": (1.0, 0.25, 0.125), "name": "sel",
            "metadata": {"unit": "mm"}}
    written = npe2.write(str(out), [(lab, meta, "labels")], plugin_name="geoshade")
    assert written == [str(out)]
    back = geoshade.load(out)
    np.testing.assert_array_equal(back.read_box(), lab)
    assert back.dtype == np.uint8 and back.spacing == (0.25, 0.5, 2.0)
    assert back.origin == (0.0, 0.0, 0.0) and back.unit == "mm"
    attrs = json.loads((out / "zarr.json").read_text())["attributes"]
    assert attrs["ome"]["version"] == "0.5" and attrs["labels"] is True  # an OME-Zarr image
    data, kw, kind = _read(out)  # and napari opens it as labels again, in place
    assert kind == "labels" and kw["scale"] == meta["scale"]
    assert kw["translate"] == meta["translate"]
    np.testing.assert_array_equal(np.asarray(data), lab)


# --- napari itself (headless) ----------------------------------------------------------------
@pytest.fixture
def napari_mod(pm, monkeypatch):
    monkeypatch.setenv("QT_QPA_PLATFORM", "offscreen")
    return pytest.importorskip("napari")


def test_viewer_model_opens_selects_and_saves(napari_mod, store, tmp_path):
    from napari.components import ViewerModel

    from geoshade.napari import selection_widget

    path, a = store
    viewer = ViewerModel()
    [layer] = viewer.open(str(path), plugin="geoshade")
    assert type(layer).__name__ == "Image" and layer.multiscale
    assert list(layer.scale) == [2.0, 0.5, 0.5] and layer.level_shapes.tolist() == [
        [12, 10, 14], [6, 5, 7], [3, 3, 4]]
    assert [str(u) for u in layer.units] == ["micrometer"] * 3
    labels = viewer.add_layer(napari_mod.layers.Layer.create(*selection_widget(layer, 0, 500)))
    assert type(labels).__name__ == "Labels"
    assert list(labels.scale) == list(layer.scale)
    assert list(labels.translate) == list(layer.translate)
    sel = np.asarray(labels.data)
    np.testing.assert_array_equal(sel, (a <= 500).astype(np.uint8))
    viewer.layers.selection = {labels}
    out = tmp_path / "pores.zarr"
    assert viewer.layers.save(str(out), selected=True, plugin="geoshade") == [str(out)]
    back = geoshade.load(out)
    np.testing.assert_array_equal(back.read_box(), sel)
    assert back.spacing == (0.5, 0.5, 2.0) and back.origin == (1.0, 2.0, 3.0)


def test_selection_widget_is_generated_from_its_signature(napari_mod):
    pytest.importorskip("magicgui")
    from magicgui import magic_factory

    from geoshade.napari import selection_widget

    try:
        widget = magic_factory(selection_widget)()
    except Exception as err:  # no Qt application possible here
        pytest.skip(f"Qt cannot start: {err}")
    assert [w.name for w in widget][:4] == ["image", "lo", "hi", "label"]
    image = napari_mod.layers.Image(_vol((3, 4, 5)), scale=(2, 1, 1))
    data, kw, kind = widget(image, 100, 900, 1)
    assert kind == "labels" and kw["scale"] == (2.0, 1.0, 1.0)
    np.testing.assert_array_equal(data, ((image.data >= 100) & (image.data <= 900)).astype(
        np.uint8))


def _drawing_failed(err: BaseException) -> bool:
    """True when ``err`` came from napari's canvas (vispy, OpenGL), not from the plugin."""
    tb = err.__traceback__
    while tb is not None:
        name = tb.tb_frame.f_code.co_filename.replace(os.sep, "/")
        if "/vispy/" in name or "/napari/_vispy/" in name or "/OpenGL/" in name:
            return True
        tb = tb.tb_next
    return False


def test_napari_viewer_opens_with_the_plugin(napari_mod, store):
    """The real viewer, where Qt and OpenGL can start (skipped with the reason elsewhere)."""
    path, _ = store
    try:
        viewer = napari_mod.Viewer(show=False)
    except Exception as err:
        pytest.skip(f"Qt cannot start: {err}")
    try:
        layers = viewer.open(str(path), plugin="geoshade")
    except Exception as err:
        if not _drawing_failed(err):
            raise
        with contextlib.suppress(Exception):
            viewer.close()
        pytest.skip(f"napari's canvas cannot draw here (offscreen Qt without usable OpenGL: "
                    f"{type(err).__name__})")
    try:
        assert layers[0].multiscale and list(layers[0].scale) == [2.0, 0.5, 0.5]
    finally:
        viewer.close()
