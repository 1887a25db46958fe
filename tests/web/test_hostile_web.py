"""A standing red team of ``geoshade serve`` (issue 32): every attack on the browser server is
one clean line to the page that made it, or correct output; nothing leaks the token or a server
path, no tab stalls another, nothing hangs, and SIGINT/SIGTERM stop it in every state.

Cases: the token and its cookie (headers, scope, the address after load, framing, Host); the
door (a flood of half-open connections with the descriptors limited to 1024); the messages
(types, fields, sizes, pictures, drape pictures, rates, panel values); the files (FIFOs, sockets,
symbolic link loops, stores and cases holding one; reads that block take no slot and keep
nothing); one cluster per server; signals.
"""

from __future__ import annotations

import asyncio
import contextlib
import http.server
import json
import os
import re
import selectors
import signal
import socket
import threading
import time
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from PIL import Image

from geoshade.errors import InputError
from geoshade.viewer.views import load_model
from geoshade.web import library as library_mod
from geoshade.web import messages
from geoshade.web.catalog import Catalog
from geoshade.web.messages import Bucket, check_control, check_set, parse
from tests.web.conftest import WAIT_S, Served, need_web, settled_still


# --- the files of the red team ------------------------------------------------------------------
def hostile_root(d: Path) -> Path:
    """A root holding good files and traps: a FIFO, a store whose zarr.json is a FIFO, a case
    whose INIT is a FIFO, a socket, link loops, a link out of the root, a picture too wide."""
    from geoshade.compute.voxels.synthetic import synthetic_core
    from tests.grid_cases import grid_cases

    root = d / "root"
    root.mkdir()
    np.save(root / "core.npy", synthetic_core(24).data)
    lab = np.zeros((8, 10, 12), np.uint8)
    lab[:3], lab[3:6], lab[6:] = 1, 2, 3
    np.save(root / "labels.npy", lab)
    (root / "bad.npy").write_bytes(b"garbage, not an array")
    grid_cases().write_case(root / "case", 6, 5, 3, steps=2)
    trap_case = root / "trapcase"
    trap_case.mkdir()
    (trap_case / "TRAP.EGRID").write_bytes((root / "case" / "BIG.EGRID").read_bytes())
    os.mkfifo(trap_case / "TRAP.INIT")
    (root / "trap.zarr").mkdir()
    os.mkfifo(root / "trap.zarr" / "zarr.json")
    os.mkfifo(root / "pipe.npy")
    os.symlink("loop.npy", root / "loop.npy")
    (root / "sub").mkdir()
    os.symlink(root / "sub" / "b.npy", root / "sub" / "a.npy")
    os.symlink(root / "sub" / "a.npy", root / "sub" / "b.npy")
    os.symlink("/etc", root / "out")
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(root / "sock.npy"))
    sock.close()
    Image.new("RGB", (12000, 2)).save(root / "wide.png")   # a header too wide to drape
    Image.new("RGB", (16, 16), (200, 40, 40)).save(root / "small.png")
    return root


# --- messages (no server) -----------------------------------------------------------------------
@pytest.mark.parametrize(("text", "match"), [
    ('{"t": "banana"}', "message: unknown type 'banana'; expected one of ack, pointer"),
    ('{"x": 1}', "unknown type None"),
    ("[1, 2]", "expected a JSON object, got list"),
    ('"str"', "expected a JSON object, got str"),
    ("{nope", "message: not JSON"),
    ("[" * 100_000 + "]" * 100_000, "at most 65,536"),
    ("[" * 30_000 + "]" * 30_000, "message: not JSON"),       # nesting: no RecursionError
    ('{"t": "resize", "w": 8000, "h": 8000}', "8000×8000 pixels is larger than this server "
                                              r"draws \(at most 4096×4096\)"),
    ('{"t": "resize", "w": 1e300, "h": 100}', "larger than this server draws"),
    ('{"t": "resize", "w": "a", "h": 100}', "resize: w: expected an integer >= 16, got 'a'"),
    ('{"t": "resize", "w": 100, "h": 1}', "resize: h: expected an integer >= 16, got 1"),
    ('{"t": "resize", "w": 100}', "resize: h is missing"),
    ('{"t": "pointer", "kind": "move", "x": NaN, "y": 1}', "pointer: x: expected a number"),
    ('{"t": "pointer", "kind": "jump", "x": 1, "y": 1}', "expected one of down, move, up"),
    ('{"t": "wheel", "notches": 1e308}', "wheel: notches: expected a number -100..100"),
    ('{"t": "key", "key": 5}', "key: key: expected text, got 5"),
    ('{"t": "key", "key": "' + "x" * 40 + '"}', "at most 16"),
    ('{"t": "ack", "extra": 1}', "ack: unknown field 'extra'; it takes no field"),
    ('{"t": "open", "name": "a", "as": "rm -rf"}', "open: as: expected one of core, grid"),
    ('{"t": "set", "values": []}', r"set: values: expected \{option: value\}"),
    ('{"t": "set", "values": {}}', "1 to 64 options"),
])
def test_a_bad_message_is_one_line(text, match):
    with pytest.raises(InputError, match=match) as e:
        parse(text)
    assert "\n" not in str(e.value)


