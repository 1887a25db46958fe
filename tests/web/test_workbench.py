"""Issue 33 in the browser, on the real OPM Flow run of Reek (restart and summary files): the
summary plot beside the picture has its cursor at the shown step, moving the step moves it and a
click on the plot moves the step (said in a line); picks are kept as tables of resfo's values
that follow the step, one can be removed, a kept cell's history is a plot; the I/J/K and value
range sliders cut what ``render`` cuts with the same options."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest

import geoshade
from geoshade.render.camera import Camera
from geoshade.styles.saved_camera import SavedCamera
from tests.viewer.reek_run import REEK, day, needs_reek, resfo_cell, x_of, y_mid
from tests.web.conftest import (
    Served,
    need_web,
    settled_still,
    state,
    still_image,
    still_with_meta,
    wait_for,
)

pytestmark = [pytest.mark.gl, needs_reek]


def _bench(driver) -> dict:
    return driver.execute_script("""
        const g = window.geoshade;
        return JSON.parse(JSON.stringify({summary: g.summary, history: g.history, cells: g.cells,
            cellsStep: g.cellsStep === undefined ? null : g.cellsStep, notes: g.notes,
            errors: g.errors}));""")


def _change(driver, element_id: str, value) -> None:
    """Set an input's value as the user leaves it (its change event)."""
    driver.execute_script("""
        const e = document.getElementById(arguments[0]);
        e.value = arguments[1];
        e.dispatchEvent(new Event("input")); e.dispatchEvent(new Event("change"));""",
                          element_id, value)


@pytest.fixture(scope="module")
def reek():
    need_web()
    s = Served([str(REEK)])
    yield s
    s.stop()


@pytest.fixture(scope="module")
def grid():
    return geoshade.load(REEK)


@pytest.fixture
def page(reek, browser):
    """The Reek run in a tab of its own, SWAT at step 5."""
    first = browser.current_window_handle
    browser.switch_to.new_window("tab")
    browser.get(reek.url)
    s = settled_still(browser, 0, lambda s: s["kind"] == "grid")
    browser.execute_script("send({t: 'set', values: {property: 'SWAT', step: 5}});")
    settled_still(browser, s["last"]["seq"], lambda s: s["settings"]["step"] == 5)
    yield browser
    browser.close()
    browser.switch_to.window(first)


def test_the_summary_cursor_follows_the_step_and_a_click_moves_it(page, grid):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    dates = grid.step_dates
    assert _bench(page)["summary"] is None   # no vector chosen: no plot
    _change(page, "ctl-summary", "FOPR, FPR")
    b = wait_for(page, lambda s: _bench(page)["summary"] is not None, "the summary plot")
    b = _bench(page)
    assert b["summary"]["vectors"] == ["FOPR", "FPR"]
    assert state(page)["settings"]["summary"] == ["FOPR", "FPR"]
    cur = b["summary"]["layout"]["cursor"]
    assert day(cur["date"]) == dates[5] and cur["report"] == 5
    units = [a["unit"] for a in b["summary"]["layout"]["axes"]]
    assert units and all(units), units   # SMSPEC's units on the axes
    _change(page, "ctl-step", 20)         # moving the step moves the cursor
    wait_for(page, lambda s: (_bench(page)["summary"] or {}).get("step") == 20, "cursor at 20")
    assert day(_bench(page)["summary"]["layout"]["cursor"]["date"]) == dates[20]
    # a click on the plot near the date of step 12: step 12, said in a line
    lay = _bench(page)["summary"]["layout"]
    x, y = x_of(lay, dates[12] + "T00:00:00") + 2, y_mid(lay)
    plot = page.find_element(By.ID, "summary-plot")
    w, h, nw, nh = page.execute_script(
        "const p = arguments[0]; return [p.clientWidth, p.clientHeight, p.naturalWidth, "
        "p.naturalHeight];", plot)
    ActionChains(page).move_to_element_with_offset(
        plot, round(x * w / nw - w / 2), round(y * h / nh - h / 2)).click().perform()
    wait_for(page, lambda s: s["settings"]["step"] == 12, "step 12 from the plot")
    note = _bench(page)["notes"][-1]
    assert "step 12" in note and "nearest report step" in note, note
    wait_for(page, lambda s: (_bench(page)["summary"] or {}).get("step") == 12, "cursor at 12")
    assert day(_bench(page)["summary"]["layout"]["cursor"]["date"]) == dates[12]
    assert page.execute_script("return document.getElementById('ctl-step').value") == "12"
    # an unknown vector: one line naming it
    _change(page, "ctl-summary", "FOPRX")
    t0 = time.monotonic()
    while not state(page)["errors"] and time.monotonic() - t0 < 120:
        time.sleep(0.2)
    line = state(page)["errors"][-1]
    assert "FOPRX" in line and "\n" not in line, line


