"""The notebook widget (``geoshade.show``, :mod:`geoshade.viewer.notebook`) in a real JupyterLab,
once: ``jupyter lab --no-browser`` on a free port with a token in a temporary folder, headless
Chromium opens a notebook that shows a small synthetic core, runs its cell, and the picture
the widget shows once it rests equals ``render`` of the same options pixel for pixel.

jupyter_rfb sends JPEG frames while the view changes and, 0.3 s after the last one, the same
frame again as a lossless PNG (``RemoteFrameBuffer._rfb_schedule_lossless_draw``): the test
waits for that PNG, so the comparison is exact (RGB: the widget drops alpha; geoshade's opaque
pictures have alpha 255 everywhere).

Skipped with the reason where JupyterLab, jupyter_rfb, ipykernel, selenium or Chromium is
absent.
"""

from __future__ import annotations

import base64
import io
import json
import os
import secrets
import socket
import subprocess
import sys
import time
import urllib.request

import numpy as np
import pytest

from tests.web.conftest import WAIT_S, need_browser

pytestmark = pytest.mark.gl

SIZE = (320, 240)
#: the notebook's one cell: the widget, and the camera it starts with written beside it
CELL = f"""import geoshade
from geoshade.compute.voxels.synthetic import synthetic_core
w = geoshade.show(synthetic_core(24), size={SIZE}, select=(0, 19000))
open("camera.json", "w").write(w.session.camera.saved().to_json())
w"""


