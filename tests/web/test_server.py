"""``geoshade serve`` without a browser: the token, the origin check, the catalogue of files,
the websocket's first frame, and a closed tab's View released."""

from __future__ import annotations

import asyncio
import json
import os
import re
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.web.catalog import Catalog
from tests.web.conftest import WAIT_S, need_web


async def _get(url: str, **kw):
    import aiohttp

    async with aiohttp.ClientSession() as s, s.get(url, **kw) as r:
        return r.status, await r.text(), dict(r.headers)


def get(url: str, **kw):
    return asyncio.run(_get(url, **kw))


def test_listens_on_this_machine_only(served):
    assert served.base.startswith("http://127.0.0.1:")
    assert len(served.token) >= 30


def test_token_required(served):
    assert get(served.base + "/")[0] == 403
    wrong = served.token[:-1] + ("y" if served.token.endswith("x") else "x")
    assert get(served.base + "/?token=" + wrong)[0] == 403
    assert get(served.base + "/static/app.js")[0] == 403
    status, text, headers = get(served.url)
    assert status == 200 and "<title>geoshade</title>" in text
    # the page lives under a path of its own, where the browser keeps a cookie (not the token)
    port = served.base.rsplit(":", 1)[1]
    cookie = re.fullmatch(rf"geoshade_{port}=([\w-]+); HttpOnly; Path=(/s/[\w-]+/); "
                          "SameSite=Strict", headers["Set-Cookie"])
    assert cookie and served.token not in headers["Set-Cookie"], headers["Set-Cookie"]
    value, path = cookie.groups()
    assert f'<base href="{path}">' in text
    cookies = {f"geoshade_{port}": value}
    assert get(served.base + path + "static/app.js", cookies=cookies)[0] == 200
    assert get(served.base + path + "static/app.js")[0] == 403
    assert get(served.base + path + "static/app.js", cookies={"geoshade_1": value})[0] == 403
    for name in ("index.html", "..%2F..%2Fpyproject.toml", "%2Fetc%2Fpasswd"):
        assert get(f"{served.base}{path}static/{name}", cookies=cookies)[0] == 404


async def _socket(served, messages, origin=None, want=lambda m: False, token=True):
    import aiohttp

    url = served.base.replace("http://", "ws://") + "/ws" + (f"?token={served.token}"
                                                               if token else "")
    headers = {"Origin": origin} if origin else {}
    got = []
    async with aiohttp.ClientSession() as s, s.ws_connect(url, headers=headers) as ws:
        for m in messages:
            await ws.send_str(json.dumps(m))
        t0 = time.monotonic()
        while time.monotonic() - t0 < WAIT_S:
            msg = await ws.receive(timeout=WAIT_S)
            if msg.type == aiohttp.WSMsgType.TEXT:
                got.append(json.loads(msg.data))
            elif msg.type == aiohttp.WSMsgType.BINARY:
                got[-1]["data"] = msg.data
                if got[-1]["type"] == "frame":
                    await ws.send_str(json.dumps({"t": "ack"}))
            else:
                break
            if want(got[-1]) and (got[-1]["type"] != "frame" or "data" in got[-1]):
                break
    return got


def test_socket_needs_token_and_same_origin(served):
    import aiohttp

    with pytest.raises(aiohttp.WSServerHandshakeError) as e:
        asyncio.run(_socket(served, [], token=False))
    assert e.value.status == 403
    with pytest.raises(aiohttp.WSServerHandshakeError) as e:
        asyncio.run(_socket(served, [], origin="http://evil.example"))
    assert e.value.status == 403


@pytest.mark.parametrize("name", ["../../etc/passwd", "/etc/passwd", "root/../x",
                                  "BIG.INIT"])
def test_browser_names_only_listed_files(served, name):
    got = asyncio.run(_socket(served, [{"t": "open", "name": name}],
                              want=lambda m: m["type"] == "error"))
    assert got[0]["type"] == "hello" and got[0]["files"] == ["BIG.EGRID"]
    assert got[-1]["type"] == "error" and "not one of the files" in got[-1]["text"]