def test_good_messages_are_taken():
    for m in ({"t": "ack"}, {"t": "resize", "w": 4096, "h": 16},
              {"t": "pointer", "kind": "down", "x": 3.5, "y": 4, "button": "right"},
              {"t": "wheel", "notches": -2.5}, {"t": "open", "name": "root/a.npy", "as": None},
              {"t": "set", "values": {"faults": "hide"}}, {"t": "load_camera", "text": "{}"}):
        assert parse(json.dumps(m)) == m
    assert messages.limits()["max_side"] == messages.MAX_SIDE == 4096


PANEL = [{"group": "g", "controls": [
    {"name": "faults", "type": "select", "choices": ["show", "hide"]},
    {"name": "colormap", "type": "select", "choices": ["viridis"], "editable": True},
    {"name": "smooth", "type": "number", "min": 0, "max": 10},
    {"name": "color_range", "type": "pair"},
    {"name": "box", "type": "ints", "n": 6},
    {"name": "filter", "type": "text"},
    {"name": "step", "type": "step", "min": 0, "max": 3},
    {"name": "otsu", "sets": "select", "type": "button", "value": "auto"},
    {"name": "select", "type": "pair"},
    {"name": "materials", "sets": ["hide", "opacity"], "type": "materials",
     "items": [[1, "sand", "#fff"], [2, "clay", "#000"]]},
    {"name": "section", "sets": "plane", "type": "section", "axes": ["x", "y", "z"]},
    {"name": "lighting", "type": "check"}]}]


@pytest.mark.parametrize(("values", "match"), [
    ({"mask": "/etc/passwd"}, "set: 'mask' is not a control of this grid's panel"),
    ({"faults": "explode"}, "faults: expected one of show, hide, got 'explode'"),
    ({"colormap": {"a": 1}}, "colormap: expected one of viridis"),
    ({"colormap": "x" * 65}, "colormap: expected one of viridis"),
    ({"smooth": 1e9}, "smooth: expected a number 0..10"),
    ({"smooth": True}, "smooth: expected a number 0..10, got True"),
    ({"color_range": [0]}, "color_range: expected 2 numbers"),
    ({"color_range": [0, None]}, "color_range: expected a number, got None"),
    ({"box": [0, 0, 0, 1, 1, 1.5]}, "box: expected an integer"),
    ({"filter": "x" * 5000}, "filter: 5,000 characters; at most 1,000"),
    ({"step": 4}, "step: expected an integer 0..3, got 4"),
    ({"select": "rm"}, "select: the otsu button sends 'auto'"),
    ({"hide": [1, 9]}, r"hide: expected material codes of \[1, 2\]"),
    ({"opacity": {"1": 5}}, "opacity of 1: expected a number 0..1"),
    ({"opacity": {"7": 0.5}}, "opacity: '7' is no material code"),
    ({"plane": ["w", 0.5, False]}, r"section: expected \[axis \(x, y, z\)"),
    ({"plane": ["x", 2, False]}, "section: fraction: expected a number 0..1"),
    ({"lighting": "yes"}, "lighting: expected true or false"),
])
def test_a_change_no_control_can_send_is_refused(values, match):
    with pytest.raises(InputError, match=match):
        check_set(values, PANEL, {}, "grid")


