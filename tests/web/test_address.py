"""Views shared by address (issue 33 item 4): the page's address carries the file, its part and
the View's state (``view.state(camera)``) and follows the user; the address opened in a fresh
tab shows the same picture pixel for pixel; a state the tab cannot take is one line naming the
field, and the file shows as it opens."""

from __future__ import annotations

import json
import time
from urllib.parse import urlsplit

import numpy as np
import pytest

import geoshade
from geoshade.errors import InputError
from geoshade.render.camera import Camera
from geoshade.styles.saved_camera import SavedCamera
from geoshade.viewer.controls import controls
from geoshade.viewer.views import open_view
from geoshade.web.address import decode, encode, restore
from geoshade.web.messages import check_control, parse
from tests.web.conftest import SIZE, WAIT_S, settled_still, state, still_image


# --- no browser ---------------------------------------------------------------------------------
def test_the_address_round_trips_and_refuses_what_it_cannot_read():
    view = {"file": "case/Ä.EGRID", "as": "grid", "state": {"colormap": "magma", "step": 2}}
    text = encode(view)
    assert set(text) <= set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_")
    assert decode(text) == view
    for bad in ("%%%", encode([1, 2]).rstrip(), "AAAA"):
        with pytest.raises(InputError, match="the view in the address") as e:
            decode(bad)
        assert "\n" not in str(e.value)


@pytest.mark.parametrize(("message", "match"), [
    ({"t": "open", "name": "a", "state": [1]}, r"open: state: expected \{option: value\}"),
    ({"t": "open", "name": "a", "state": {str(i): 1 for i in range(200)}}, "at most 128"),
    ({"t": "open", "name": "a", "state": {"x" * 65: 1}}, "at most 64 characters"),
    ({"t": "unpick", "cell": [1, 2]}, r"unpick: cell: expected a cell \[i, j, k\]"),
    ({"t": "unpick", "cell": [1, 2, -1]}, "expected a cell"),
    ({"t": "unpick", "cell": [1, 2, True]}, "expected a cell"),
    ({"t": "history", "cell": None}, "history: name is missing"),
    ({"t": "history", "cell": [0, 0, 0], "name": "x" * 65}, "at most 64"),
    ({"t": "plot_size", "w": 10, "h": 200}, "plot_size: w: expected an integer 120..2048"),
    ({"t": "plot_size", "w": 300, "h": 1e9}, "plot_size: h: expected an integer 120..2048"),
])
def test_a_bad_address_or_workbench_message_is_one_line(message, match):
    with pytest.raises(InputError, match=match) as e:
        parse(json.dumps(message))
    assert "\n" not in str(e.value)


@pytest.mark.parametrize(("spec", "value", "match"), [
    ({"type": "ijk", "dims": [4, 3, 2]}, [[0, 5], [0, 3], [0, 2]], "I to: expected an integer 1..4"
     ),
    ({"type": "ijk", "dims": [4, 3, 2]}, [[2, 2], [0, 3], [0, 2]], "I to: expected an integer 3..4"
     ),
    ({"type": "ijk", "dims": [4, 3, 2]}, "k=0:1", r"expected \[\[i0, i1\]"),
    ({"type": "ranges", "items": [["SWAT", 0, 1]]}, {"PORO": [0, 1]}, "'PORO' is no property"),
    ({"type": "ranges", "items": [["SWAT", 0, 1]]}, {"SWAT": [0.5, 0.2]}, "SWAT high: expected"),
    ({"type": "ranges", "items": [["SWAT", 0, 1]]}, {"SWAT": [0, "1"]}, "SWAT high: expected"),
    ({"type": "vectors", "choices": ["FOPR"]}, ["FOPR"] * 17, "at most 16 vector names"),
    ({"type": "vectors", "choices": ["FOPR"]}, "FOPR", "at most 16 vector names"),
])
def test_a_bad_slider_or_vector_value_is_one_line(spec, value, match):
    with pytest.raises(InputError, match=match) as e:
        check_control({"name": "x", **spec}, "x", value)
    assert "\n" not in str(e.value)


