"""The page at 1280×720 as a user sees it: the panel beside a picture that fills the rest of the
window, the picture equal to ``render`` at that size. With ``GEOSHADE_WEB_SCREENSHOT=FILE.jpg``
the test saves the page as the documentation's picture (``docs/guide/web.jpg``)::

    GEOSHADE_WEB_SCREENSHOT=docs/guide/web.jpg python -m pytest -q tests/web/test_docs_picture.py
"""

from __future__ import annotations

import io
import os

import numpy as np
import pytest

import geoshade
from geoshade.render.camera import Camera
from geoshade.styles.saved_camera import SavedCamera
from geoshade.viewer.views import prepare
from tests.grid_cases import grid_cases
from tests.web.conftest import Served, need_web, settled_still, still_image

pytestmark = pytest.mark.gl

WINDOW = (1280, 720)


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """A 24×20×6 ECLIPSE case with three report steps."""
    need_web()
    return grid_cases().write_case(tmp_path_factory.mktemp("docs") / "case", 24, 20, 6,
                                   steps=3, name="CASE")


def test_page_at_1280x720(case, browser):
    from PIL import Image
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    s = Served([str(case["EGRID"])])
    try:
        browser.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {
            "width": WINDOW[0], "height": WINDOW[1], "deviceScaleFactor": 1, "mobile": False})
        browser.get(s.url)
        st = settled_still(browser, 0, lambda st: st["kind"] == "grid")
        Select(browser.find_element(By.ID, "ctl-property")).select_by_visible_text("SWAT")
        st = settled_still(browser, st["last"]["seq"],
                           lambda st: st["settings"]["property"] == "SWAT")
        Select(browser.find_element(By.ID, "ctl-edges")).select_by_visible_text("quad")
        st = settled_still(browser, st["last"]["seq"],
                           lambda st: st["settings"]["edges"] == "quad")
        browser.find_element(By.ID, "frame").click()    # a pick: the read-out line
        st = settled_still(browser, 0, lambda st: st["pick"] is not None)
        got = still_image(browser)
        area = browser.execute_script(
            "const a = document.getElementById('area');"
            "return [a.clientWidth, a.clientHeight, innerWidth, innerHeight,"
            " document.getElementById('side').getBoundingClientRect().width];")
        shot = Image.open(io.BytesIO(browser.get_screenshot_as_png())).convert("RGB")
        where = os.environ.get("GEOSHADE_WEB_SCREENSHOT")
        if where:
            shot.save(where, quality=88)
    finally:
        browser.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})
        s.stop()
    assert shot.size == WINDOW and tuple(area[2:4]) == WINDOW
    # the picture fills the page beside the panel
    assert (got.shape[1], got.shape[0]) == (area[0], area[1])
    assert area[0] + area[4] > 0.95 * WINDOW[0] and area[1] > 0.8 * WINDOW[1]
    opening = prepare(str(case["EGRID"]))
    cam = Camera.from_saved(SavedCamera.from_dict(st["still"]["camera"]))
    with geoshade.view(geoshade.load(case["EGRID"]), size=(area[0], area[1]),
                       options=opening.options, property="SWAT", edges="quad") as v:
        want, _ = v.draw(cam)
    diff = np.argwhere(np.any(got != want, axis=-1))
    assert diff.size == 0, f"{len(diff)} pixels differ, first at {diff[:3].tolist()}"