def test_a_change_a_control_sends_is_taken():
    good = {"faults": "hide", "colormap": "magma", "smooth": 2, "color_range": None,
            "box": [0, 0, 0, 4, 4, 4], "filter": "PORO > 0.2", "step": 3, "select": "auto",
            "hide": [2], "opacity": {"1": 0.5}, "plane": ["z", 0.25, True], "lighting": False}
    assert check_set(good, PANEL, {}, "grid") == good
    assert check_set({"select": [0, 9000]}, PANEL, {}, "core") == {"select": [0, 9000]}
    # a select may send back the value it shows, though no choice (an expression's property)
    spec = {"name": "property", "type": "select", "choices": [None, "PORO"]}
    assert check_control(spec, "property", "log10(PERMX)", "log10(PERMX)") == "log10(PERMX)"


def test_the_bucket_drops_what_is_over_the_rate():
    b = Bucket(rate=10, burst=5)
    taken = sum(b.take() for _ in range(8000))
    assert 5 <= taken < 8000 and b.dropped == 8000 - taken


# --- the catalogue (no server) ------------------------------------------------------------------
def test_the_listing_shows_no_trap_and_survives_loops(tmp_path):
    root = hostile_root(tmp_path)
    names = Catalog([], root=root).names()
    assert names == ["root/bad.npy", "root/case/BIG.EGRID", "root/case/BIG.INIT",
                     "root/case/BIG.UNRST", "root/core.npy", "root/labels.npy",
                     "root/trap.zarr", "root/trapcase/TRAP.EGRID"]
    assert Catalog([], root=root).images() == ["root/small.png", "root/wide.png"]


@pytest.mark.parametrize(("name", "match"), [
    ("root/pipe.npy", r"^root/pipe.npy: is a FIFO \(named pipe\), not a file"),
    ("root/sock.npy", "^root/sock.npy: is a socket, not a file"),
    ("root/trap.zarr", r"^root/trap.zarr: zarr.json inside it is a FIFO \(named pipe\)"),
    ("root/trapcase/TRAP.EGRID", r"^root/trapcase/TRAP.EGRID: TRAP.INIT beside it is a FIFO"),
    ("root/loop.npy", "^open: 'root/loop.npy' is not one of the files this server shows"),
    ("root/sub/a.npy", "is not one of the files this server shows"),
    ("root/out/passwd", "is not one of the files this server shows"),
    ("root/.hidden", "is not one of the files this server shows"),
])
def test_what_could_block_a_read_is_refused_before_it(tmp_path, name, match):
    root = hostile_root(tmp_path)
    cat = Catalog([], root=root)
    with pytest.raises(InputError, match=match) as e:
        cat.checked(name)
    assert str(root) not in str(e.value)


def test_a_fifo_named_on_the_command_line_is_refused(tmp_path):
    os.mkfifo(tmp_path / "scan.npy")
    with pytest.raises(InputError, match=r"scan.npy: is a FIFO \(named pipe\); serve shows"):
        Catalog([tmp_path / "scan.npy"])
    os.symlink("x.npy", tmp_path / "x.npy")
    with pytest.raises(InputError, match="a symbolic link that leads nowhere"):
        Catalog([tmp_path / "x.npy"])


def test_messages_name_files_as_the_page_knows_them(tmp_path):
    root = hostile_root(tmp_path)
    (tmp_path / "named.npy").write_bytes(b"")
    cat = Catalog([tmp_path / "named.npy"], root=root)
    msg = {"type": "error", "text": f"{root}/bad.npy: not an array; {tmp_path}/named.npy: "
                                    "too; /usr/lib/libEGL.so.1: missing",
           "svg": '<svg xmlns="http://www.w3.org/2000/svg"><title>a</title></svg>'}
    out = cat.public(msg)
    assert out["text"] == "root/bad.npy: not an array; named.npy: too; libEGL.so.1: missing"
    assert out["svg"] == msg["svg"]
    assert cat.public("PORO / NTG > 0.2 and log10(PERMX)/2") == \
        "PORO / NTG > 0.2 and log10(PERMX)/2"


# --- reads that block -------------------------------------------------------------------------
def _unblock(fifo: Path) -> None:
    """Let a reader blocked opening ``fifo`` go on (it reads an empty file)."""
    with contextlib.suppress(OSError):   # no reader (any more): nothing to do
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))