def test_good_slider_and_vector_values_are_taken():
    assert check_control({"type": "ijk", "dims": [4, 3, 2]}, "slice",
                         [[1, 4], [0, 3], [1, 2]]) == [[1, 4], [0, 3], [1, 2]]
    assert check_control({"type": "ranges", "items": [["SWAT", 0, 1]]}, "ranges",
                         {"SWAT": [0.2, 0.2]}) == {"SWAT": [0.2, 0.2]}
    assert check_control({"type": "vectors", "choices": []}, "summary", ["WOPR:*"]) == ["WOPR:*"]


def test_good_address_and_workbench_messages_are_taken():
    for m in ({"t": "open", "name": "a", "state": {"colormap": "magma"}},
              {"t": "open", "name": "a", "state": None}, {"t": "unpick", "cell": [1, 2, 3]},
              {"t": "history", "cell": [0, 1, 2], "name": "SWAT"},
              {"t": "history", "cell": None, "name": None}, {"t": "plot_size", "w": 300, "h": 200},
              {"t": "timeline", "x": 12.5, "y": 40}):
        assert parse(json.dumps(m)) == m


@pytest.mark.gl
def test_a_state_changes_only_what_the_panel_changes(case_dir):
    """The state of a View reopens it (panel options, the camera) and names no file; what no
    control changes must be as the server opens it; the wells turn off and on by their box."""
    with open_view(str(case_dir["EGRID"]), size=(64, 48)) as v:
        panel = controls(v)
        cam = v.camera("top").orbit(20, 5)
        v.update(property="SWAT", colormap="magma", step=0, faults="hide")
        r = restore(v.state(cam), v, panel)
        assert r.changes == {} and r.camera is not None   # this View is already that state
        assert r.camera.saved().as_dict() == cam.saved().as_dict()
    with open_view(str(case_dir["EGRID"]), size=(64, 48)) as fresh:
        r = restore({**v.state(cam), "size": [9, 9]}, fresh, controls(fresh))
        assert r.changes == {"property": "SWAT", "colormap": "magma", "step": 0,
                             "faults": "hide"}
        for bad, match in [({"scheduler": "local:2"}, "scheduler is not part of a view"),
                           ({"mask": "/etc/passwd"}, "'mask' is no option of a grid"),
                           ({"medium": "fracture"}, "medium is fixed by the server"),
                           ({"wells_coords": "map"}, "wells_coords is fixed by the server"),
                           ({"camera": {"geoshade_camera": 1}}, "camera: camera: .* missing"),
                           ({"view": "sideways"}, "unknown view 'sideways'"),
                           ({"Property": "SWAT"}, "'Property' is no option of a grid view")]:
            with pytest.raises(InputError, match=match):
                restore(bad, fresh, controls(fresh))
        assert restore({"view": "top", "zoom": 2}, fresh, controls(fresh)).spec.zoom == 2


# --- in the browser -----------------------------------------------------------------------------
def _address(driver) -> dict:
    frag = urlsplit(driver.current_url).fragment
    assert frag.startswith("view="), driver.current_url
    return decode(frag[len("view="):])


