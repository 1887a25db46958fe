"""Fixtures of the browser tests: a ``geoshade serve`` process, headless Chromium (Debian's
``chromium`` and ``chromium-driver``, driven by selenium), small cases written per session.

Skipped with the reason where the web extra, selenium, Chromium or OpenGL is absent.
"""

from __future__ import annotations

import base64
import io
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from tests.grid_cases import grid_cases

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
#: the flags the browser runs with: no sandbox (root in a container), no GPU, no network chatter
CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                  "--no-first-run", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync")
#: generous: a loaded two-core machine draws with llvmpipe
WAIT_S = 120.0
SIZE = (320, 240)


def need_web():
    pytest.importorskip("aiohttp", reason="the web extra is not installed (pip install "
                                          "'geoshade[web]')")


def need_browser():
    need_web()
    pytest.importorskip("selenium", reason="selenium is not installed")
    for p in (CHROMIUM, CHROMEDRIVER):
        if not os.path.exists(p):
            pytest.skip(f"{p} is absent (apt-get install chromium chromium-driver)")


class Served:
    """A running ``geoshade serve``: its URL (with the token) and its process.

    ``prelude``: Python run before ``main`` in that process; ``nofile``: its limit of open
    files (soft and hard), for the hostile tests."""

    def __init__(self, args, cwd=None, prelude: str = "", nofile: int | None = None):
        code = "; ".join(["import sys", *([prelude] if prelude else []),
                          "from geoshade.cli.main import main", "sys.exit(main(sys.argv[1:]))"])

        def limit():
            if nofile is not None:
                resource.setrlimit(resource.RLIMIT_NOFILE, (nofile, nofile))

        self.proc = subprocess.Popen([sys.executable, "-c", code, "serve", "--port", "0", *args],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     cwd=cwd, preexec_fn=limit if nofile else None)
        self.lines: list[str] = []
        self.errors: list[str] = []
        ready = threading.Event()

        def read(stream, into):
            for line in stream:
                into.append(line)
                if "http://" in line:
                    ready.set()

        threading.Thread(target=read, args=(self.proc.stdout, self.lines), daemon=True).start()
        threading.Thread(target=read, args=(self.proc.stderr, self.errors), daemon=True).start()
        t0 = time.monotonic()
        while not ready.wait(0.2):
            if self.proc.poll() is not None or time.monotonic() - t0 > WAIT_S:
                self.stop()
                raise AssertionError("geoshade serve did not start: " + "".join(self.errors))
        line = next(x for x in self.lines if "http://" in x)
        self.url = line.split()[-1]
        self.base, self.token = self.url.split("/?token=")

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10)


@pytest.fixture(scope="session")
def case_dir():
    """A small ECLIPSE case with three report steps (EGRID, INIT, UNRST) and a GRDECL file."""
    d = Path(tempfile.mkdtemp(prefix="geoshade-web-"))
    paths = grid_cases().write_case(d / "case", 8, 6, 3, steps=3)
    yield paths
    shutil.rmtree(d, ignore_errors=True)


@pytest.fixture(scope="session")
def served(case_dir):
    """``geoshade serve CASE.EGRID`` for the whole session."""
    need_web()
    s = Served([str(case_dir["EGRID"])])
    yield s
    s.stop()


@pytest.fixture(scope="session")
def browser():
    """Headless Chromium with a fresh profile (selenium, the system's chromedriver)."""
    need_browser()
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="geoshade-chromium-")
    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for flag in (*CHROMIUM_FLAGS, f"--user-data-dir={profile}", "--window-size=1000,760"):
        opts.add_argument(flag)
    opts.add_experimental_option("prefs", {"download.default_directory": profile})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=opts)
    driver.set_script_timeout(WAIT_S)
    driver.download_dir = profile
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


# --- helpers the tests share -------------------------------------------------------------------
def state(driver) -> dict:
    """What the page's script keeps in ``window.geoshade`` (the last still's meta, not its URL)."""
    return driver.execute_script("""
        const g = window.geoshade;
        return JSON.parse(JSON.stringify({frames: g.frames, stills: g.stills, last: g.last,
            still: g.still && g.still.meta, pick: g.pick, settings: g.settings,
            errors: g.errors, kind: g.kind, reads: g.reads, busy: g.busy,
            version: g.version, plots: g.plots}));""")


def wait_for(driver, test, what: str, timeout: float = WAIT_S) -> dict:
    """Poll the page's state until ``test(state)`` holds."""
    t0 = time.monotonic()
    while True:
        s = state(driver)
        if s["errors"]:
            raise AssertionError(f"the page shows an error: {s['errors'][-1]}")
        if test(s):
            return s
        if time.monotonic() - t0 > timeout:
            raise AssertionError(f"waited {timeout:.0f} s for {what}; last state {s}")
        time.sleep(0.2)


def settled_still(driver, after_seq: int, test=lambda s: True, quiet_s: float = 1.5) -> dict:
    """The page's lossless frame once the picture rests: a still newer than ``after_seq``
    drawn with the settings the page last heard (their ``version``) for which ``test`` holds,
    and no newer frame for ``quiet_s`` seconds."""
    def drawn(s):
        return (s["last"] and s["last"]["still"] and s["last"]["seq"] > after_seq
                and s["last"].get("version", 0) >= (s.get("version") or 0) and test(s))

    s = wait_for(driver, drawn, "a new lossless frame")
    while True:
        time.sleep(quiet_s)
        t = state(driver)
        if t["last"]["seq"] == s["last"]["seq"] and t["last"]["still"]:
            return t
        s = wait_for(driver, drawn, "the frame to rest")


def still_image(driver) -> np.ndarray:
    """The last lossless frame the page shows, as the browser received it (RGBA)."""
    return still_with_meta(driver)[0]


def still_with_meta(driver) -> tuple[np.ndarray, dict]:
    """The last lossless frame the page shows (RGBA) and its meta (``state``, ``camera``...),
    read in one script: a frame that arrives between two reads would pair one frame's
    picture with another's meta."""
    from PIL import Image

    data, meta = driver.execute_async_script("""
        const done = arguments[arguments.length - 1];
        const still = window.geoshade.still;
        fetch(still.url).then((r) => r.arrayBuffer()).then((b) => {
          let s = ""; const u = new Uint8Array(b);
          for (let i = 0; i < u.length; i += 8192) {
            s += String.fromCharCode(...u.subarray(i, i + 8192));
          }
          done([btoa(s), JSON.parse(JSON.stringify(still.meta))]);
        });""")
    return np.asarray(Image.open(io.BytesIO(base64.b64decode(data))).convert("RGBA")), meta