def _release(futures, fifos) -> None:
    """Unblock ``fifos`` until every read of ``futures`` is over (a waiting read starts, and
    blocks, only once another ended); each ends in one line (an empty FIFO is no array)."""
    t0 = time.monotonic()
    while not all(f.done() for f in futures) and time.monotonic() - t0 < WAIT_S:
        for fifo in fifos:
            _unblock(fifo)
        time.sleep(0.05)
    for f in futures:
        with pytest.raises(InputError):
            f.result(0)


#: what a reader that misses a FIFO does: it opens it, and open(2) waits for a writer for ever
#: (the catalogue's checks refuse FIFOs first; the tests switch them off to hold a reader)
BLOCKING_READER = ("from geoshade.web.catalog import Catalog; import geoshade.web.library as L; "
                   "Catalog.checked = Catalog.path; read = L.load_model; "
                   "L.load_model = lambda path, kind, hints: open(path, 'rb').read() "
                   "if path.endswith('pipe.npy') else read(path, kind, hints)")


def test_reads_that_block_take_no_slot_and_keep_nothing(tmp_path, monkeypatch):
    """Reads blocked for ever in open(2) on FIFOs (the checks switched off, the reader opening
    whatever it is given) hold no slot after SLOW_READ_S; a second tab opening one waits on the
    same read; other files still open; the blocked threads are daemons."""
    root = hostile_root(tmp_path)
    for k in range(3):
        os.mkfifo(root / f"stuck{k}.npy")

    def reader(path, kind, hints):
        if "stuck" in path:
            with open(path, "rb") as f:   # blocks until a writer comes
                f.read()
        return load_model(path, kind, hints)

    monkeypatch.setattr(Catalog, "checked", Catalog.path)
    monkeypatch.setattr(library_mod, "load_model", reader)
    monkeypatch.setattr(library_mod, "SLOW_READ_S", 0.5)
    lib = library_mod.Library(Catalog([], root=root))
    try:
        stuck = [lib.read(f"root/stuck{k}.npy") for k in range(3)]
        assert lib.read("root/stuck0.npy") is stuck[0]          # one read, two tabs
        opening = lib.read("root/core.npy").result(WAIT_S)       # more stuck reads than slots
        assert opening.cls.kind == "core"
        readers = [t for t in threading.enumerate() if t.name.startswith("geoshade-read")]
        assert len(readers) == 3 and all(t.daemon for t in readers)
        assert not any(f.done() for f in stuck)
    finally:
        _release(stuck, [root / f"stuck{k}.npy" for k in range(3)])
        lib.close()


def test_reads_waiting_and_kept_are_bounded(tmp_path, monkeypatch):
    """Past MAX_WAITING reads waiting to start, an open is one line; only the last MAX_KEPT
    files read are kept for the next tab."""
    root = hostile_root(tmp_path)
    for k in range(3):
        os.mkfifo(root / f"stuck{k}.npy")
        np.save(root / f"v{k}.npy", np.zeros((4, 4, 4), np.uint8))

    def reader(path, kind, hints):
        if "stuck" in path:
            with open(path, "rb") as f:   # blocks until a writer comes
                f.read()
        return load_model(path, kind, hints)

    monkeypatch.setattr(Catalog, "checked", Catalog.path)
    monkeypatch.setattr(library_mod, "load_model", reader)
    monkeypatch.setattr(library_mod, "MAX_WAITING", 1)
    monkeypatch.setattr(library_mod, "MAX_KEPT", 2)
    lib = library_mod.Library(Catalog([], root=root))
    try:
        stuck = [lib.read(f"root/stuck{k}.npy") for k in range(3)]   # 2 run, 1 waits
        with pytest.raises(InputError, match=r"^open: 1 files are waiting to be read; open "
                                             "root/core.npy once they are$"):
            lib.read("root/core.npy")
    finally:
        _release(stuck, [root / f"stuck{k}.npy" for k in range(3)])
    for k in range(3):
        lib.read(f"root/v{k}.npy").result(WAIT_S)
    assert lib.loaded() == ["root/v1.npy", "root/v2.npy"] and lib.reads == 3
    lib.close()