def _drag(driver, dx: int, dy: int) -> None:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    img = driver.find_element(By.ID, "frame")
    chain = ActionChains(driver).move_to_element(img).click_and_hold()
    for _ in range(4):
        chain = chain.move_by_offset(dx // 4, dy // 4).pause(0.05)
    chain.release().perform()


def _in_new_tab(driver, url: str, test=lambda s: True):
    """Open ``url`` in a new tab of the same browser (its cookie, no token); its settled
    lossless frame, its state and the picture."""
    driver.switch_to.new_window("tab")
    driver.get(url)
    s = settled_still(driver, 0, lambda s: s["kind"] == "grid" and test(s))
    return s, still_image(driver)


def _line(driver, what: str, timeout: float = WAIT_S) -> str:
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        s = state(driver)
        if s["errors"]:
            return s["errors"][-1]
        time.sleep(0.2)
    raise AssertionError(f"waited for {what}")


@pytest.mark.gl
def test_a_turned_and_recoloured_view_opens_the_same_in_a_fresh_tab(served, browser, case_dir):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    first = browser.current_window_handle
    browser.switch_to.new_window("tab")
    try:
        browser.get(f"{served.url}&size={SIZE[0]}x{SIZE[1]}")
        s = settled_still(browser, 0, lambda s: s["kind"] == "grid")
        assert _address(browser)["state"] == s["still"]["state"]   # the first frame's state
        assert "token" not in browser.current_url
        _drag(browser, 48, -16)
        s = settled_still(browser, s["last"]["seq"], lambda s: s["still"]["camera"]["azimuth"]
                          != 45.0)
        Select(browser.find_element(By.ID, "ctl-property")).select_by_visible_text("SWAT")
        s = settled_still(browser, s["last"]["seq"], lambda s: s["settings"]["property"] ==
                          "SWAT")
        Select(browser.find_element(By.ID, "ctl-colormap")).select_by_visible_text("magma")
        s = settled_still(browser, s["last"]["seq"], lambda s: s["settings"]["color"][
            "colormap"] == "magma")
        want = still_image(browser)
        view = _address(browser)
        assert view["file"] == case_dir["EGRID"].name and view["as"] == "grid"
        st = view["state"]
        assert st["property"] == "SWAT" and st["colormap"] == "magma"
        assert st["camera"] == s["still"]["camera"]
        assert not any("/" in json.dumps(v) for v in st.values())   # no server path
        url = browser.current_url
        assert "token" not in url
        # the same picture from Python: geoshade.view(model, **state) (annotations: the tests'
        # default is the bare render, the server's the annotated one)
        py = {k: v for k, v in st.items() if k != "camera"}
        cam = Camera.from_saved(SavedCamera.from_dict(st["camera"]))
        with geoshade.view(geoshade.load(case_dir["EGRID"]), annotations=True, **py) as v:
            assert np.array_equal(v.draw(cam)[0], want)
        second = browser.current_window_handle
        s2, got = _in_new_tab(browser, url, lambda s: s["settings"]["property"] == "SWAT")
        try:
            assert s2["settings"]["color"]["colormap"] == "magma"
            assert s2["still"]["camera"] == s["still"]["camera"]
            assert s2["reads"] == s["reads"]   # the view's file was read once, for both tabs
            diff = np.argwhere(np.any(got != want, axis=-1))
            assert diff.size == 0, f"{len(diff)} pixels differ, first {diff[:3].tolist()}"
            assert _address(browser) == view   # the new tab's address is the same view
        finally:
            browser.close()
            browser.switch_to.window(second)
    finally:
        browser.close()
        browser.switch_to.window(first)


@pytest.mark.gl
@pytest.mark.parametrize(("bad", "says"), [
    ({"banana": 1}, "'banana' is no option of a grid view"),
    ({"colormap": "no-such-map"}, "colormap"),
    ({"wells": ["/etc/passwd"]}, "wells is fixed by the server"),
])
def test_a_state_the_tab_cannot_take_is_one_line_and_the_file_opens(served, browser, case_dir,
                                                                    bad, says):
    base = f"{served.base}/?token={served.token}&size={SIZE[0]}x{SIZE[1]}"
    first = browser.current_window_handle
    browser.switch_to.new_window("tab")
    try:
        browser.get(base)   # the cookie; then the address alone
        settled_still(browser, 0, lambda s: s["kind"] == "grid")
        plain = still_image(browser)
        path = urlsplit(browser.current_url)
        view = {"file": case_dir["EGRID"].name, "as": "grid", "state": bad}
        browser.get("about:blank")   # (the same address but its fragment would not load)
        browser.get(f"{path.scheme}://{path.netloc}{path.path}?{path.query}#view="
                    f"{encode(view)}")
        line = _line(browser, "the refused state's line")
        assert line.startswith("the view in the address") and says in line, line
        assert "\n" not in line and "Traceback" not in line
        s = state(browser)
        t0 = time.monotonic()
        while not (s["still"] and s["last"]["still"]) and time.monotonic() - t0 < WAIT_S:
            time.sleep(0.2)
            s = state(browser)
        time.sleep(1.5)
        print(browser.get_log("browser"))
        assert state(browser)["settings"]["property"] == "PORO"   # as it opens
        assert np.array_equal(still_image(browser), plain)
    finally:
        browser.close()
        browser.switch_to.window(first)


@pytest.mark.gl
def test_an_unreadable_address_is_one_line(served, browser):
    first = browser.current_window_handle
    browser.switch_to.new_window("tab")
    try:
        browser.get(f"{served.url}&size={SIZE[0]}x{SIZE[1]}#view=%25%25not-base64")
        line = _line(browser, "the unreadable address's line")
        assert line.startswith("the view in the address: not readable"), line
    finally:
        browser.close()
        browser.switch_to.window(first)
