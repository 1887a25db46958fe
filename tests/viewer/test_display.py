"""The desktop viewer where no window can be opened: one line saying what to install or to use
``--screenshot``, never Qt aborting the process; and the real xcb window under Xvfb."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time

import pytest

pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")


def _env(**changes) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY",
                                                            "QT_QPA_PLATFORM")}
    env.update({k: v for k, v in changes.items() if v is not None})
    return env


def _view(env, *args, timeout=120):
    return subprocess.run([sys.executable, "-m", "geoshade.cli.main", "view", *args],
                          capture_output=True, text=True, env=env, timeout=timeout)


def test_no_display_is_one_line():
    r = _view(_env(), "--demo", "core")
    assert r.returncode == 8 and r.stderr.count("\n") == 1, r.stderr
    assert r.stderr.startswith("geoshade: error: no display") and "--screenshot" in r.stderr


def test_an_unreachable_x_display_is_one_line():
    r = _view(_env(DISPLAY=":4711"), "--demo", "core")
    assert r.returncode == 8 and r.stderr.count("\n") == 1, r.stderr
    assert "cannot connect to the X display :4711" in r.stderr and "Traceback" not in r.stderr


def test_a_missing_xcb_library_is_named(monkeypatch):
    """Qt would print a plugin error and abort; we name the library and the packages."""
    import ctypes

    from geoshade.viewer import app

    real = ctypes.CDLL

    def cdll(name, *a, **kw):
        if str(name).endswith("libqxcb.so"):
            raise OSError("libxcb-cursor.so.0: cannot open shared object file: No such file or "
                          "directory")
        return real(name, *a, **kw)

    monkeypatch.setattr(ctypes, "CDLL", cdll)
    monkeypatch.setenv("DISPLAY", ":0")
    monkeypatch.delenv("QT_QPA_PLATFORM", raising=False)
    msg = app.platform_problem()
    assert msg.startswith("Qt's xcb platform cannot load (libxcb-cursor.so.0 is missing)")
    assert "apt-get install -y libxcb-cursor0" in msg


@pytest.mark.gl
def test_screenshot_needs_no_display(tmp_path):
    out = tmp_path / "s.png"
    r = _view(_env(DISPLAY=":4711"), "--demo", "core", "--screenshot", out, "--size",
              "120x90")
    assert r.returncode == 0 and out.stat().st_size > 0, r.stderr


@pytest.fixture
def xvfb():
    """A virtual X server on a free display (CI installs Xvfb; .ci/run)."""
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed (apt-get install -y xvfb; .ci/run does)")
    for n in range(90, 120):
        if not os.path.exists(f"/tmp/.X11-unix/X{n}") and not os.path.exists(f"/tmp/.X{n}-lock"):
            break
    proc = subprocess.Popen(["Xvfb", f":{n}", "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for _ in range(100):
        if os.path.exists(f"/tmp/.X11-unix/X{n}"):
            break
        time.sleep(0.05)
    yield f":{n}"
    proc.terminate()
    proc.wait(10)


@pytest.mark.gl
def test_the_real_xcb_window_under_xvfb(xvfb, tmp_path):
    """The window opens on Qt's xcb platform (not offscreen), draws the demo and saves it."""
    from geoshade.viewer.app import xcb_problem

    env = _env(DISPLAY=xvfb)
    os.environ["DISPLAY"], saved = xvfb, os.environ.get("DISPLAY")
    try:
        problem = xcb_problem()
    finally:
        if saved is None:
            del os.environ["DISPLAY"]
        else:
            os.environ["DISPLAY"] = saved
    assert problem is None, problem
    out = tmp_path / "x.png"
    script = ("from geoshade.viewer.app import application\n"
              "app = application()\n"
              "print(app.platformName())\n"
              "from geoshade.viewer.window import run_viewer\n"
              f"raise SystemExit(run_viewer(demo='core', screenshot={str(out)!r}, "
              "size=(160, 120)))\n")
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env,
                       timeout=180)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines()[0] == "xcb"
    import numpy as np
    from PIL import Image

    img = np.asarray(Image.open(out).convert("RGB"))
    assert img.shape == (120, 160, 3) and len(np.unique(img.reshape(-1, 3), axis=0)) > 10


@pytest.mark.gl
@pytest.mark.parametrize("kind", ["grid", "stacks"])
def test_a_screenshot_never_clips_the_model(tmp_path, kind):
    """The demo grid at exaggeration 5 (and the stacks at 10): the picture has a white border."""
    import numpy as np
    from PIL import Image

    out = tmp_path / "s.png"
    r = _view(_env(), "--demo", kind, "--screenshot", out, "--size", "500x260")
    assert r.returncode == 0, r.stderr
    img = np.asarray(Image.open(out).convert("RGB"))
    # the 3D model (the part of the picture that is not white nor annotation text) stays
    # inside: the outermost two pixel rows/columns are background
    edge = np.concatenate([img[:2].reshape(-1, 3), img[-2:].reshape(-1, 3),
                           img[:, :2].reshape(-1, 3), img[:, -2:].reshape(-1, 3)])
    assert (edge >= 250).all()
