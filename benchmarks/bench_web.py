"""``geoshade serve`` measured in a real browser (headless Chromium): frames per second while the
camera turns, latency from a camera move to the new picture shown by the page, and memory per
open tab, for each part at 1280×720.

Run: ``python benchmarks/bench_web.py [--size 1280x720] [--seconds 6] [--tabs 3]``; prints a
Markdown table, writes ``benchmarks/results/web.json`` and the ``web`` section of RESULTS.md.
Needs the web extra, selenium and Debian's ``chromium`` + ``chromium-driver``.

How it measures: the page's own script is driven from inside the browser. *Latency*: one
pointer move of 8 px is sent (a real ``pointermove`` on the picture) and the time until the
page has decoded and shown the next frame (``img.onload``), repeated; *fps*: pointer moves at
every browser frame for ``--seconds`` and the frames shown counted (frames the server could not
draw in time are dropped, never queued). *Memory per tab*: the server's RSS (``VmRSS``) after
opening the same file in ``--tabs`` more tabs, minus before, per tab; the GPU bytes of one tab's
View come from its read-out (``stats["gpu_bytes"]``).
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import harness

FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync")
WAIT_S = 300.0

MOVE_JS = """
const [n, done] = [arguments[0], arguments[arguments.length - 1]];
const img = document.getElementById('frame'), g = window.geoshade;
const r = img.getBoundingClientRect(), cx = r.left + r.width / 2, cy = r.top + r.height / 2;
const ev = (type, x) => img.dispatchEvent(new PointerEvent(type, {clientX: x, clientY: cy,
    pointerId: 1, button: 0, buttons: 1, bubbles: true}));
const lat = [];
ev('pointerdown', cx);
let k = 0, x = cx;
const next = () => {
  if (k === n) { ev('pointerup', x); done(lat); return; }
  const f0 = g.frames, t0 = performance.now();
  x += 8; ev('pointermove', x);
  const wait = () => { if (g.frames > f0) { lat.push(performance.now() - t0); k += 1;
                                           setTimeout(next, 50); }
                       else setTimeout(wait, 2); };
  wait();
};
setTimeout(next, 100);
"""

FPS_JS = """
const [seconds, done] = [arguments[0], arguments[arguments.length - 1]];
const img = document.getElementById('frame'), g = window.geoshade;
const r = img.getBoundingClientRect(), cx = r.left + r.width / 2, cy = r.top + r.height / 2;
const ev = (type, x) => img.dispatchEvent(new PointerEvent(type, {clientX: x, clientY: cy,
    pointerId: 1, button: 0, buttons: 1, bubbles: true}));
