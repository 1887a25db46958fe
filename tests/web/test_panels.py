"""The browser's panels: generated from the options classes (each field once), the controls the
desktop viewer has beyond them (a typed expression, a core's Otsu, ROI and occlusion, a stack
model's materials, section and drape), each change drawing what ``render`` draws with that
option, the core's histogram and porosity plots (SVG) against their data, and a change of an
option no control shows (a file option) refused."""

from __future__ import annotations

import asyncio
import io
import itertools
import json
import math
import time
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import geoshade
from geoshade.api import view_class
from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.render.camera import Camera
from geoshade.stacks import section_plane
from geoshade.styles.declare import control_type
from geoshade.styles.saved_camera import SavedCamera
from geoshade.viewer.controls import APPLIES, option_controls, settable
from geoshade.viewer.controls import controls as panel_spec
from geoshade.viewer.views import open_view, prepare
from geoshade.web.plots import histogram_bars, histogram_svg, porosity_points, porosity_svg
from tests.web.conftest import Served, need_web
from tests.web.test_server import _socket_then, settled_frame

SVG = "{http://www.w3.org/2000/svg}"


# --- generated panels ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def views():
    """A View of every part's demo data (small)."""
    out = {}
    for kind in ("core", "grid", "iso", "stacks"):
        cls = view_class(kind)
        model, options = cls.demo()
        if kind == "stacks":
            options = {**options, "drape": np.full((4, 4, 4), 200, np.uint8)}
        out[kind] = open_view(model, kind=kind, size=(32, 24), **options)
    yield out
    for v in out.values():
        v.release()


@pytest.mark.gl
@pytest.mark.parametrize("kind", ["core", "grid", "iso", "stacks"])
def test_panel_fields_once_from_the_options_class(views, kind):
    """Issue 30: the controls are the declarations': one per option that can change on an open
    View and has a control, with its declared words and default; an option fixed at opening
    (where the work runs, the GPU budget) or without a control is never one."""
    view = views[kind]
    cls = view.Options
    controls = [c for g in panel_spec(view) for c in g["controls"]]
    names = [c["name"] for c in controls]
    assert len(names) == len(set(names)), names                 # no control typed twice
    sets = [c.get("sets", c["name"]) for c in controls]
    flat = [s for x in sets for s in ([x] if isinstance(x, str) else x)]
    twice = ("select", "property", "drape")   # Otsu, an expression, the drape picker
    assert len([s for s in flat if s not in twice]) == len({s for s in flat if s not in twice})
    generated = {c["name"]: c for c in option_controls(cls)}
    for name, (opt, default) in cls.declarations().items():
        ctype = control_type(opt, default)
        if not opt.live or not ctype:
            assert name not in flat, name
            continue
        if name in generated and (name not in APPLIES or APPLIES[name](view)):
            c = next(c for c in controls if c["name"] == name)
            assert c == generated[name]                          # the declaration's words
            if name in cls.CHOICES:   # "off" first where no choice is the default
                assert c["choices"] == [None] * (default is None) + list(cls.CHOICES[name])
    # what a browser may change: options of this part (and the camera), nothing else
    assert settable(panel_spec(view)) <= set(cls.names()) | {"view", "ortho"}
    assert not settable(panel_spec(view)) & {"mask", "wells_coords", "scheduler", "logs",
                                             "distributed", "size", "camera", "gpu_memory"}


@pytest.mark.gl
def test_the_desktop_viewers_controls_are_there(views):
    def names(kind):
        return {c["name"] for g in panel_spec(views[kind]) for c in g["controls"]}

    assert {"property", "expression", "step", "filter", "slice", "edges", "faults",
            "well_xray", "colormap", "color_range", "log"} <= names("grid")
    assert {"select", "otsu", "box", "roi", "occlusion", "method", "colormap"} <= names("core")
    assert {"level", "caps", "colormap"} <= names("iso")
    assert {"materials", "section", "boreholes", "top", "legend", "drape", "drape_mix",
            "lighting"} <= names("stacks")
    mats = next(c for g in panel_spec(views["stacks"]) for c in g["controls"]
                if c["name"] == "materials")
    assert [m[0] for m in mats["items"]] == [c for c, _, _ in views["stacks"].materials()]