def test_one_cluster_for_every_tab(tmp_path):
    """``--scheduler local:1``: one cluster started for the server, whatever opens; every
    View gets its client; closing the server closes it."""
    pytest.importorskip("distributed", reason="the distributed extra is not installed")
    from geoshade.scheduler import Scheduler

    lib = library_mod.Library(Catalog([], demo=True), {"scheduler": Scheduler.parse("local:1")})
    try:
        a = lib.read("demo/core").result(WAIT_S)
        b = lib.read("demo/grid").result(WAIT_S)
        c = lib.read("demo/stacks").result(WAIT_S)     # takes no scheduler: starts nothing
        assert lib.work.starts == 1
        assert a.options.scheduler.client is b.options.scheduler.client is lib.work.client()
        assert not hasattr(c.options, "scheduler")
    finally:
        lib.close()
    assert not lib.work.started


# --- the server ----------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def served_hostile(tmp_path_factory):
    """``geoshade serve --root`` over the red team's files, with 1024 descriptors at most."""
    need_web()
    root = hostile_root(tmp_path_factory.mktemp("hostile"))
    s = Served(["--root", str(root)], nofile=1024)
    yield s, root
    s.stop()


async def _http(url: str, headers=None):
    import aiohttp

    async with aiohttp.ClientSession() as c, c.get(url, headers=headers or {}) as r:
        return r.status, dict(r.headers), await r.text()


async def _talk(served, batches, until, token=True):
    """Send each batch of messages (a batch: after the previous ``until`` held); the
    messages heard, frames acknowledged."""
    import aiohttp

    url = served.base.replace("http://", "ws://") + "/ws" + \
        (f"?token={served.token}" if token else "")
    got: list = []
    async with aiohttp.ClientSession() as c, c.ws_connect(url) as ws:
        for batch, test in zip(batches, until, strict=True):
            for m in batch:
                await (ws.send_bytes(m) if isinstance(m, bytes) else
                       ws.send_str(m if isinstance(m, str) else json.dumps(m)))
            t0 = time.monotonic()
            while not test(got):
                if time.monotonic() - t0 > WAIT_S:
                    raise AssertionError(f"waited {WAIT_S:.0f} s; heard {got[-3:]}")
                msg = await ws.receive(timeout=WAIT_S)
                if msg.type == aiohttp.WSMsgType.TEXT:
                    got.append(json.loads(msg.data))
                elif msg.type == aiohttp.WSMsgType.BINARY:
                    got[-1]["data"] = msg.data
                    await ws.send_str('{"t": "ack"}')
                else:
                    got.append({"type": "closed", "code": ws.close_code})
                    break
    return got


def _errors(got, after=0):
    return [m["text"] for m in got[after:] if m["type"] == "error"]


def test_the_token_stays_on_the_server(served_hostile):
    s, _ = served_hostile
    status, headers, text = asyncio.run(_http(s.url))
    assert status == 200 and s.token not in text and s.token not in json.dumps(headers)
    port = s.base.rsplit(":", 1)[1]
    assert re.fullmatch(rf"geoshade_{port}=[\w-]+; HttpOnly; Path=/s/[\w-]+/; SameSite=Strict",
                        headers["Set-Cookie"])
    assert "frame-ancestors 'none'" in headers["Content-Security-Policy"]
    assert headers["X-Frame-Options"] == "DENY" and headers["Referrer-Policy"] == "no-referrer"
    for url, host in ((s.url, f"evil.example:{port}"), (s.url, f"127.0.0.1.nip.io:{port}"),
                      (s.base + "/", None)):
        status, headers, text = asyncio.run(_http(url, {"Host": host} if host else None))
        assert status == 403 and headers.get("Connection") == "close"
        assert text.count("\n") == 1 and text.startswith("geoshade serve: ")
    assert asyncio.run(_http(s.url, {"Host": f"localhost:{port}"}))[0] == 200


def test_hostile_messages_get_one_line_each_and_the_tab_goes_on(served_hostile):
    s, _ = served_hostile
    bad = ['{"t": "banana"}', "[1, 2]", b"\x00binary", "x" * 100_000,
           '{"t": "resize", "w": 8000, "h": 8000}', '{"t": "set", "values": {"select": [0, 1]}}',
           '{"t": "screenshot"}', '{"t": "open", "name": "/etc/passwd"}',
           '{"t": "open", "name": "root/../../etc/passwd"}']
    got = asyncio.run(_talk(s, [bad, [{"t": "open", "name": "root/bad.npy"}]],
                            [lambda g: len(_errors(g)) == len(bad),
                             lambda g: len(_errors(g)) == len(bad) + 1]))
    errors = _errors(got)
    assert [e.split(":")[0] for e in errors] == [
        "message", "message", "message", "message", "resize", "set", "screenshot", "open", "open",
        "root/bad.npy"]   # the tab still reads after all that
    assert "no file is open in this tab yet" in errors[5]
    assert errors[-1].startswith("root/bad.npy: not a readable .npy array")


