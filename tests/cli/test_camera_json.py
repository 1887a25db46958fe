"""``--save-camera`` / ``--camera``: the camera of a picture as JSON reproduces it pixel for
pixel, in every part, from the CLI and the Python API."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

import geoshade
from geoshade.cli.main import main
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.compute.voxels.synthetic import random_labels, synthetic_core
from geoshade.errors import InputError
from geoshade.io.grids.grdecl_writer import write_grdecl
from geoshade.render.camera import Camera
from geoshade.styles.options import CameraSpec, SavedCamera

SIZE = "240x180"  # large enough for the annotations (their viewport is in the camera)


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("cam")
    np.save(d / "core.npy", np.asarray(synthetic_core(20).data))
    z, y, x = np.mgrid[0:10, 0:11, 0:12]
    np.save(d / "field.npy", np.stack([((x - 6) ** 2 + (y - 5) ** 2 + (z - 5) ** 2)
                                       / (30.0 + 10 * t) for t in range(3)]).astype(np.float32))
    write_grdecl(synthetic_grid(8, 6, 3), d / "case.grdecl")
    np.save(d / "labels.npy", np.asarray(random_labels((12, 10, 8), 0.5, seed=1).data)
            .astype(np.int32))
    assert main(["stacks", "convert", str(d / "labels.npy"), "-o", str(d / "m.stacks.npz"),
                 "--empty", "0", "--no-octree"]) == 0
    return d


def _commands(d):
    return {
        "core": ["core", "render", d / "core.npy", "--select", 0, 9000],
        "grid": ["grid", "render", d / "case.grdecl", "--property", "PORO", "--edges"],
        "iso": ["iso", "render", d / "field.npy", "--level", 1],
        "stacks": ["stacks", "render", d / "m.stacks.npz"],
    }


@pytest.mark.parametrize("part", ["core", "grid", "iso", "stacks"])
def test_saved_camera_reproduces_the_picture(ctx, capsys, tmp_path, inputs, part):
    base = _commands(inputs)[part]
    cam, a, b = tmp_path / "cam.json", tmp_path / "a.png", tmp_path / "b.png"
    rc, _, err = run(capsys, *base, "--size", SIZE, "--frames", 1, "--azimuth", 20,
                     "--elevation", 50, "--zoom", 1.3, "-o", a, "--save-camera", cam)
    assert rc == 0, err
    saved = json.loads(cam.read_text())
    assert saved["geoshade_camera"] == 1 and saved["azimuth"] == 20.0
    rc, _, err = run(capsys, *base, "--size", SIZE, "--frames", 1, "--camera", cam, "-o", b)
    assert rc == 0, err
    ia, ib = np.asarray(Image.open(a)), np.asarray(Image.open(b))
    assert (ia != ib[0, 0]).any()  # a picture, not a blank
    assert np.array_equal(ia, ib)
    # a different default camera gives a different picture: the file made the difference
    c = tmp_path / "c.png"
    assert run(capsys, *base, "--size", SIZE, "--frames", 1, "-o", c)[0] == 0
    assert not np.array_equal(np.asarray(Image.open(c)), ia)


def test_saved_camera_is_the_framed_camera(ctx, capsys, tmp_path, inputs):
    cam = tmp_path / "cam.json"
    rc, _, err = run(capsys, *_commands(inputs)["grid"], "--size", SIZE, "--frames", 1,
                     "--view", "top", "--ortho", "-o", tmp_path / "a.png", "--save-camera", cam)
    assert rc == 0, err
    grid = geoshade.load(inputs / "case.grdecl")
    with geoshade.view(grid, property="PORO", edges=True, size=(240, 180), view="top", ortho=True,
                       annotations=True) as v:
        framed = v.camera()
        assert Camera.load(cam).saved() == framed.saved()
        # the Python API takes the file too, and draws the CLI's picture
        img, _ = v.draw(Camera.load(cam))
    with geoshade.view(grid, property="PORO", edges=True, size=(240, 180), camera=str(cam),
                       annotations=True) as v:
        img2, _ = v.draw()
    assert np.array_equal(img, img2)
    assert np.array_equal(img2, np.asarray(Image.open(tmp_path / "a.png")))


def test_camera_json_round_trip_is_exact():
    cam = Camera.framed(np.array([[1.1, 2.2, -3.3], [4.4, 5.5, 6.6]]), azimuth=33.3,
                        elevation=-12.5, zoom=1.7, aspect=4 / 3,
                        viewport=(-0.97, -0.97, 0.7, 0.8))
    back = Camera.from_saved(SavedCamera.from_json(cam.saved().to_json()))
    assert np.array_equal(back.view_matrix(), cam.view_matrix())
    assert np.array_equal(back.projection_matrix(), cam.projection_matrix())
    spec = CameraSpec.parse(cam.saved().as_dict())
    assert Camera.framed(np.zeros((2, 3)), spec).saved() == cam.saved()


def test_camera_file_errors_are_one_line(capsys, tmp_path, inputs):
    base = _commands(inputs)["grid"]
    out = tmp_path / "o.png"
    bad = tmp_path / "bad.json"
    bad.write_text('{"view": "top"}')
    trunc = tmp_path / "trunc.json"
    trunc.write_text('{"geoshade_camera": 1, "target": [0, 0, 0], "distance": -1}')
    good = tmp_path / "good.json"
    Camera.framed(np.array([[0, 0, 0], [1, 1, 1.0]])).save(good)
    cases = [(("--camera", tmp_path / "none.json"), "no such camera file"),
             (("--camera", bad), "not a geoshade camera"),
             (("--camera", trunc), "missing"),
             (("--camera", bad, "--azimuth", 10), "give either it or azimuth"),
             (("--save-camera", tmp_path / "cam.txt"), "expected a name ending in .json"),
             (("--camera", good, "--save-camera", good), "names an input")]
    for extra, message in cases:
        rc, _, err = run(capsys, *base, "--size", "64x48", "-o", out, *extra)
        assert rc == 2 and message in err, (extra, err)
        assert len(err.strip().splitlines()) == 1
    assert not out.exists() and not (tmp_path / "cam.txt").exists()


def test_saved_camera_and_view_flags_refused_in_the_api():
    saved = Camera.framed(np.array([[0, 0, 0], [1, 1, 1.0]])).saved()
    with pytest.raises(InputError, match="give either it or azimuth"):
        CameraSpec.parse(saved, azimuth=10)
    # an existing spec holding a saved camera gives way to new angles (the viewer's orbit)
    spec = CameraSpec.parse(CameraSpec.parse(saved), azimuth=10)
    assert spec.saved is None and spec.azimuth == 10


def test_viewer_save_and_load_camera(ctx, tmp_path, capsys, inputs):
    """The viewer's Camera menu writes the camera the CLI reads, and reads the CLI's."""
    import os

    pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6")
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from geoshade.viewer.app import application
    from geoshade.viewer.window import ViewerWindow

    application(offscreen=True)
    win = ViewerWindow(size=(200, 150))
    win.show()
    try:
        win.open(geoshade.load(inputs / "case.grdecl"), settings={"property": "PORO"})
        win.wait_idle()
        assert [a.text() for a in win.camera_menu.actions()] == ["Save camera…", "Load camera…"]
        s = win.session
        s.orbit(40, -10)
        s.zoom(2)
        saved = win.save_camera(tmp_path / "viewer.json")
        assert saved is not None
        assert Camera.load(saved).saved() == s.camera.saved()
        # the CLI's camera, loaded in the viewer
        cli_cam = tmp_path / "cli.json"
        assert run(capsys, *_commands(inputs)["grid"], "--size", "200x150", "--frames", 1,
                   "--view", "top", "-o", tmp_path / "a.png", "--save-camera", cli_cam)[0] == 0
        assert win.load_camera(cli_cam)
        w, h = s.size  # the viewer's picture keeps its own shape
        assert s.camera.saved() == Camera.load(cli_cam).with_aspect(w / h).saved()
        assert not win.load_camera(tmp_path / "none.json")
        assert "no such camera file" in win.errors[-1]
        assert win.save_camera(tmp_path / "cam.txt") is None and "ending in .json" in \
            win.errors[-1]
    finally:
        win.close()