# --- plots ---------------------------------------------------------------------------------------
def _svg(text: str) -> ET.Element:
    return ET.fromstring(text)


@pytest.mark.gl
def test_histogram_svg_is_the_histogram(views):
    view = views["core"]
    hist = view.histogram()
    t = view.thresholds()
    root = _svg(histogram_svg(hist, select=(10000, 20000), otsu=t.otsu, multi=t.multiotsu))
    bars = [r for r in root.iter(SVG + "rect") if r.get("class") == "bar"]
    assert [int(b.get("data-bin")) for b in bars] == np.flatnonzero(hist.counts).tolist()
    c = np.log1p(hist.counts.astype(float))
    for b in bars:   # heights: log(1 + count) over the fullest bin's, to the rounding of 0.01
        want = c[int(b.get("data-bin"))] / c.max() * (70 - 4)
        assert float(b.get("height")) == pytest.approx(want, abs=0.006)
    assert [r[0] for r in histogram_bars(hist.counts)] == np.flatnonzero(hist.counts).tolist()
    sel = next(r for r in root.iter(SVG + "rect") if r.get("class") == "select")
    span = hist.edges[-1] - hist.edges[0]
    assert float(sel.get("x")) == pytest.approx((10000 - hist.edges[0]) / span * 250, abs=0.006)
    otsu = next(x for x in root.iter(SVG + "line") if x.get("class") == "otsu")
    assert float(otsu.get("x1")) == pytest.approx((t.otsu - hist.edges[0]) / span * 250,
                                                  abs=0.006)
    assert len([x for x in root.iter(SVG + "line") if x.get("class") == "multi"]) == \
        len(t.multiotsu)


def test_porosity_svg_is_the_profile():
    from geoshade.compute.voxels.porosity import porosity

    vol = synthetic_core(20)
    res = porosity(vol, 0, 12000)
    root = _svg(porosity_svg(res))
    lines = [p for p in root.iter(SVG + "polyline") if p.get("class") == "profile"]
    assert len(lines) == 1
    pts = [tuple(map(float, p.split(","))) for p in lines[0].get("points").split()]
    assert len(pts) == len(res.profile) == 20
    got, xmax = porosity_points(res)
    assert [(round(x, 2), round(y, 2)) for x, y in got[0]] == \
        [(round(x, 2), round(y, 2)) for x, y in pts]
    # the x of each point gives back the slice's porosity (left margin 34, right 8)
    back = [(x - 34) / (250 - 42) * xmax for x, _ in pts]
    assert np.allclose(back, res.profile, atol=0.01 * xmax / 208 + 1e-12)
    assert all(a > b for (_, a), (_, b) in itertools.pairwise(pts))  # z upwards
    total = next(x for x in root.iter(SVG + "line") if x.get("class") == "total")
    assert (float(total.get("x1")) - 34) / 208 * xmax == pytest.approx(res.porosity, abs=1e-4)
    texts = " ".join(t.text or "" for t in root.iter(SVG + "text"))
    assert f"total {res.porosity:.4f}" in texts and "z (" in texts


def test_porosity_svg_breaks_at_slices_without_voxels():
    """A slice with no voxel inside the ROI has no fraction (NaN): the line breaks there."""
    import dataclasses

    from geoshade.compute.voxels.porosity import porosity

    res = porosity(synthetic_core(16), 0, 12000)
    prof = np.asarray(res.profile, float).copy()
    prof[5:7] = np.nan
    lines, _ = porosity_points(dataclasses.replace(res, profile=prof))
    assert [len(x) for x in lines] == [5, 9]
    assert not any(math.isnan(v) for ln in lines for p in ln for v in p)