ev('pointerdown', cx);
let x = cx; const f0 = g.frames, t0 = performance.now();
const step = () => {
  if (performance.now() - t0 > seconds * 1000) {
    const frames = g.frames - f0, t = (performance.now() - t0) / 1000;
    ev('pointerup', x); done([frames, t]); return;
  }
  x += 2; ev('pointermove', x); requestAnimationFrame(step);
};
requestAnimationFrame(step);
"""


def rss_kib(pid: int) -> int:
    return harness.status_kib("VmRSS", f"/proc/{pid}/status") or 0


def write_data(d: Path) -> dict[str, tuple[str, str | None]]:
    """A 60×50×20 grid case (3 steps), a 128³ core, a 64³×3 field, a 128×128×48 layered
    volume: name -> (catalogue name, part to open it as)."""
    import grid_cases

    from geoshade.compute.voxels.synthetic import synthetic_core

    grid_cases.write_case(d, 60, 50, 20, steps=3, name="BENCH")
    np.save(d / "core.npy", synthetic_core(128, porosity=0.2, seed=7).data)
    t = np.linspace(0, 1, 3)[:, None, None, None]
    z, y, x = np.mgrid[0:64, 0:64, 0:64] / 16.0
    np.save(d / "field.npy", (np.sin(x + 2 * t) + np.cos(y) + 0.3 * z).astype(np.float32) / 4)
    lab = (np.floor(np.mgrid[0:48, 0:128, 0:128][0] / 8 + np.sin(np.mgrid[0:48, 0:128, 0:128][2]
                                                                  / 20.0)) % 6 + 1)
    np.save(d / "layers.npy", lab.astype(np.uint8))
    return {"grid": ("root/BENCH.EGRID", None), "core": ("root/core.npy", None),
            "iso": ("root/field.npy", None), "stacks": ("root/layers.npy", "stacks")}


def start_server(root: Path):
    code = "import sys; from geoshade.cli.main import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.Popen([sys.executable, "-c", code, "serve", "--port", "0", "--root",
                             str(root)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                            text=True)
    line = proc.stdout.readline()
    if "http://" not in line:
        proc.kill()
        raise SystemExit(f"geoshade serve did not start: {line!r}")
    threading.Thread(target=proc.stdout.read, daemon=True).start()
    return proc, line.split()[-1]


def browser(profile: str):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = "/usr/bin/chromium"
    for f in (*FLAGS, f"--user-data-dir={profile}", "--window-size=1700,1000"):
        opts.add_argument(f)
    d = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
    d.set_script_timeout(WAIT_S)
    return d


def wait_still(d, after: int = 0) -> dict:
    t0 = time.monotonic()
    while time.monotonic() - t0 < WAIT_S:
        s = d.execute_script("const g = window.geoshade; return {errors: g.errors, "
                             "last: g.last, stills: g.stills};")
        if s["errors"]:
            raise SystemExit(f"the page shows an error: {s['errors'][-1]}")
        if s["last"] and s["last"]["still"] and s["stills"] > after:
            return s
        time.sleep(0.2)
    raise SystemExit("no frame")


def measure(url: str, pid: int, name: str, kind: str | None, size, seconds: float, moves: int,
            tabs: int, profile: str) -> dict:
    d = browser(profile)
    try:
        q = f"&size={size[0]}x{size[1]}&open={name}" + (f"&as={kind}" if kind else "")
        rss0 = rss_kib(pid)
        d.get(url + q)
        s = wait_still(d)
        gpu = s["last"]["readout"].split("GPU ")[1].split(" MiB")[0]
        rss1 = rss_kib(pid)
        lat = d.execute_async_script(MOVE_JS, moves)
        wait_still(d, d.execute_script("return window.geoshade.stills"))
        frames, t = d.execute_async_script(FPS_JS, seconds)
        first = d.current_window_handle
        rss_tabs0 = rss_kib(pid)
        for _ in range(tabs):
            d.switch_to.new_window("tab")
            d.get(url + q)
            wait_still(d)
        rss_tabs1 = rss_kib(pid)
        d.switch_to.window(first)
        lat = np.asarray(lat)
        return {"fps": frames / t, "frames": frames, "seconds": t,
                "latency_ms_median": float(np.median(lat)), "latency_ms_p90":
                float(np.percentile(lat, 90)), "latency_ms_min": float(lat.min()),
                "gpu_mib_per_tab": float(gpu),
                "rss_first_tab_mib": (rss1 - rss0) / 1024,
                "rss_per_more_tab_mib": (rss_tabs1 - rss_tabs0) / 1024 / max(1, tabs)}
    finally:
        d.quit()


def run(size=(1280, 720), seconds: float = 6.0, moves: int = 15, tabs: int = 3) -> dict:
    tmp = Path(tempfile.mkdtemp(prefix="geoshade-bench-web-"))
    data = write_data(tmp)
    proc, url = start_server(tmp)
    rows = {}
    try:
        for part, (name, kind) in data.items():
            profile = tempfile.mkdtemp(prefix="geoshade-chromium-", dir=tmp)
            r = measure(url, proc.pid, name, kind, size, seconds, moves, tabs, profile)
            r["part"] = part
            rows[part] = r
            print(f"{part}: {r['fps']:.1f} fps, latency {r['latency_ms_median']:.0f} ms",
                  file=sys.stderr, flush=True)
        rows["server_rss_mib"] = rss_kib(proc.pid) / 1024
    finally:
        proc.terminate()
        proc.wait(30)
        shutil.rmtree(tmp, ignore_errors=True)
    return rows


def markdown(result: dict) -> str:
    m = result["machine"]
    w, h = result["size"]
    lines = ["<!-- web:begin -->", "## web: `geoshade serve` in a browser", "",
             f"`python benchmarks/bench_web.py` — headless Chromium on the same machine, "
             f"{w}×{h} pictures, {result['moves']} single moves for the latency, "
             f"{result['seconds']:.0f} s of continuous turning for the frame rate, "
             f"{result['tabs']} more tabs for the memory.", "",
             f"- machine: {m['cpu']}, {m['cores_usable']} cores usable, "
             f"{m.get('gl_renderer', '?')} (software OpenGL: compare ratios, not absolutes); "
             f"1-min load {m['load_avg'][0]:.1f} at the start (other agents ran meanwhile)", "",
             "| part | model | frames/s turning | move → picture median (p90) ms | GPU MiB "
             "per tab | server RSS first tab MiB | RSS per more tab MiB |",
             "|---|---|---:|---:|---:|---:|---:|"]
    models = {"grid": "60×50×20 cells, 3 steps", "core": "128³ voxels",
              "iso": "64³ × 3 steps", "stacks": "128×128×48 labels, 6 strata"}
    for part in ("grid", "core", "iso", "stacks"):
        r = result["rows"][part]
        lines.append(f"| {part} | {models[part]} | {r['fps']:.1f} | "
                     f"{r['latency_ms_median']:.0f} ({r['latency_ms_p90']:.0f}) | "
                     f"{r['gpu_mib_per_tab']:.2f} | {r['rss_first_tab_mib']:.0f} | "
                     f"{r['rss_per_more_tab_mib']:.0f} |")
    lines += ["", "While the camera turns the page gets JPEG frames and the server draws without "
              "the counting pass; the lossless PNG follows when it rests. Latency includes the "
              "draw, the encoding, the websocket and the browser's decoding. Memory: the "
              "server's RSS grows by the first tab of a part (its model read once, its View; "
              "the grid, measured first, also starts the GL context) and then by the \"more "
              "tab\" figure for each further tab of the same file (its own View; llvmpipe keeps "
              "GPU objects in host memory, so the GPU MiB are in it too; a few MiB are noise).",
              "<!-- web:end -->",
              ""]
    return "\n".join(lines)


def rewrite(json_path) -> int:
    """Write the RESULTS.md section again from a saved ``web.json`` (no measuring)."""
    result = json.loads(Path(json_path).read_text())
    harness.write_results(HERE, "web", markdown(result))
    return 0


def main(argv=None, folder=None) -> int:
    """``python benchmarks/bench_web.py [--size WxH ...]``, or ``geoshade bench web`` (which
    passes its parsed arguments and this folder)."""
    from geoshade.styles.image import parse_size

    if isinstance(argv, argparse.Namespace):   # from geoshade bench web
        argv = ["--size", "1280x720" if argv.size == "1024x768" else argv.size,
                "-o", str(argv.output or folder or HERE)]
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--size", default="1280x720")
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--moves", type=int, default=10)
    p.add_argument("--tabs", type=int, default=2)
    p.add_argument("-o", "--output", default=str(HERE))
    a = p.parse_args(argv)
    size = parse_size(a.size)
    result = {"part": "web", "size": list(size), "seconds": a.seconds, "moves": a.moves,
              "tabs": a.tabs, "machine": harness.machine_info(),
              "rows": run(size, a.seconds, a.moves, a.tabs)}
    out = Path(a.output)
    (out / "results").mkdir(parents=True, exist_ok=True)
    js = out / "results" / "web.json"
    js.write_text(json.dumps(result, indent=1))
    md = markdown(result)
    print(md)
    harness.write_results(out, "web", md, js)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