@pytest.mark.gl
def test_socket_streams_render(served, case_dir):
    """Without a browser: the websocket's first lossless frame is ``render``'s picture."""
    import io

    from PIL import Image

    import geoshade
    from geoshade.render.camera import Camera
    from geoshade.styles.saved_camera import SavedCamera
    from geoshade.viewer.views import prepare

    got = asyncio.run(_socket(served, [{"t": "resize", "w": 96, "h": 72},
                                       {"t": "open", "name": "BIG.EGRID"}],
                              want=lambda m: m["type"] == "frame" and m["still"]))
    frame = got[-1]
    assert frame["mime"] == "image/png" and (frame["width"], frame["height"]) == (96, 72)
    img = np.asarray(Image.open(io.BytesIO(frame["data"])).convert("RGBA"))
    opening = prepare(str(case_dir["EGRID"]))
    cam = Camera.from_saved(SavedCamera.from_dict(frame["camera"]))
    with geoshade.view(geoshade.load(case_dir["EGRID"]), size=(96, 72),
                       options=opening.options) as v:
        want, _ = v.draw(cam)
    assert np.array_equal(img, want)


# --- the catalogue (no server) --------------------------------------------------------------
def test_catalog_names_and_root(tmp_path):
    (tmp_path / "a.npy").write_bytes(b"")
    root = tmp_path / "data"
    (root / "sub").mkdir(parents=True)
    (root / "sub" / "c.EGRID").write_bytes(b"")
    (root / "notes.txt").write_text("x")
    (root / ".hidden").mkdir()
    (root / ".hidden" / "d.npy").write_bytes(b"")
    outside = tmp_path / "secret.npy"
    outside.write_bytes(b"")
    os.symlink(outside, root / "link.npy")
    cat = Catalog([tmp_path / "a.npy"], root=root)
    assert cat.names() == ["a.npy", "root/sub/c.EGRID"]   # the link leaves the root
    assert cat.path("root/sub/c.EGRID") == (root / "sub" / "c.EGRID").resolve()
    for bad in ("root/../secret.npy", "root//etc/passwd", "root/link.npy", "root/",
                "secret.npy", str(outside), "root/sub/../../secret.npy", "root/missing.npy"):
        with pytest.raises(InputError, match="not one of the files"):
            cat.path(bad)