# --- each control draws what render draws ---------------------------------------------------------
@pytest.fixture(scope="module")
def served_panels(tmp_path_factory):
    """``serve --root DIR --drape IMAGE`` over a core, a labelled volume and a field over time
    (the drape is the stacks' only: the core opens without it)."""
    need_web()
    from PIL import Image

    d = tmp_path_factory.mktemp("panels")
    np.save(d / "core.npy", synthetic_core(24).data)
    lab = np.zeros((8, 10, 12), np.uint8)
    lab[:3], lab[3:6], lab[6:] = 1, 2, 3
    np.save(d / "labels.npy", lab)
    t = np.linspace(0, 1, 3)[:, None, None, None]
    z, y, x = np.mgrid[0:12, 0:10, 0:8] / 10.0
    np.save(d / "field.npy", (np.sin(3 * x + 2 * t) + np.cos(2 * y) + z).astype(np.float32))
    img = np.zeros((20, 24, 3), np.uint8)
    img[:, :12] = (230, 40, 40)
    img[:, 12:] = (40, 40, 230)
    Image.fromarray(img).save(d / "drape.png")
    img[:10] = (40, 200, 60)
    Image.fromarray(img).save(d / "other.png")   # a picture the drape picker lists
    s = Served(["--root", str(d), "--drape", str(d / "drape.png")])
    yield s, d
    s.stop()


#: (file, part, the page's change, the same change as render's options (None: computed))
CHANGES = [
    ("core.npy", None, {"select": "auto"}, None),
    ("core.npy", None, {"roi": "cylinder:12,12,8"}, {"roi": "cylinder:12,12,8"}),
    ("core.npy", None, {"occlusion": True}, {"occlusion": True}),
    ("labels.npy", "stacks", {"hide": [2], "opacity": {"1": 0.5}},
     {"hide": (2,), "opacity": {1: 0.5}}),
    ("labels.npy", "stacks", {"plane": ["x", 0.5, False]}, None),
    ("labels.npy", "stacks", {"drape": False}, {"drape": None}),
]


@pytest.mark.gl
@pytest.mark.parametrize(("name", "kind", "page", "options"), CHANGES,
                         ids=["otsu", "roi", "occlusion", "materials", "section", "drape"])
def test_part_controls_draw_what_render_draws(served_panels, name, kind, page, options):
    from PIL import Image

    served, d = served_panels
    got = asyncio.run(_socket_then(served, [{"t": "resize", "w": 96, "h": 72},
                                            {"t": "open", "name": f"root/{name}", "as": kind}],
                                   {"t": "set", "values": page}, settled_frame()))
    frame = got[-1]
    img = np.asarray(Image.open(io.BytesIO(frame["data"])).convert("RGBA"))
    settings = {"drape": str(d / "drape.png")} if kind == "stacks" else {}
    opening = prepare(str(d / name), kind, **settings)
    if options is None and "select" in page:
        options = {"select": "auto"}
    if options is None and "plane" in page:
        options = {"plane": section_plane(opening.model, "x", 0.5, False)}
    cam = Camera.from_saved(SavedCamera.from_dict(frame["camera"]))
    with geoshade.view(opening.model, size=(96, 72), options=opening.options, **options) as v:
        want_img, _ = v.draw(cam)
        after = v.settings()
    with geoshade.view(opening.model, size=(96, 72), options=opening.options) as v:
        before, _ = v.draw(cam)
    assert np.array_equal(img, want_img)
    assert not np.array_equal(img, before)   # the change shows
    last = next(x for x in reversed(got) if x["type"] == "settings")["settings"]
    if "select" in page:   # Otsu's selection, as the core's `--select auto` picks it
        assert tuple(last["select"]) == pytest.approx(tuple(after["select"]))
    if "plane" in page:
        assert last["plane"] == ["x", 0.5, False]
    if "hide" in page:
        assert last["hide"] == [2] and last["opacity"] == {"1": 0.5}
    if kind == "stacks" and "drape" not in page:
        assert last["drape"] is True   # the page hears on/off, never the image's path