def _model_pixels(img: np.ndarray) -> list[tuple[int, int]]:
    """Pixels of the picture that show the model, from its middle outwards."""
    ys, xs = np.nonzero(~(img[..., :3] >= 250).all(axis=-1))
    order = np.argsort((xs - img.shape[1] / 2) ** 2 + (ys - img.shape[0] / 2) ** 2)
    return [(int(xs[k]), int(ys[k])) for k in order[:: max(1, len(order) // 45)]]


def _pick(page, x: int, y: int) -> None:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    img = page.find_element(By.ID, "frame")
    w, h = page.execute_script("return [arguments[0].clientWidth, arguments[0].clientHeight]",
                               img)
    ActionChains(page).move_to_element_with_offset(img, x - w // 2, y - h // 2).click().perform()


def _table(cell: dict) -> dict:
    return {r["name"]: (r["value"], r.get("unit")) for r in cell["rows"]}


def test_picks_are_kept_tables_of_resfos_values_that_follow_the_step(page, grid):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    img = still_image(page)
    picked = []
    for x, y in _model_pixels(img):
        before = state(page)["pick"]
        _pick(page, x, y)
        p = wait_for(page, lambda s, b=before: s["pick"] != b, "this click's pick", 60)["pick"]
        if p is None or p["kind"] != "grid":
            continue
        ijk = [int(v) for v in p["index"][:3]]
        wait_for(page, lambda s, c=ijk: (_bench(page)["cells"] or [{}])[0].get("cell") == c,
                 "the tables of this pick", 60)
        if tuple(ijk) not in picked:
            picked.insert(0, tuple(ijk))
        if len(picked) == 2:
            break
    assert len(picked) == 2
    wait_for(page, lambda s: len(_bench(page)["cells"]) == 2, "two kept cells")
    for step in (5, 30):
        b = _bench(page)
        assert b["cellsStep"] == step
        for cell in b["cells"]:
            got, want = _table(cell), resfo_cell(cell["cell"], step, grid.dims, grid.active)
            assert {"PORO", "PERMX", "PRESSURE", "SWAT", "SGAS"} <= set(got)
            for name, v in want.items():
                if name in got and got[name][0] is not None:
                    assert got[name][0] == pytest.approx(v, rel=1e-5, abs=1e-6), name
            assert got["PRESSURE"][1] == "bar" and got["SWAT"][1] == "fraction"
        assert len(page.find_elements(By.CSS_SELECTOR, "#cells .cell")) == 2
        if step == 5:
            _change(page, "ctl-step", 30)
            wait_for(page, lambda s: _bench(page)["cellsStep"] == 30, "the tables at step 30")
    # a kept cell's history: its values over every step, the plot's cursor at the step
    key = ",".join(map(str, picked[0]))
    box = page.find_element(By.CSS_SELECTOR, f"#cells .cell[data-cell='{key}']")
    Select(box.find_element(By.CSS_SELECTOR, "select.cell-history")).select_by_value("PRESSURE")
    wait_for(page, lambda s: _bench(page)["history"] is not None, "the history plot")
    h = _bench(page)["history"]
    assert h["name"] == "PRESSURE" and h["cell"] == list(picked[0]) and h["step"] == 30
    assert len(h["values"]) == len(grid.step_dates) == 37
    for step in (0, 17, 36):
        want = resfo_cell(picked[0], step, grid.dims, grid.active)["PRESSURE"]
        assert h["values"][step] == pytest.approx(want, rel=1e-5)
    assert page.find_element(By.ID, "history-plot").get_attribute("naturalWidth") != "0"
    # remove the first kept cell: its history goes with it, the other stays
    box.find_element(By.CSS_SELECTOR, "button.cell-remove").click()
    wait_for(page, lambda s: len(_bench(page)["cells"]) == 1, "one kept cell")
    b = _bench(page)
    assert tuple(b["cells"][0]["cell"]) == picked[1] and b["history"] is None
    if os.environ.get("GEOSHADE_WEB_SHOTS"):   # the picture for the guide (looked at)
        _change(page, "ctl-summary", "FOPR, FPR, FWCT")
        wait_for(page, lambda s: _bench(page)["summary"] is not None, "the summary plot")
        box = page.find_element(By.CSS_SELECTOR, "#cells .cell")
        Select(box.find_element(By.CSS_SELECTOR, "select.cell-history")).select_by_value("SWAT")
        wait_for(page, lambda s: _bench(page)["history"] is not None, "the history plot")
        time.sleep(2)
        page.save_screenshot(os.path.join(os.environ["GEOSHADE_WEB_SHOTS"], "workbench.png"))


def assert_same(got: np.ndarray, want: np.ndarray, st: dict) -> None:
    assert got.shape == want.shape, (got.shape, want.shape)
    diff = np.argwhere(np.any(got != want, axis=-1))
    assert diff.size == 0, \
        f"{len(diff)} pixels differ, first at (row, col) {diff[:3].tolist()}; state {st}"


def test_ijk_and_value_range_sliders_cut_what_render_cuts(page, grid):
    s = state(page)
    _change(page, "ctl-slice-k1", 7)     # K 1..7
    s = settled_still(page, s["last"]["seq"], lambda s: str(s["settings"].get("slice"))
                      .endswith("k=0:7"))
    _change(page, "ctl-range-SWAT-lo", 500)   # SWAT from half its range
    s = settled_still(page, s["last"]["seq"], lambda s: s["settings"].get("ranges"))
    values = page.execute_script("return [document.getElementById('ctl-slice-k1').value, "
                                 "document.getElementById('ctl-range-SWAT-lo').value]")
    assert values == ["7", "500"]
    got, meta = still_with_meta(page)   # the picture and the state it was drawn with
    st = meta["state"]
    assert "SWAT" in str(st["ranges"]) and st["slice"]
    py = {k: v for k, v in st.items() if k != "camera"}
    cam = Camera.from_saved(SavedCamera.from_dict(st["camera"]))
    w, h = got.shape[1], got.shape[0]
    with geoshade.view(grid, annotations=True, **{**py, "size": [w, h]}) as v:
        want, _ = v.draw(cam)
        cut = v.options.slice
    assert (cut[2].start or 0, cut[2].stop) == (0, 7)
    assert_same(got, want, st)
    _change(page, "ctl-range-SWAT-lo", 0)
    s = settled_still(page, s["last"]["seq"], lambda s: not s["settings"].get("ranges"))
    whole = still_image(page)
    # the clip plane from the page: across x at 40 % of the box, the near side kept
    _change(page, "ctl-section-pos", 40)
    page.execute_script("document.getElementById('ctl-section').click()")
    s = settled_still(page, s["last"]["seq"], lambda s: s["settings"].get("plane"))
    assert s["settings"]["plane"] == ["x", 0.4, False]
    got, meta = still_with_meta(page)
    st = meta["state"]
    cam = Camera.from_saved(SavedCamera.from_dict(st["camera"]))
    py = {k: v for k, v in st.items() if k not in ("camera", "plane")}
    with geoshade.view(grid, annotations=True, **{**py, "size": [w, h]}) as v:
        v.update(plane=v.section_plane("x", 0.4, False))
        want, _ = v.draw(cam)
    assert_same(got, want, st)
    assert (got != whole).any(-1).mean() > 0.01   # the plane cuts the model