@pytest.mark.gl
def test_panel_values_and_drape_pictures_are_checked(served_hostile):
    s, root = served_hostile
    sets = [{"drape": "root/wide.png"}, {"drape": str(root / "small.png")},
            {"drape_mix": 7}, {"hide": [99]}, {"mask": "/etc/passwd"}, {"kernel": "x"}]
    got = asyncio.run(_talk(
        s, [[{"t": "resize", "w": 64, "h": 48},
             {"t": "open", "name": "root/labels.npy", "as": "stacks"}],
            [{"t": "set", "values": v} for v in sets], [{"t": "set", "values": {
                "drape": "root/small.png"}}]],
        [lambda g: g and g[-1]["type"] == "frame" and "data" in g[-1],
         lambda g: len(_errors(g)) == len(sets),
         lambda g: any(m["type"] == "settings" and m["settings"].get("drape") for m in g)]))
    errors = sorted(_errors(got))
    assert len(errors) == len(sets)
    assert errors[0].startswith("drape: expected one of None, root/small.png, root/wide.png")
    assert errors[1] == ("drape: root/wide.png is 12000×2 pixels; the browser drapes pictures "
                         "of at most 4096×4096 (make a smaller copy, or give it to serve with "
                         "--drape)")
    assert errors[2].startswith("drape_mix: expected a number 0..1")
    assert errors[3].startswith("hide: expected material codes")
    assert errors[4].startswith("kernel: expected") and "'mask' is not a control" in errors[5]
    assert not any(str(root) in e for e in errors)


@pytest.mark.parametrize(("name", "says"), [
    ("root/bad.npy", "root/bad.npy: not a readable .npy array"),
    ("root/pipe.npy", "root/pipe.npy: is a FIFO (named pipe), not a file"),
    ("root/trap.zarr", "root/trap.zarr: zarr.json inside it is a FIFO (named pipe)"),
    ("root/trapcase/TRAP.EGRID", "root/trapcase/TRAP.EGRID: TRAP.INIT beside it is a FIFO"),
    ("root/loop.npy", "open: 'root/loop.npy' is not one of the files this server shows"),
])
def test_a_bad_file_is_one_line_without_the_server_paths(served_hostile, name, says):
    s, root = served_hostile
    got = asyncio.run(_talk(s, [[{"t": "open", "name": name}]],
                            [lambda g: bool(_errors(g))]))
    assert got[0]["files"] == Catalog([], root=root).names()   # the loops listed nothing
    assert _errors(got)[0].startswith(says)
    assert str(root) not in json.dumps(got) and s.token not in json.dumps(got)


@pytest.mark.gl
def test_a_message_flood_is_rate_limited_and_stalls_no_one(served_hostile):
    """8,000 panel changes as fast as a socket takes them: dropped over the rate (said in a
    line), merged while they wait; another tab opened meanwhile gets its frame; the flooder
    hears a few messages back until it is quiet, not one per change."""
    s, _ = served_hostile
    flood = [json.dumps({"t": "set", "values": {"colormap": ["viridis", "magma"][k % 2]}})
             for k in range(8000)]

    async def run():
        import aiohttp

        url = s.base.replace("http://", "ws://") + f"/ws?token={s.token}"
        async with aiohttp.ClientSession() as c, c.ws_connect(url) as ws:
            async def hear(quiet_s: float) -> list:
                """Messages until none came for ``quiet_s`` (frames acknowledged)."""
                heard: list = []
                t0 = time.monotonic()
                while time.monotonic() - t0 < WAIT_S:
                    try:
                        m = await ws.receive(timeout=quiet_s)
                    except TimeoutError:
                        return heard
                    if m.type == aiohttp.WSMsgType.TEXT:
                        heard.append(json.loads(m.data))
                    elif m.type == aiohttp.WSMsgType.BINARY:
                        await ws.send_str('{"t": "ack"}')
                    else:
                        break
                return heard

            await ws.send_str('{"t": "resize", "w": 64, "h": 48}')
            await ws.send_str('{"t": "open", "name": "root/core.npy"}')
            opened = await hear(3.0)
            assert any(m["type"] == "frame" for m in opened), opened[-3:]
            for m in flood:
                await ws.send_str(m)
            other = await _talk(s, [[{"t": "resize", "w": 64, "h": 48},
                                     {"t": "open", "name": "root/labels.npy"}]],
                                [lambda g: g and g[-1]["type"] == "frame" and "data" in g[-1]])
            return await hear(3.0), other

    heard, other = asyncio.run(run())
    assert other[-1]["type"] == "frame"
    lines = [m["text"] for m in heard if m["type"] == "error"]
    assert lines and all(re.fullmatch(r"too many messages from this page: [\d,]+ dropped so "
                                      r"far \(at most 200 a second\)", x) for x in lines)
    assert len(heard) < 800   # a few per merged change, not one per change