@pytest.mark.gl
def test_the_drape_picker_drapes_a_listed_picture_and_refuses_a_path(served_panels):
    """The stacks panel lists the server's pictures by name; choosing one draws what render
    draws with it as ``--drape`` (the check box then turns that one on and off); a path, or
    a name the server does not show, is refused in one line."""
    from PIL import Image

    served, d = served_panels
    got = asyncio.run(_socket_then(served, [{"t": "resize", "w": 96, "h": 72},
                                            {"t": "open", "name": "root/labels.npy",
                                             "as": "stacks"}],
                                   {"t": "set", "values": {"drape": "root/other.png"}},
                                   settled_frame()))
    opened = next(m for m in got if m["type"] == "opened")
    picker = next(c for g in opened["panel"] for c in g["controls"] if c["name"] == "drape_file")
    assert picker["choices"] == [None, "root/drape.png", "root/other.png"]
    assert not any("/" + str(d) in str(c) for c in picker["choices"][1:])   # names, no paths
    img = np.asarray(Image.open(io.BytesIO(got[-1]["data"])).convert("RGBA"))
    opening = prepare(str(d / "labels.npy"), "stacks", drape=str(d / "other.png"))
    cam = Camera.from_saved(SavedCamera.from_dict(got[-1]["camera"]))
    with geoshade.view(opening.model, size=(96, 72), options=opening.options) as v:
        want_img, _ = v.draw(cam)
    assert np.array_equal(img, want_img)
    for bad in (str(d / "other.png"), "/etc/passwd", "root/../x.png"):
        with pytest.raises(AssertionError, match=r"is not one of the files this server shows|"
                                                 r"drape: expected one of None, root/drape\.png"):
            asyncio.run(_socket_then(   # (an error message from the server raises there)
                served, [{"t": "resize", "w": 48, "h": 36},
                         {"t": "open", "name": "root/labels.npy", "as": "stacks"}],
                {"t": "set", "values": {"drape": bad}}, lambda m: False))


@pytest.mark.gl
def test_core_plots_are_sent_with_each_change(served_panels):
    served, _ = served_panels
    seen = []

    def want(m):
        seen.append(m)
        plots = [x for x in seen if x["type"] == "plots"]
        return len(plots) >= 1 and any(x["type"] == "settings" and x["settings"].get(
            "select") == [0, 9000] and not x["busy"] for x in seen) and \
            m["type"] == "plots" and "9000" not in str(plots[0])

    got = asyncio.run(_socket_then(served, [{"t": "resize", "w": 96, "h": 72},
                                            {"t": "open", "name": "root/core.npy"}],
                                   {"t": "set", "values": {"select": [0, 9000],
                                                           "porosity": "z"}}, want))
    plots = [x for x in got if x["type"] == "plots"]
    assert plots and all("histogram" in p for p in plots)
    model = geoshade.load(served_panels[1] / "core.npy")
    from geoshade.compute.voxels.porosity import porosity

    res = porosity(model, 0, 9000)
    assert f"total {res.porosity:.4f}" in plots[-1]["porosity"]


@pytest.mark.gl
@pytest.mark.parametrize("values", [{"mask": "/etc/passwd"}, {"drape": "/etc/passwd"},
                                    {"logs": "x.csv"}])
def test_options_without_a_control_are_refused(served_panels, values):
    served, _ = served_panels
    got = asyncio.run(_socket_errors(served, values))
    errors = [m["text"] for m in got if m["type"] == "error"]
    assert errors and "is not a control of this core's panel" in errors[0], got[-1]


async def _socket_errors(served, values):
    import json

    import aiohttp

    url = served.base.replace("http://", "ws://") + f"/ws?token={served.token}"
    got = []
    async with aiohttp.ClientSession() as s, s.ws_connect(url) as ws:
        await ws.send_str(json.dumps({"t": "resize", "w": 48, "h": 36}))
        await ws.send_str(json.dumps({"t": "open", "name": "root/core.npy"}))
        sent = False
        while True:
            msg = await ws.receive(timeout=120)
            if msg.type == aiohttp.WSMsgType.BINARY:
                await ws.send_str(json.dumps({"t": "ack"}))
                if not sent:
                    await ws.send_str(json.dumps({"t": "set", "values": values}))
                    sent = True
                continue
            if msg.type != aiohttp.WSMsgType.TEXT:
                break
            got.append(json.loads(msg.data))
            if got[-1]["type"] == "error" or (sent and got[-1]["type"] == "settings"):
                break
    return got


