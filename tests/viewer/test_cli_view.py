"""``geoshade view`` end to end in a subprocess (Qt's offscreen platform, no display)."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")


def _run(*args, cwd):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.pop("QT_QPA_PLATFORM", None)  # --screenshot must pick the offscreen platform itself
    return subprocess.run([sys.executable, "-m", "geoshade.cli.main", "view", *args], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=300)


def test_view_demo_screenshot(tmp_path, ctx):
    r = _run("--demo", "--screenshot", "out.png", "--size", "160x120", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    from PIL import Image

    img = np.asarray(Image.open(tmp_path / "out.png"))
    assert img.shape == (120, 160, 4) and (img[..., :3] != 255).any()
    assert "out.png: 160x120" in r.stdout


def test_view_file_with_raw_hints_and_errors(tmp_path, ctx):
    from geoshade.compute.voxels.synthetic import synthetic_core

    vol = synthetic_core(16, seed=2, dtype="uint8")
    np.asarray(vol.data).tofile(tmp_path / "core.raw")
    r = _run("core.raw", "--shape", "16", "16", "16", "--dtype", "uint8", "--select", "0", "60",
             "--screenshot", "a.png", "--size", "96x64", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "a.png").is_file()
    bad = _run("core.raw", "--screenshot", "b.png", cwd=tmp_path)  # raw without hints
    assert bad.returncode == 2 and not (tmp_path / "b.png").exists()
    assert bad.stderr.strip().splitlines() == [
        "geoshade: error: core.raw: headerless raw file and no .nhdr/.mhd header beside it; give "
        "--shape NX NY NZ and --dtype (the shape may be left out for a cube; its size fits the "
        "cube 16×16×16 int8/uint8, 8×8×8 float64), e.g. --shape 110 110 110 --dtype uint8"]
    assert _run("--screenshot", "c.png", cwd=tmp_path).stderr.strip() == (
        "geoshade: error: view: give a PATH to open, or --demo")
    r = _run("--demo", "--screenshot", "c.txt", cwd=tmp_path)
    assert r.returncode == 2 and "c.txt: --screenshot: expected a name ending in .png" in r.stderr


def test_view_without_display_is_one_line(tmp_path):
    r = _run("--demo", cwd=tmp_path)
    assert r.returncode == 8  # EXIT_VIEWER
    assert r.stderr.strip().splitlines() == [
        "geoshade: error: no display: set DISPLAY, or run under xvfb-run; or save a picture "
        "without a display: geoshade view ... --screenshot OUT.png"]