def test_an_oversized_message_closes_only_its_socket(served_hostile):
    s, _ = served_hostile
    got = asyncio.run(_talk(s, [["x" * (5 * messages.MAX_MESSAGE)]],
                            [lambda g: g and g[-1]["type"] == "closed"]))
    assert got[-1]["code"] == 1009
    got = asyncio.run(_talk(s, [['{"t": "banana"}']], [lambda g: bool(_errors(g))]))
    assert got[0]["type"] == "hello"


@pytest.mark.gl
def test_half_open_connections_do_not_lock_the_tab(served_hostile):
    """1,100 connections that never finish their headers, the server limited to 1024
    descriptors: the open tab keeps getting frames, a new tab loads the page and opens, and
    the server closed the connections past its limit at once."""
    s, _ = served_hostile
    port = int(s.base.rsplit(":", 1)[1])

    async def run():
        import aiohttp

        url = s.base.replace("http://", "ws://") + f"/ws?token={s.token}"
        async with aiohttp.ClientSession() as c, c.ws_connect(url) as ws:
            async def frame():
                while True:
                    m = await ws.receive(timeout=WAIT_S)
                    if m.type == aiohttp.WSMsgType.BINARY:
                        await ws.send_str('{"t": "ack"}')
                        return True
                    if m.type != aiohttp.WSMsgType.TEXT:
                        return False

            await ws.send_str('{"t": "resize", "w": 64, "h": 48}')
            await ws.send_str('{"t": "open", "name": "root/core.npy"}')
            assert await frame()
            socks = await asyncio.to_thread(_half_open, port, 1100)
            try:
                await ws.send_str('{"t": "wheel", "notches": 1}')
                moved = await frame()
                page = await _http(s.url)
                fresh = await _talk(s, [[{"t": "resize", "w": 64, "h": 48},
                                         {"t": "open", "name": "root/labels.npy"}]],
                                    [lambda g: g and g[-1]["type"] == "frame"])
                closed = await asyncio.to_thread(_closed_by_server, socks)
                fds = len(os.listdir(f"/proc/{s.proc.pid}/fd"))
            finally:
                for k in socks:
                    k.close()
            return moved, page[0], fresh[-1]["type"], closed, len(socks), fds

    moved, status, fresh, closed, opened, fds = asyncio.run(run())
    assert moved and status == 200 and fresh == "frame"
    assert opened == 1100 and closed >= 1100 - 64 and fds < 1024 - 128


def _half_open(port: int, n: int) -> list[socket.socket]:
    out = []
    for _ in range(n):
        k = socket.create_connection(("127.0.0.1", port), timeout=10)
        k.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n")   # the headers never end
        out.append(k)
    return out


def _closed_by_server(socks: list[socket.socket], within: float = 5.0) -> int:
    """How many of ``socks`` the server closed (end of stream or reset) within ``within``
    seconds, all watched at once (one by one, each kept open cost its 5 s); one that is sent
    bytes first is not closed."""
    sel = selectors.DefaultSelector()   # epoll: more sockets than select() takes
    for k in socks:
        k.setblocking(False)
        sel.register(k, selectors.EVENT_READ)
    closed = 0
    deadline = time.monotonic() + within
    while sel.get_map() and (left := deadline - time.monotonic()) > 0:
        for key, _ in sel.select(left):
            try:
                data = key.fileobj.recv(1 << 16)
            except BlockingIOError:
                continue
            except ConnectionResetError:
                data = b""
            closed += data == b""
            sel.unregister(key.fileobj)
    sel.close()
    return closed