# --- in the browser ------------------------------------------------------------------------------
@pytest.mark.gl
def test_typed_expression_in_the_browser(served, case_dir, browser):
    """Typing ``log10(PERMX)`` in the grid's expression box colours by it, as ``render``
    with ``property="log10(PERMX)"`` does."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    from tests.web.conftest import SIZE, settled_still, still_image

    browser.get(f"{served.url}&size={SIZE[0]}x{SIZE[1]}")
    s0 = settled_still(browser, 0, lambda s: s["kind"] == "grid")
    box = browser.find_element(By.ID, "ctl-expression")
    box.send_keys("log10(PERMX)", Keys.ENTER)
    s = settled_still(browser, s0["last"]["seq"],
                      lambda s: s["settings"]["property"] == "log10(PERMX)")
    got = still_image(browser)
    opening = prepare(str(case_dir["EGRID"]))
    cam = Camera.from_saved(SavedCamera.from_dict(s["still"]["camera"]))
    with geoshade.view(geoshade.load(case_dir["EGRID"]), size=SIZE,
                       options=opening.options, property="log10(PERMX)") as v:
        want, _ = v.draw(cam)
    assert np.array_equal(got, want)
    # the property list shows the expression once applied
    shown = browser.find_element(By.ID, "ctl-property").get_attribute("value")
    assert shown == '"log10(PERMX)"'


@pytest.mark.gl
def test_core_plots_and_otsu_in_the_browser(served_panels, browser):
    """A core's page shows its histogram, and its porosity profile once an axis is chosen (no
    profile is the default, as in ``render``); the Otsu button selects the pore space as
    ``--select auto`` does, and the plots follow."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    from tests.web.conftest import settled_still, wait_for

    served, d = served_panels
    browser.get(f"{served.url}&size=160x120&open=root/core.npy")
    s0 = settled_still(browser, 0, lambda s: s["kind"] == "core")
    Select(browser.find_element(By.ID, "ctl-porosity")).select_by_visible_text("z")
    s0 = wait_for(browser, lambda s: bool(browser.execute_script(
        "return window.geoshade.plots && window.geoshade.plots.porosity")), "the plots")
    svgs = browser.find_elements(By.CSS_SELECTOR, "#plots svg")
    assert [e.get_attribute("class") for e in svgs] == ["histogram", "porosity"]
    assert all(e.size["width"] == 250 and e.size["height"] > 60 for e in svgs)
    before = browser.execute_script("return window.geoshade.plots.porosity")
    browser.find_element(By.XPATH, "//button[text()='Otsu (pore space)']").click()
    with geoshade.view(geoshade.load(d / "core.npy"), size=(32, 24), select="auto") as v:
        otsu = tuple(v.settings()["select"])
    s = settled_still(browser, s0["last"]["seq"],
                      lambda s: tuple(s["settings"]["select"]) == pytest.approx(otsu))
    assert s["settings"]["select_auto"] is not None
    wait_for(browser, lambda s: browser.execute_script(
        "return window.geoshade.plots.porosity") != before, "new plots")


@pytest.fixture(scope="module")
def served_wells(tmp_path_factory):
    """``serve G.EGRID --wells wells.txt``: a vertical well through the grid's middle."""
    need_web()
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.egrid_writer import write_egrid, write_init

    d = tmp_path_factory.mktemp("wells")
    grid = synthetic_grid(10, 8, 4, seed=1)
    write_egrid(grid, d / "G.EGRID")
    write_init(grid, d / "G.INIT")
    xy = np.asarray(grid.coord).reshape(-1, 6)[:, :2]
    x, y = (xy.min(0) + xy.max(0)) / 2
    z = np.asarray(grid.zcorn)
    wells = d / "wells.txt"
    wells.write_text(f"WELL P1\n{x} {y} {float(z.min()) - 100}\n{x} {y} {float(z.max()) + 50}\n")
    s = Served([str(d / "G.EGRID"), "--wells", str(wells)])
    yield s, d / "G.EGRID", wells
    s.stop()