def need_lab() -> None:
    need_browser()
    for name in ("jupyterlab", "jupyter_rfb", "ipykernel"):
        pytest.importorskip(name, reason=f"{name} is not installed (pip install jupyterlab "
                                         "'geoshade[viewer]')")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A JupyterLab server on 127.0.0.1 in a temporary folder holding ``widget.ipynb``."""
    need_lab()
    d = tmp_path_factory.mktemp("lab")
    nb = {"nbformat": 4, "nbformat_minor": 5,
          "metadata": {"kernelspec": {"name": "python3", "display_name": "Python 3",
                                      "language": "python"}},
          "cells": [{"cell_type": "code", "id": "widget", "metadata": {}, "outputs": [],
                     "execution_count": None, "source": CELL}]}
    (d / "widget.ipynb").write_text(json.dumps(nb))
    port, token = _free_port(), secrets.token_hex(16)
    env = {**os.environ, "JUPYTER_RUNTIME_DIR": str(d / ".runtime"),
           "IPYTHONDIR": str(d / ".ipython"), "JUPYTER_CONFIG_DIR": str(d / ".config"),
           "PYTHONPATH": os.pathsep.join([os.getcwd(), os.environ.get("PYTHONPATH", "")])}
    log = open(d / "lab.log", "w")   # closed below
    proc = subprocess.Popen(
        [sys.executable, "-m", "jupyterlab", "--no-browser", "--allow-root",
         "--ServerApp.ip=127.0.0.1", f"--ServerApp.port={port}",
         f"--IdentityProvider.token={token}", f"--ServerApp.root_dir={d}",
         "--ServerApp.port_retries=0", "--LabApp.news_url=", "--LabApp.check_for_updates_class="
         "jupyterlab.NeverCheckForUpdate"],
        cwd=d, env=env, stdout=log, stderr=subprocess.STDOUT)
    base = f"http://127.0.0.1:{port}"
    t0 = time.monotonic()
    while True:
        try:
            with urllib.request.urlopen(f"{base}/api/status?token={token}", timeout=2) as r:
                if r.status == 200:
                    break
        except OSError:
            pass
        if proc.poll() is not None or time.monotonic() - t0 > WAIT_S:
            proc.kill()
            log.close()
            raise AssertionError("jupyter lab did not start: "
                                 + (d / "lab.log").read_text()[-2000:])
        time.sleep(0.3)
    yield base, token, d
    proc.terminate()   # the server shuts its kernels down
    try:
        proc.wait(30)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(10)
    log.close()


def _widget_png(driver) -> tuple[bytes, tuple[int, int]] | None:
    """The bytes of the picture the widget's ``<img>`` shows and the element's size in CSS
    pixels, or None (none yet)."""
    data = driver.execute_async_script("""
        const done = arguments[arguments.length - 1];
        const img = document.querySelector(".jp-OutputArea-output img.renderview-view");
        if (!img || !img.src) { done(null); return; }
        const size = [img.clientWidth, img.clientHeight];
        fetch(img.src).then((r) => r.arrayBuffer()).then((b) => {
          let s = ""; const u = new Uint8Array(b);
          for (let i = 0; i < u.length; i += 8192) {
            s += String.fromCharCode(...u.subarray(i, i + 8192));
          }
          done([btoa(s), size]);
        }).catch(() => done(null));""")
    return None if data is None else (base64.b64decode(data[0]), tuple(data[1]))


def test_widget_in_jupyterlab_draws_what_render_draws(lab, browser):
    from PIL import Image
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    import geoshade
    from geoshade.compute.voxels.synthetic import synthetic_core
    from geoshade.render.camera import Camera
    from geoshade.viewer.views import prepare

    base, token, d = lab
    seen: list = []
    browser.get(f"{base}/lab/tree/widget.ipynb?token={token}")
    t0 = time.monotonic()

    def wait(test, what):
        while True:
            got = test()
            if got:
                return got
            if time.monotonic() - t0 > WAIT_S:
                raise AssertionError(f"waited {WAIT_S:.0f} s for {what} (seen: {seen[-3:]}); "
                                     "JupyterLab log: "
                                     + (d / "lab.log").read_text()[-1500:])
            time.sleep(0.3)

    def kernel_idle():
        text = browser.execute_script("return document.body.innerText")
        return "Idle" in text and "Python 3" in text

    wait(lambda: browser.find_elements(By.CSS_SELECTOR, ".jp-Notebook .jp-Cell .cm-content"),
         "the notebook")
    wait(kernel_idle, "the kernel")
    cell = browser.find_element(By.CSS_SELECTOR, ".jp-Notebook .jp-Cell .cm-content")
    cell.click()
    ActionChains(browser).key_down(Keys.SHIFT).send_keys(Keys.ENTER).key_up(Keys.SHIFT).perform()

    def lossless():
        """A PNG of the size the widget shows (the first is jupyter_rfb's 1x1 stand-in; the
        widget then draws at its element's size, its border inside SIZE)."""
        got = _widget_png(browser)
        if not (got and got[0].startswith(b"\x89PNG")):
            return None
        data, shown = got
        w, h = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
        seen.append(((w, h), shown))
        return data if (w, h) == shown and w > SIZE[0] - 8 else None


    png = wait(lossless, "the widget's lossless frame")
    time.sleep(1.0)   # the picture rests: no newer frame
    png = wait(lossless, "the widget's lossless frame")
    got = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))
    size = (got.shape[1], got.shape[0])
    errors = browser.find_elements(By.CSS_SELECTOR, ".jp-OutputArea-output[data-mime-type="
                                                    "'application/vnd.jupyter.stderr']")
    assert not [e.text for e in errors if "Error" in e.text]

    # the widget started with the camera render frames the model with at SIZE; JupyterLab then
    # gave it its element's size, and an untouched widget frames the model again for that
    # size (Session.resize): what `render --size WxH` draws
    camera = Camera.load(d / "camera.json")
    opening = prepare(synthetic_core(24), select=(0, 19000))
    with geoshade.view(opening.model, size=SIZE, options=opening.options) as v:
        framed, _ = v.draw()
        assert np.array_equal(framed, v.draw(camera)[0])
    with geoshade.view(opening.model, size=size, options=opening.options) as v:
        want, _ = v.draw()
    diff = np.argwhere(np.any(got != want[..., :3], axis=-1))
    assert diff.size == 0, f"{len(diff)} pixels differ, first at {diff[:3].tolist()}"
    assert np.all(want[..., 3] == 255)
    assert len(np.unique(got.reshape(-1, 3), axis=0)) > 20   # a picture, not a blank
