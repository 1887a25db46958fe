"""``geoshade serve`` in a real browser (headless Chromium): the streamed lossless frame equals
``render`` of the same options and camera pixel for pixel, after a camera drag, a property and a
step change; a click's read-out is the model's value; tabs share the data, not their options."""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

import geoshade
from geoshade.render.camera import Camera
from geoshade.styles.saved_camera import SavedCamera
from geoshade.viewer.session import DEGREES_PER_PIXEL
from geoshade.viewer.views import prepare
from tests.web.conftest import SIZE, WAIT_S, settled_still, still_image, wait_for

pytestmark = pytest.mark.gl


@pytest.fixture(scope="module")
def page(served, browser):
    """The page of the served case at 320x240, its first lossless frame shown."""
    browser.get(f"{served.url}&size={SIZE[0]}x{SIZE[1]}")
    settled_still(browser, 0, lambda s: s["kind"] == "grid")
    return browser


@pytest.fixture(scope="module")
def oracle(case_dir):
    """The View ``render`` would draw with the options the page opened with."""
    opening = prepare(str(case_dir["EGRID"]))
    with geoshade.view(geoshade.load(case_dir["EGRID"]), size=SIZE,
                       options=opening.options) as v:
        yield v


def camera_of(s: dict) -> Camera:
    return Camera.from_saved(SavedCamera.from_dict(s["still"]["camera"]))


def assert_same_picture(page, s, oracle) -> np.ndarray:
    got = still_image(page)
    want, _ = oracle.draw(camera_of(s))
    assert got.shape == want.shape
    diff = np.argwhere(np.any(got != want, axis=-1))
    assert diff.size == 0, f"{len(diff)} pixels differ, first at (row, col) {diff[:3].tolist()}"
    return got


