"""``geoshade serve`` opens what ``geoshade view`` opens, with the same input options from one
definition (:mod:`geoshade.cli.inputs`): a headerless raw volume with ``--shape --dtype`` and a
``--select`` drawn in a real browser equals ``render`` of the same array read another way."""

from __future__ import annotations

import argparse

import numpy as np
import pytest

import geoshade
from geoshade.cli.main import build_parser, main
from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.render.camera import Camera
from geoshade.styles.saved_camera import SavedCamera
from tests.web.conftest import Served, need_web, settled_still, still_image

#: the options only one of the two commands has: what view draws without a browser, and where
#: serve listens
VIEW_ONLY = {"--screenshot"}
SERVE_ONLY = {"--root", "--host", "--port"}


def _options(command: str) -> dict[str, argparse.Action]:
    sub = next(a for a in build_parser()._actions
               if isinstance(a, argparse._SubParsersAction)).choices[command]
    return {o: a for a in sub._actions for o in a.option_strings}


def test_view_and_serve_take_the_same_input_options():
    view, serve = _options("view"), _options("serve")
    assert set(view) - VIEW_ONLY == set(serve) - SERVE_ONLY
    for flag in ("--demo", "--shape", "--dtype", "--endian", "--spacing", "--unit",
                 "--skip-missing", "--param", "--keyword", "--as", "--select", "--property",
                 "--step", "--edges", "--method", "--caps", "--layout", "--size"):
        a, b = view[flag], serve[flag]
        assert (a.dest, a.nargs, a.choices, a.default, a.help) == \
            (b.dest, b.nargs, b.choices, b.default, b.help), flag


@pytest.mark.parametrize(("args", "says"), [
    (["--keyword", "SWAT", "--as", "grid"], "--keyword: applies to fields over time"),
    (["--skip-missing", "--as", "iso"], "--skip-missing: applies to decks"),
    (["--distributed"], "--distributed: give the cluster with --scheduler"),
    (["--select", "1", "2", "3"], "--select"),
])
def test_serve_refuses_bad_input_options_in_one_line(tmp_path, capsys, args, says):
    need_web()
    f = tmp_path / "v.npy"
    np.save(f, np.zeros((4, 4, 4), np.uint8))
    assert main(["serve", str(f), "--port", "0", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert says in err and "\n" not in err and "Traceback" not in err


@pytest.fixture(scope="module")
def raw_case(tmp_path_factory):
    """A headerless uint16 volume 28×24×20 (x fastest) and the same array as ``.npy``."""
    d = tmp_path_factory.mktemp("raw")
    a = np.ascontiguousarray(synthetic_core(28).data[:20, :24, :])   # (z, y, x)
    a.tofile(d / "scan.raw")
    np.save(d / "same.npy", a)
    return d


@pytest.mark.gl
def test_raw_volume_in_the_browser(raw_case, browser):
    """``serve scan.raw --shape 28 24 20 --dtype uint16 --select 0 9000``: the page's lossless
    frame equals ``render`` of the same array read from ``.npy`` with that selection."""
    size = (160, 120)
    s = Served([str(raw_case / "scan.raw"), "--shape", "28", "24", "20", "--dtype", "uint16",
                "--select", "0", "9000"])
    try:
        browser.get(f"{s.url}&size={size[0]}x{size[1]}")
        st = settled_still(browser, 0, lambda st: st["kind"] == "core")
        assert st["settings"]["select"] == [0, 9000]
        got = still_image(browser)
    finally:
        s.stop()
    cam = Camera.from_saved(SavedCamera.from_dict(st["still"]["camera"]))
    model = geoshade.load(raw_case / "same.npy")
    assert model.shape_xyz == (28, 24, 20)
    with geoshade.view(model, size=size, select=(0, 9000), porosity="z",
                       annotations=True) as v:
        want, _ = v.draw(cam)
    assert got.shape == want.shape
    diff = np.argwhere(np.any(got != want, axis=-1))
    assert diff.size == 0, f"{len(diff)} pixels differ, first at {diff[:3].tolist()}"
    assert len(np.unique(got.reshape(-1, 4), axis=0)) > 20


@pytest.mark.gl
@pytest.mark.data
def test_real_raw_core_in_the_browser(shared_data, browser):
    """The Berea micro-CT as it ships (headerless uint8, 110³): ``serve berea_pore.raw --dtype
    uint8 --select 0 0 --porosity z`` (the cube the file size allows, the pore value); the
    page's lossless frame is ``render``'s picture and its read-out the pore fraction numpy
    counts."""
    f = shared_data / "microct_dpm_berea" / "berea_pore.raw"
    if not f.exists():
        pytest.skip(f"{f} is absent (see shared/data/README.md)")
    size = (200, 150)
    s = Served([str(f), "--dtype", "uint8", "--select", "0", "0", "--porosity", "z"])
    try:
        browser.get(f"{s.url}&size={size[0]}x{size[1]}")
        st = settled_still(browser, 0, lambda st: st["kind"] == "core")
        got = still_image(browser)
    finally:
        s.stop()
    data = np.fromfile(f, np.uint8).reshape(110, 110, 110)
    pores = float((data == 0).mean())
    assert f"porosity {pores:.4f}" in st["last"]["readout"]
    cam = Camera.from_saved(SavedCamera.from_dict(st["still"]["camera"]))
    with geoshade.view(geoshade.load(f, dtype="uint8"), size=size, select=(0, 0),
                       porosity="z", annotations=True) as v:
        want, _ = v.draw(cam)
    assert np.array_equal(got, want)