@pytest.mark.gl
def test_wells_given_to_serve_turn_off_and_on(served_wells):
    """The wells of ``--wells`` are the wells check box's: off draws what render draws without
    them, on again what it draws with them."""
    from PIL import Image

    from geoshade.grid.options import read_well_files as read_wells

    served, egrid, wells = served_wells
    pictures = []
    for on in (False, True):
        got = asyncio.run(_socket_then(
            served, [{"t": "resize", "w": 320, "h": 240}, {"t": "open", "name": "G.EGRID"}],
            {"t": "set", "values": {"wells": False}} if not on else
            {"t": "set", "values": {"wells": True}}, settled_frame()))
        opened = next(m for m in got if m["type"] == "opened")
        check = next(c for g in opened["panel"] for c in g["controls"] if c["name"] == "wells")
        assert check["label"] == "1 wells" and opened["settings"]["wells"]
        frame = got[-1]
        img = np.asarray(Image.open(io.BytesIO(frame["data"])).convert("RGBA"))
        opening = prepare(str(egrid), wells=read_wells(wells))
        assert len(opening.options.wells) == 1
        cam = Camera.from_saved(SavedCamera.from_dict(frame["camera"]))
        with geoshade.view(geoshade.load(egrid), size=(320, 240), options=opening.options,
                           wells=opening.options.wells if on else False) as v:
            want_img, _ = v.draw(cam)
        assert np.array_equal(img, want_img), on
        pictures.append(img)
    assert (pictures[0] != pictures[1]).any(-1).mean() > 0.001   # the well shows


@pytest.mark.gl
def test_play_the_steps_in_the_browser(served_panels, browser):
    """The step's play button shows every step in turn (each drawn before the next is asked
    for), wraps round, and pauses; the picture it rests on is ``render``'s at that step."""
    from selenium.webdriver.common.by import By

    from tests.web.conftest import settled_still, wait_for

    served, d = served_panels
    browser.get(f"{served.url}&size=96x72&open=root/field.npy")
    s0 = settled_still(browser, 0, lambda s: s["kind"] == "iso")
    assert s0["settings"]["step"] == 2            # the last, as render's default
    shown = []

    def record(s):
        if s["last"] and s["last"].get("version", 0) >= (s["version"] or 0) \
                and s["settings"]["step"] not in shown[-1:]:
            shown.append(s["settings"]["step"])
        return len(shown) >= 4

    button = browser.find_element(By.ID, "ctl-step-play")
    button.click()
    wait_for(browser, record, "four steps shown in turn")
    button.click()
    assert button.text == "▶ play"
    assert shown[:4] in ([0, 1, 2, 0], [1, 2, 0, 1], [2, 0, 1, 2])   # in turn, wrapping round
    s = settled_still(browser, 0)
    time.sleep(1.0)
    assert state_step(browser) == s["settings"]["step"]          # paused: no newer step
    got = still_image_of(browser)
    opening = prepare(str(d / "field.npy"))
    cam = Camera.from_saved(SavedCamera.from_dict(s["still"]["camera"]))
    with geoshade.view(opening.model, size=(96, 72),
                       options=opening.options, step=s["settings"]["step"],
                       level=s["settings"]["level"]) as v:
        want, _ = v.draw(cam)
    assert np.array_equal(got, want)


def state_step(browser) -> int:
    from tests.web.conftest import state

    return state(browser)["settings"]["step"]


def still_image_of(browser) -> np.ndarray:
    from tests.web.conftest import still_image

    return still_image(browser)


@pytest.mark.gl
def test_load_camera_in_the_browser(served, case_dir, browser, tmp_path):
    """**load camera** reads a camera file (what ``--camera FILE`` reads): the page's picture is
    ``render``'s with that camera, and the frame says it was drawn with it."""
    from selenium.webdriver.common.by import By

    from tests.web.conftest import SIZE, settled_still, still_image

    browser.get(f"{served.url}&size={SIZE[0]}x{SIZE[1]}")
    s0 = settled_still(browser, 0, lambda s: s["kind"] == "grid")
    cam = Camera.from_saved(SavedCamera.from_dict(s0["still"]["camera"])).orbit(75, 20)
    path = tmp_path / "camera.json"
    path.write_text(cam.saved().to_json())
    box = browser.find_element(By.ID, "load-camera")
    browser.execute_script("arguments[0].hidden = false;", box)
    box.send_keys(str(path))
    want_cam = json.loads(path.read_text())
    s = settled_still(browser, s0["last"]["seq"], lambda s: s["still"]["camera"] == want_cam)
    got = still_image(browser)
    opening = prepare(str(case_dir["EGRID"]))
    with geoshade.view(geoshade.load(case_dir["EGRID"]), size=SIZE,
                       options=opening.options, camera=str(path)) as v:
        want, _ = v.draw()
    assert np.array_equal(got, want)
    assert s["still"]["camera"]["azimuth"] != s0["still"]["camera"]["azimuth"]