def drag(page, dx: int, dy: int) -> None:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    img = page.find_element(By.ID, "frame")
    chain = ActionChains(page).move_to_element(img).click_and_hold()
    for _ in range(4):
        chain = chain.move_by_offset(dx // 4, dy // 4).pause(0.05)
    chain.release().perform()


def test_first_frame_is_render(page, oracle):
    s = settled_still(page, 0)
    assert s["still"]["width"] == SIZE[0] and s["still"]["height"] == SIZE[1]
    img = assert_same_picture(page, s, oracle)
    assert len(np.unique(img.reshape(-1, 4), axis=0)) > 20   # a picture, not a blank
    assert "cells" in s["last"]["readout"]


def test_drag_turns_the_camera(page, oracle):
    before = settled_still(page, 0)
    cam0 = camera_of(before)
    drag(page, 40, 20)
    s = settled_still(page, before["last"]["seq"],
                      lambda s: s["still"]["camera"]["azimuth"] != cam0.azimuth)
    cam = camera_of(s)
    # the whole drag turned the camera: 40 px right and 20 px down, as the desktop viewer does
    assert cam.azimuth == pytest.approx((cam0.azimuth - 40 * DEGREES_PER_PIXEL) % 360, abs=1e-6) \
        or cam.azimuth == pytest.approx(cam0.azimuth - 40 * DEGREES_PER_PIXEL, abs=1e-6)
    assert cam.elevation == pytest.approx(cam0.elevation + 20 * DEGREES_PER_PIXEL, abs=1e-6)
    assert_same_picture(page, s, oracle)


def test_property_and_step(page, oracle):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    s0 = settled_still(page, 0)
    Select(page.find_element(By.ID, "ctl-property")).select_by_visible_text("SWAT")
    s = settled_still(page, s0["last"]["seq"], lambda s: s["settings"]["property"] == "SWAT")
    oracle.update(property="SWAT")
    assert_same_picture(page, s, oracle)
    assert s["settings"]["step"] == 2   # the last step, as render's default
    page.execute_script("const r = document.getElementById('ctl-step'); r.value = 0;"
                        "r.dispatchEvent(new Event('change'));")
    s = settled_still(page, s["last"]["seq"], lambda s: s["settings"]["step"] == 0)
    oracle.update(step=0)
    img = assert_same_picture(page, s, oracle)
    assert "2000-01-01" in page.find_element(By.ID, "ctl-step").find_element(
        By.XPATH, "following-sibling::div").text
    assert img.shape[:2] == (SIZE[1], SIZE[0])


def test_click_picks_a_cell(page, oracle, case_dir):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    s0 = settled_still(page, 0)
    oracle.draw(camera_of(s0))
    w, h = SIZE
    hit = None
    for y in range(h // 3, 2 * h // 3, 7):   # a pixel of the picture that shows a cell
        for x in range(w // 4, 3 * w // 5, 7):
            p = oracle.pick(x, y)
            if p is not None:
                hit = (x, y, p)
                break
        if hit:
            break
    assert hit is not None
    x, y, want = hit
    img = page.find_element(By.ID, "frame")
    ActionChains(page).move_to_element_with_offset(img, x - w // 2, y - h // 2).click().perform()
    s = wait_for(page, lambda s: s["pick"] is not None, "the pick read-out")
    got = s["pick"]
    assert tuple(got["index"]) == tuple(want.index)
    g = geoshade.load(case_dir["EGRID"])
    i, j, k = got["index"]
    step = s["settings"]["step"]
    assert s["settings"]["property"] == "SWAT"
    assert got["value"] == pytest.approx(float(np.asarray(g.steps[step]["SWAT"])[i, j, k]),
                                         rel=1e-6)
    text = page.find_element(By.ID, "pick").text
    assert text and f"{i + 1}" in text


def test_tabs_share_data_not_options(page):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    first = page.current_window_handle
    url = page.current_url.split("#")[0]   # the address without its view (that one shares it)
    page.switch_to.new_window("tab")
    try:
        page.get(url)
        s = settled_still(page, 0, lambda s: s["kind"] == "grid")
        assert s["reads"] == 1                       # the file was read once, for both tabs
        assert s["settings"]["property"] == "PORO"   # its own options: not the other tab's
        Select(page.find_element(By.ID, "ctl-faults")).select_by_visible_text("hide")
        settled_still(page, s["last"]["seq"], lambda s: s["settings"]["faults"] == "hide")
    finally:
        page.close()
        page.switch_to.window(first)
    time.sleep(0.5)
    s = wait_for(page, lambda s: True, "the first tab")
    assert s["settings"]["property"] == "SWAT" and s["settings"]["faults"] == "show"


def test_camera_save_and_screenshot(page):
    from selenium.webdriver.common.by import By

    s = settled_still(page, 0)
    folder = Path(page.download_dir)
    for f in folder.glob("*.json"):
        f.unlink()
    page.find_element(By.ID, "save-camera").click()
    path = folder / "camera.json"
    t0 = time.monotonic()
    while not path.exists() and time.monotonic() - t0 < WAIT_S:
        time.sleep(0.2)
    if not path.exists():
        pytest.skip("this Chromium does not save downloads headless")
    assert json.loads(path.read_text()) == s["still"]["camera"]
    assert Camera.load(path).azimuth == s["still"]["camera"]["azimuth"]
    page.find_element(By.ID, "screenshot").click()
    t0 = time.monotonic()
    while not list(folder.glob("geoshade-grid-*.png")) and time.monotonic() - t0 < WAIT_S:
        time.sleep(0.2)
    from PIL import Image

    shot = np.asarray(Image.open(next(folder.glob("geoshade-grid-*.png"))).convert("RGBA"))
    assert np.array_equal(shot, still_image(page))
    shutil.rmtree(folder / "unused", ignore_errors=True)


def test_categorical_control_takes_the_legend_away(browser, tmp_path):
    """(Last in this module: it takes the browser to another server.) Issue 30: the browser's
    "categorical" control drives the same declaration as
    ``update(categorical=False)``: on a region property the legend goes and a colour bar comes,
    the frame equal to a View changed the same way."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.egrid_writer import write_egrid, write_init
    from tests.web.conftest import Served

    grid = synthetic_grid(10, 8, 4, seed=1)
    write_egrid(grid, tmp_path / "R.EGRID")
    write_init(grid, tmp_path / "R.INIT")
    served = Served([str(tmp_path / "R.EGRID"), "--property", "FIPNUM"])
    try:
        browser.get(f"{served.url}&size={SIZE[0]}x{SIZE[1]}")
        s1 = settled_still(browser, 0, lambda s: s["kind"] == "grid")
        opening = prepare(str(tmp_path / "R.EGRID"), property="FIPNUM")
        with geoshade.view(geoshade.load(tmp_path / "R.EGRID"), size=SIZE,
                           options=opening.options) as oracle:
            with_legend = assert_same_picture(browser, s1, oracle)
            assert oracle.draw(camera_of(s1))[1].get("categories")   # codes drawn as classes
            Select(browser.find_element(By.ID, "ctl-categorical")).select_by_visible_text("no")
            s2 = settled_still(browser, s1["last"]["seq"],
                               lambda s: s["settings"]["color"]["categorical"] is False)
            oracle.update(categorical=False)
            without = assert_same_picture(browser, s2, oracle)
            assert not oracle.draw(camera_of(s2))[1].get("categories")   # the legend went
            assert not np.array_equal(with_legend, without)
    finally:
        served.stop()