# --- signals -----------------------------------------------------------------------------------
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_stops_it_with_a_read_blocked(tmp_path, sig):
    """Two tabs open a FIFO that the checks miss (switched off here, :data:`BLOCKING_READER`):
    a third tab's file is still read, and SIGTERM or SIGINT ends the server (exit 0)."""
    need_web()
    root = hostile_root(tmp_path)
    s = Served(["--root", str(root)], prelude=BLOCKING_READER)
    try:
        async def tabs():
            import aiohttp

            url = s.base.replace("http://", "ws://") + f"/ws?token={s.token}"
            async with aiohttp.ClientSession() as c:
                held = [await c.ws_connect(url) for _ in range(2)]
                for ws in held:
                    await ws.send_str('{"t": "open", "name": "root/pipe.npy"}')
                return await _talk(s, [[{"t": "open", "name": "root/bad.npy"}]],
                                   [lambda g: bool(_errors(g))])

        # another file is still read (its line comes back) while two tabs wait on the FIFO
        assert _errors(asyncio.run(tabs()))[0].startswith("root/bad.npy: not a readable")
        s.proc.send_signal(sig)
        assert s.proc.wait(WAIT_S) == 0
        assert "geoshade serve: stopping" in "".join(s.errors)
        assert "Traceback" not in "".join(s.errors)
    finally:
        _unblock(root / "pipe.npy")
        s.stop()


def test_sigterm_tells_the_open_tab():
    need_web()
    s = Served(["--demo", "stacks"])
    try:
        async def tab():
            import aiohttp

            url = s.base.replace("http://", "ws://") + f"/ws?token={s.token}"
            async with aiohttp.ClientSession() as c, c.ws_connect(url) as ws:
                assert json.loads((await ws.receive(timeout=WAIT_S)).data)["type"] == "hello"
                s.proc.send_signal(signal.SIGTERM)
                heard = []
                while True:
                    m = await ws.receive(timeout=WAIT_S)
                    if m.type != aiohttp.WSMsgType.TEXT:
                        return heard, ws.close_code
                    heard.append(json.loads(m.data))

        heard, code = asyncio.run(tab())
        assert {"type": "error", "text": "the server stopped"} in heard and code == 1001
        assert s.proc.wait(WAIT_S) == 0
    finally:
        s.stop()


# --- in the browser ----------------------------------------------------------------------------
class _Recorder(http.server.BaseHTTPRequestHandler):
    """Another local server on another port: records the cookies browsers send it and serves
    a page that frames the viewer."""

    cookies: ClassVar[list] = []
    framed = ""

    def do_GET(self):
        type(self).cookies.append(self.headers.get("Cookie") or "")
        body = f'<html><body><iframe id="v" src="{self.framed}"></iframe></body></html>'
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.end_headers()
        self.wfile.write(body.encode())

    def log_message(self, *args):
        pass


@pytest.mark.gl
def test_in_the_browser_the_token_leaves_and_nothing_frames_it(served_hostile, browser):
    s, _ = served_hostile
    browser.get(f"{s.url}&size=64x48&open=root/core.npy")
    settled_still(browser, 0, lambda st: st["kind"] == "core")
    here = browser.current_url
    assert "token" not in here and s.token not in here and re.search(r"/s/[\w-]+/\?", here)
    assert browser.execute_script("return document.cookie") == ""   # HTTP-only
    browser.refresh()                                               # the cookie lets it in again
    settled_still(browser, 0, lambda st: st["kind"] == "core")
    _Recorder.cookies, _Recorder.framed = [], s.url
    other = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Recorder)
    threading.Thread(target=other.serve_forever, daemon=True).start()
    try:
        browser.get(f"http://127.0.0.1:{other.server_address[1]}/page")
        time.sleep(2)
        browser.switch_to.frame(browser.find_element("id", "v"))
        assert browser.execute_script("return typeof window.geoshade") == "undefined"
        browser.switch_to.default_content()
    finally:
        other.shutdown()
    assert _Recorder.cookies and not any("geoshade" in c for c in _Recorder.cookies)