def test_catalog_refuses_missing(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        Catalog([tmp_path / "nope.EGRID"])
    with pytest.raises(InputError, match="not a folder"):
        Catalog([], root=tmp_path / "nope")
    with pytest.raises(InputError, match="at least one file"):
        Catalog([])
    (tmp_path / "x").mkdir()
    (tmp_path / "y").mkdir()
    for d in ("x", "y"):
        (tmp_path / d / "A.EGRID").write_bytes(b"")
    assert Catalog([tmp_path / "x" / "A.EGRID", tmp_path / "y" / "A.EGRID"]).names() == \
        ["A.EGRID", "A.EGRID (2)"]


def test_catalog_lists_the_demos_first(tmp_path):
    (tmp_path / "a.npy").write_bytes(b"")
    cat = Catalog([tmp_path / "a.npy"], demo="grid")
    assert cat.names() == ["demo/grid", "demo/core", "demo/iso", "demo/stacks", "a.npy"]
    assert cat.demo_kind("demo/iso") == "iso" and cat.demo_kind("a.npy") is None
    cat.check("demo/stacks")
    cat.check("a.npy")
    assert Catalog([], demo=True).names()[0] == "demo/core"
    for bad in ("demo/banana", "demo/"):
        with pytest.raises(InputError, match="not one of the files"):
            cat.check(bad)
    with pytest.raises(InputError, match="not one of the files"):
        Catalog([tmp_path / "a.npy"]).check("demo/core")     # not listed without --demo
    with pytest.raises(InputError, match="--demo: unknown part 'banana'; expected one of core"):
        Catalog([], demo="banana")


@pytest.fixture(scope="module")
def served_demo():
    need_web()
    from tests.web.conftest import Served

    s = Served(["--demo", "grid"])
    yield s
    s.stop()


@pytest.mark.gl
@pytest.mark.parametrize("part", ["grid", "core", "iso", "stacks"])
def test_serve_demo_streams_what_the_demo_renders(served_demo, part):
    """``geoshade serve --demo grid``: no file needed; the page lists every part's demo (grid
    first) and each streams the picture of that part's demo View (its demo options)."""
    import io

    from PIL import Image

    import geoshade
    from geoshade.render.camera import Camera
    from geoshade.styles.saved_camera import SavedCamera
    from geoshade.viewer.views import view_class

    got = asyncio.run(_socket(served_demo, [{"t": "resize", "w": 96, "h": 72},
                                            {"t": "open", "name": f"demo/{part}"}],
                              want=lambda m: m["type"] in ("frame", "error")
                              and m.get("still", True)))
    assert got[0]["files"] == ["demo/grid", "demo/core", "demo/iso", "demo/stacks"]
    opened = next(m for m in got if m["type"] == "opened")
    assert opened["kind"] == part and opened["name"] == f"demo/{part}"
    frame = got[-1]
    assert frame["type"] == "frame", frame
    img = np.asarray(Image.open(io.BytesIO(frame["data"])).convert("RGBA"))
    model, options = view_class(part).demo()
    cam = Camera.from_saved(SavedCamera.from_dict(frame["camera"]))
    with geoshade.view(model, size=(96, 72), **options) as v:
        want, _ = v.draw(cam)
    assert np.array_equal(img, want)


@pytest.mark.gl
def test_closed_tab_releases_its_view(case_dir):
    """A tab's View lives on the GL thread; closing the tab releases its GPU objects."""
    need_web()
    from geoshade.web.engine import GLThread, Library, Tab

    lib = Library(Catalog([case_dir["EGRID"]]))
    gl, pool = GLThread(), ThreadPoolExecutor(1)
    frames, done = [], threading.Event()

    def send(msg, data):
        if msg["type"] == "frame":
            frames.append(msg)
            done.set()
        if msg["type"] == "error":
            frames.append(msg)
            done.set()

    try:
        tabs = [Tab(lib, gl, pool, send, lambda s, fn: None, size=(64, 48)) for _ in range(2)]
        for t in tabs:
            done.clear()
            t.open("BIG.EGRID")
            assert done.wait(WAIT_S)
            assert frames[-1]["type"] == "frame", frames[-1]
        assert lib.reads == 1   # two tabs, one read
        a, b = (t.session.view for t in tabs)
        assert a is not b and a.model is b.model   # own Views, one model
        tabs[0].close().result(WAIT_S)
        assert a.released and not b.released
    finally:
        for t in tabs:
            t.close().result(WAIT_S)
        pool.shutdown()
        gl.stop()


@pytest.fixture(scope="module")
def served_root(tmp_path_factory):
    """``geoshade serve --root DIR`` over a core, a field over time and a labelled volume."""
    need_web()
    from geoshade.compute.voxels.synthetic import synthetic_core
    from tests.web.conftest import Served

    d = tmp_path_factory.mktemp("root")
    np.save(d / "core.npy", synthetic_core(24).data)
    t = np.linspace(0, 1, 3)[:, None, None, None]
    z, y, x = np.mgrid[0:12, 0:10, 0:8] / 10.0
    np.save(d / "field.npy", (np.sin(3 * x + 2 * t) + np.cos(2 * y) + z).astype(np.float32))
    lab = np.zeros((8, 10, 12), np.uint8)
    lab[:3], lab[3:6], lab[6:] = 1, 2, 3
    np.save(d / "labels.npy", lab)
    s = Served(["--root", str(d)])
    yield s, d
    s.stop()


@pytest.mark.gl
@pytest.mark.parametrize(("name", "kind", "part"), [("core.npy", None, "core"),
                                                     ("field.npy", None, "iso"),
                                                     ("labels.npy", "stacks", "stacks")])
def test_every_part_streams_render(served_root, name, kind, part):
    """A core, an isosurface and stacks open from ``--root``; the first lossless frame is
    ``render``'s picture with the options the page opened with."""
    import io

    from PIL import Image

    import geoshade
    from geoshade.render.camera import Camera
    from geoshade.styles.saved_camera import SavedCamera
    from geoshade.viewer.views import prepare

    served, d = served_root
    got = asyncio.run(_socket(served, [{"t": "resize", "w": 96, "h": 72},
                                       {"t": "open", "name": f"root/{name}", "as": kind}],
                              want=lambda m: m["type"] in ("frame", "error")
                              and m.get("still", True)))
    assert got[0]["files"] == ["root/core.npy", "root/field.npy", "root/labels.npy"]
    opened = next(m for m in got if m["type"] == "opened")
    assert opened["kind"] == part
    names = [c["name"] for g in opened["panel"] for c in g["controls"]]
    assert {"view", "ortho", "annotations"} <= set(names)
    frame = got[-1]
    assert frame["type"] == "frame", frame
    img = np.asarray(Image.open(io.BytesIO(frame["data"])).convert("RGBA"))
    opening = prepare(str(d / name), kind)
    cam = Camera.from_saved(SavedCamera.from_dict(frame["camera"]))
    with geoshade.view(opening.model, size=(96, 72), options=opening.options) as v:
        want, _ = v.draw(cam)
    assert np.array_equal(img, want)


@pytest.mark.gl
def test_long_change_reports_progress_then_streams_render(served_root):
    """A core's new selection is a long change: its CPU half runs on a worker (the page hears
    its label), then the lossless frame equals ``render`` with that selection."""
    import io

    from PIL import Image

    import geoshade
    from geoshade.render.camera import Camera
    from geoshade.styles.saved_camera import SavedCamera
    from geoshade.viewer.views import prepare

    served, d = served_root
    seen = []

    def want(m):
        seen.append(m)
        applied = any(x["type"] == "settings" and x["settings"].get("select") == [0, 9000]
                      and not x["busy"] for x in seen)
        return applied and m["type"] == "frame" and m["still"]

    msgs = [{"t": "resize", "w": 96, "h": 72}, {"t": "open", "name": "root/core.npy"}]
    got = asyncio.run(_socket_then(served, msgs, {"t": "set", "values": {"select": [0, 9000]}},
                                   want))
    busy = [x for x in got if x["type"] == "settings" and x["busy"]]
    assert busy and busy[0]["busy"][0]   # the job's label, shown while it runs
    frame = got[-1]
    img = np.asarray(Image.open(io.BytesIO(frame["data"])).convert("RGBA"))
    opening = prepare(str(d / "core.npy"))
    cam = Camera.from_saved(SavedCamera.from_dict(frame["camera"]))
    with geoshade.view(opening.model, size=(96, 72), options=opening.options,
                       select=(0, 9000)) as v:
        want_img, _ = v.draw(cam)
    assert np.array_equal(img, want_img)


def settled_frame():
    """A ``want`` for :func:`_socket_then`: the first lossless frame after the change was
    applied (a settings message with nothing busy)."""
    seen: list = []

    def want(m) -> bool:
        seen.append(m)
        applied = any(x["type"] == "settings" and not x["busy"] for x in seen)
        return applied and m["type"] == "frame" and m["still"]

    return want


async def _socket_then(served, first, then, want):
    """Send ``first``; once the first lossless frame came, send ``then``; until ``want``."""
    import aiohttp

    url = served.base.replace("http://", "ws://") + f"/ws?token={served.token}"
    got, sent = [], False
    async with aiohttp.ClientSession() as s, s.ws_connect(url) as ws:
        for m in first:
            await ws.send_str(json.dumps(m))
        t0 = time.monotonic()
        while time.monotonic() - t0 < WAIT_S:
            msg = await ws.receive(timeout=WAIT_S)
            if msg.type == aiohttp.WSMsgType.TEXT:
                got.append(json.loads(msg.data))
                if got[-1]["type"] == "error":
                    raise AssertionError(got[-1]["text"])
                if got[-1]["type"] != "frame" and sent and want(got[-1]):
                    break
                continue
            if msg.type != aiohttp.WSMsgType.BINARY:
                break
            got[-1]["data"] = msg.data
            await ws.send_str(json.dumps({"t": "ack"}))
            if not sent and got[-1]["still"]:
                await ws.send_str(json.dumps(then))
                sent = True
            elif sent and want(got[-1]):
                break
    return got


#: a panel's change as the page sends it -> the same change as ``render``'s options
GRID_CHANGES = [
    ({"filter": "PORO > 0.2"}, {"filter": "PORO > 0.2"}),
    ({"slice": [[0, 4], [1, 6], [0, 2]]}, {"slice": "i=0:4,j=1:6,k=0:2"}),   # the I/J/K sliders
    ({"faults": "hide", "edges": "quad"}, {"faults": "hide", "edges": "quad"}),
    ({"colormap": "magma", "color_range": [0.1, 0.25], "reverse": True},
     {"colormap": "magma", "color_range": (0.1, 0.25), "reverse": True}),
    # (the case's PERMX is an exponential of its PORO: on a log scale it draws as PORO does)
    ({"property": "PERMX", "log": False}, {"property": "PERMX", "log": False}),
    ({"property": "SWAT", "step": 1, "log": "auto"}, {"property": "SWAT", "step": 1}),
    ({"view": "top", "ortho": True}, {}),
    ({"exaggeration": 3}, {"exaggeration": 3.0}),
]


@pytest.mark.gl
@pytest.mark.parametrize(("page", "options"), GRID_CHANGES,
                         ids=["filter", "slice", "faults-edges", "colour", "log", "step",
                              "top-ortho", "exaggeration"])
def test_panel_changes_draw_what_render_draws(served, case_dir, page, options):
    import io

    from PIL import Image

    import geoshade
    from geoshade.render.camera import Camera
    from geoshade.styles.saved_camera import SavedCamera
    from geoshade.viewer.views import prepare

    got = asyncio.run(_socket_then(served, [{"t": "resize", "w": 96, "h": 72},
                                            {"t": "open", "name": "BIG.EGRID"}],
                                   {"t": "set", "values": page}, settled_frame()))
    frame = got[-1]
    img = np.asarray(Image.open(io.BytesIO(frame["data"])).convert("RGBA"))
    opening = prepare(str(case_dir["EGRID"]))
    cam = Camera.from_saved(SavedCamera.from_dict(frame["camera"]))
    with geoshade.view(geoshade.load(case_dir["EGRID"]), size=(96, 72),
                       options=opening.options, **options) as v:
        want_img, _ = v.draw(cam)
    assert np.array_equal(img, want_img)
    if options:   # the change shows: the picture without it differs
        with geoshade.view(geoshade.load(case_dir["EGRID"]), size=(96, 72),
                           options=opening.options) as v:
            before, _ = v.draw(cam)
        assert not np.array_equal(img, before)
    if "view" in page:
        assert cam.elevation == pytest.approx(90, abs=1) and cam.ortho


@pytest.fixture(scope="module")
def served_real(shared_data):
    """``geoshade serve`` over real data: a micro-CT TIFF and the Reek case (EGRID, UNRST)."""
    need_web()
    from tests.web.conftest import Served

    files = [shared_data / "microct_spam_snow" / "snow.tif",
             shared_data / "reek_cornerpoint" / "opm_flow_run" / "2_R001_REEK-0.EGRID"]
    for f in files:
        if not f.exists():
            pytest.skip(f"{f} is absent (see shared/data/README.md)")
    s = Served([str(f) for f in files])
    yield s, files
    s.stop()


@pytest.mark.gl
@pytest.mark.parametrize(("index", "kind", "part"), [(0, None, "core"), (1, None, "grid"),
                                                     (1, "iso", "iso")])
def test_real_data_streams_render(served_real, index, kind, part):
    """Real files as they ship: the first lossless frame is ``render``'s picture."""
    import io

    from PIL import Image

    import geoshade
    from geoshade.render.camera import Camera
    from geoshade.styles.saved_camera import SavedCamera
    from geoshade.viewer.views import prepare

    served, files = served_real
    got = asyncio.run(_socket(served, [{"t": "resize", "w": 96, "h": 72},
                                       {"t": "open", "name": files[index].name, "as": kind}],
                              want=lambda m: m["type"] in ("frame", "error")
                              and m.get("still", True)))
    assert next(m for m in got if m["type"] == "opened")["kind"] == part
    frame = got[-1]
    assert frame["type"] == "frame", frame
    img = np.asarray(Image.open(io.BytesIO(frame["data"])).convert("RGBA"))
    opening = prepare(str(files[index]), kind)
    cam = Camera.from_saved(SavedCamera.from_dict(frame["camera"]))
    with geoshade.view(opening.model, size=(96, 72), options=opening.options) as v:
        want, _ = v.draw(cam)
    assert np.array_equal(img, want)


@pytest.mark.gl
def test_progressive_grid_streams_the_preview_then_render(tmp_path, monkeypatch):
    """``serve --progressive``: a tab shows the coarse preview at once, the full picture is
    built on a worker (its label on the page) and the still after it is ``render``'s."""
    need_web()
    import io

    from PIL import Image

    import geoshade
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.grid import lod as lod_mod
    from geoshade.grid.view import GridView
    from geoshade.io.grids.egrid_writer import write_egrid, write_init
    from geoshade.render.camera import Camera
    from geoshade.styles.saved_camera import SavedCamera
    from geoshade.viewer.views import prepare
    from geoshade.web.engine import GLThread, Library, Tab

    monkeypatch.setattr(lod_mod, "PREVIEW_CELLS", 2000)   # a preview for this small grid
    # the full picture's work waits for the preview's frame (on a fast machine it could be
    # done before the first frame is drawn, and the preview never shown)
    first_frame = threading.Event()
    refine = GridView._refine_faces

    def refine_after_the_preview(self, *a, **kw):
        first_frame.wait(WAIT_S)
        return refine(self, *a, **kw)

    monkeypatch.setattr(GridView, "_refine_faces", refine_after_the_preview)
    grid = synthetic_grid(24, 16, 8, seed=3)
    write_egrid(grid, tmp_path / "G.EGRID")
    write_init(grid, tmp_path / "G.INIT")
    lib = Library(Catalog([tmp_path / "G.EGRID"]), {"progressive": True, "select": (0, 1)})
    gl, pool = GLThread(), ThreadPoolExecutor(2)
    got, done = [], threading.Event()

    def send(msg, data):
        got.append({**msg, "data": data})
        if msg["type"] == "frame":
            first_frame.set()
            tab.ack()
            if msg["still"] and any(
                    m["type"] == "settings" and not m["busy"] for m in got):
                done.set()
        if msg["type"] == "error":
            done.set()

    tab = Tab(lib, gl, pool, send, lambda s, fn: None, size=(96, 72))
    try:
        tab.open("G.EGRID")
        assert done.wait(WAIT_S)
        assert not [m for m in got if m["type"] == "error"], got[-1]
        cells = [int(re.search(r"of ([\d,]+) cells", m["readout"]).group(1).replace(",", ""))
                 for m in got if m["type"] == "frame"]
        assert cells[0] < cells[-1]   # the coarse preview first, then every cell
        busy = [m for m in got if m["type"] == "settings" and m["busy"]]
        assert busy and busy[0]["busy"][0].startswith("coarse preview — full picture")
        frame = got[-1] if got[-1]["type"] == "frame" else \
            next(m for m in reversed(got) if m["type"] == "frame")
        img = np.asarray(Image.open(io.BytesIO(frame["data"])).convert("RGBA"))
        opening = prepare(str(tmp_path / "G.EGRID"))
        cam = Camera.from_saved(SavedCamera.from_dict(frame["camera"]))
        with geoshade.view(geoshade.load(tmp_path / "G.EGRID"), size=(96, 72),
                           options=opening.options) as v:
            want, _ = v.draw(cam)
        assert np.array_equal(img, want)
    finally:
        tab.close().result(WAIT_S)
        pool.shutdown()
        gl.stop()
