"""``geoshade bench scale``: whole cores beyond memory — ingest, porosity on 1…n workers, first
picture of a 1000³ box from a 20 G-voxel store.

For each volume size (default 1, 2, 4, 8 GiB of uint16; ``--quick`` 0.25 GiB; ``--full`` doubles
on to 32 GiB as far as the free disk allows) the parent writes a procedural CT-like raw file
(:func:`ct_block`: two grey levels, pores from a smooth field, hashed noise; a pure function of
the voxel position) and runs, each in its own subprocess so that the peak RSS is that row's:

- ingest: :func:`geoshade.io.stores.ingest.ingest` raw → zarr v3 (128³ chunks, zstd, nearest
pyramid)
  with 2 threads; on the 2 GiB volume also with 1 thread and with a 4-process LocalCluster
  ("simulated" 4 workers: this machine has 2 cores);
- porosity (profile along z) through the user's entry point, :func:`geoshade.core.porosity`
  (what ``geoshade core porosity`` runs, sample detection included): of the zarr store with dask
  threads (``--scheduler threads``), the slab loop (no ``--scheduler``), a LocalCluster of
  1, 2 and 4 worker processes (1 thread and 1 GB each), the slab loop on the raw memmap,
  numpy in memory (``np.fromfile`` + ``((a >= lo) & (a <= hi)).sum((1, 2))``)
  and PoreSpy's ``porosity_profile`` on the numpy bool image, the last two only where the volume
  fits (2.5 × its size ≤ half the available memory).  Every row's voxel count is checked against
  the numpy (or the threaded dask) result.

Then the 20 G-voxel store: 2600 × 2600 × 2960 uint16 (20.0 G voxels, 40 GB if dense) written
*sparsely*: level 0 holds only the 128³ chunks that the box [800, 800, 1000] + 1000³ touches
(9 × 9 × 9 = 729 of 10,584 chunks), level 1 the chunks over the same region (125 of 1,452);
levels 2-4 (650 × 650 × 740 and smaller) are written whole.  Every written voxel is
:func:`ct_block` of its level-0 position (levels sample every 2**k-th voxel, as
``downsample="nearest"`` does); chunks never written read as the fill value 0.  The worker
times ``load`` + ``CoreView(box=1000³)`` + the first ``draw`` at 1024×768 (maps built from the
lazy store), then the same box in 512³ bricks, and an overview of
the whole core from the finest level with at most 512³ voxels (level 3, 325 × 325 × 370;
:func:`geoshade.core.bricks.render_overview`).

Writes ``RESULTS.md`` (between ``<!-- scale:begin -->`` and ``<!-- scale:end -->``) and
``results/scale.json``.  Run: ``geoshade bench scale [--quick | --full] [-o DIR]``.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np

PART = "scale"
MARK_BEGIN, MARK_END = "<!-- scale:begin -->", "<!-- scale:end -->"

sys.path.insert(0, str(Path(__file__).resolve().parent))  # harness.py, for workers too
import harness
from harness import peak_rss_mib as _peak_mib
from harness import status_kib as _kib

GIB = 2**30
MiB = 2**20
SIZES = {"quick": (0.25,), "default": (1, 2, 4, 8), "full": (1, 2, 4, 8, 16, 32)}
NX = NY = 1024
CHUNKS = (128, 128, 128)
PORE_LEVEL, GRAIN_LEVEL, THRESHOLD = 8000, 30000, 19000
PORE_CUT = np.float32(0.2)
RANGE = (0, THRESHOLD)
WORKER_TIMEOUT_S = 1800
BIG_SHAPE = (2600, 2600, 2960)  # x, y, z: 20.0 G voxels
BIG_BOX = (800, 800, 1000, 1000, 1000, 1000)
BIG_LEVELS = 5
BIG_FULL_LEVEL = 2  # levels from here on are written whole (the overview's), finer ones sparse
IMAGE = (1024, 768)


# ==============================================================================================
# the procedural volume
# ==============================================================================================
def _smooth(i: np.ndarray, seed: int, period: float) -> np.ndarray:
    """A smooth 1D signal at the integer positions ``i`` (sum of 3 sines), float32, ~ -1..1."""
    rng = np.random.default_rng(seed)
    x = np.asarray(i, dtype=np.float64)
    out = np.zeros(x.size)
    for k in range(3):  # three sines, not voxels
        f = (k + 1) * 2 * np.pi / period * rng.uniform(0.7, 1.3)
        out += np.sin(f * x + rng.uniform(0, 2 * np.pi)) / (k + 1)
    return (out / 1.8).astype(np.float32)


def ct_block(z0, z1, y0, y1, x0, x1, step: int = 1) -> np.ndarray:
    """uint16 values at level-0 positions ``(z, y, x) * step`` for the given index ranges.

    pore (8000) where ``sx·sy + sy'·sz + sz'·sx' > 0.2``, grain (30000) elsewhere, plus a
    position hash noise of about ±700; a pure function of the level-0 position.
    """
    zs, ys, xs = (np.arange(a, b, dtype=np.int64) * step for a, b in ((z0, z1), (y0, y1),
                                                                       (x0, x1)))
    sx, sx2 = _smooth(xs, 1, 61.0), _smooth(xs, 2, 83.0)
    sy, sy2 = _smooth(ys, 3, 71.0), _smooth(ys, 4, 53.0)
    sz, sz2 = _smooth(zs, 5, 67.0), _smooth(zs, 6, 97.0)
    out = np.empty((zs.size, ys.size, xs.size), np.uint16)
    _ct_kernel(zs, ys, xs, sx, sx2, sy, sy2, sz, sz2, out)
    return out


def _ct_kernel_py(zs, ys, xs, sx, sx2, sy, sy2, sz, sz2, out):
    f = sy[None, :, None] * sx[None, None, :]
    f = f + sy2[None, :, None] * sz[:, None, None]
    f = f + sz2[:, None, None] * sx2[None, None, :]
    val = np.where(f > PORE_CUT, np.int32(PORE_LEVEL), np.int32(GRAIN_LEVEL))
    h = (xs.astype(np.uint32)[None, None, :] * np.uint32(0x9E3779B1)
         + ys.astype(np.uint32)[None, :, None] * np.uint32(0x85EBCA77))
    h = h + zs.astype(np.uint32)[:, None, None] * np.uint32(0xC2B2AE3D)
    h ^= h >> np.uint32(15)
    h *= np.uint32(0x2C1B3C6D)
    h ^= h >> np.uint32(12)
    noise = (h & np.uint32(0x3FF)).astype(np.int32) + ((h >> np.uint32(20)) & np.uint32(0x3FF))
    out[...] = val + (noise - 1023) * 7 // 10


try:  # numba makes the generator ~30x faster; the numpy version gives the same values
    import numba

    @numba.njit(parallel=True)
    def _ct_kernel(zs, ys, xs, sx, sx2, sy, sy2, sz, sz2, out):  # pragma: no cover
        m32 = np.uint64(0xFFFFFFFF)
        for k in numba.prange(zs.size):  # uint64 arithmetic masked to 32 bits = uint32 wrap
            hz = (np.uint64(zs[k]) * np.uint64(0xC2B2AE3D)) & m32
            for j in range(ys.size):
                hy = (np.uint64(ys[j]) * np.uint64(0x85EBCA77)) & m32
                for i in range(xs.size):
                    f = (sy[j] * sx[i] + sy2[j] * sz[k]) + sz2[k] * sx2[i]
                    v = PORE_LEVEL if f > PORE_CUT else GRAIN_LEVEL
                    h = (((np.uint64(xs[i]) * np.uint64(0x9E3779B1)) & m32) + hy) & m32
                    h = (h + hz) & m32
                    h ^= h >> np.uint64(15)
                    h = (h * np.uint64(0x2C1B3C6D)) & m32
                    h ^= h >> np.uint64(12)
                    n = np.int64(h & np.uint64(0x3FF)) + np.int64((h >> np.uint64(20))
                                                                  & np.uint64(0x3FF))
                    out[k, j, i] = v + ((n - 1023) * 7) // 10
except ImportError:  # pragma: no cover
    _ct_kernel = _ct_kernel_py


def write_raw(path: Path, nz: int, slab: int = 32) -> float:
    """The (nz, NY, NX) volume as a raw file, written slab by slab; seconds."""
    t0 = time.perf_counter()
    with open(path, "wb") as f:
        for z in range(0, nz, slab):
            f.write(ct_block(z, min(nz, z + slab), 0, NY, 0, NX).tobytes())
    return time.perf_counter() - t0


def write_sparse_store(path: Path) -> dict:
    """The 20 G-voxel store, written only where the box (and the coarse levels) need it."""
    import zarr

    nx, ny, nz = BIG_SHAPE
    bx, by, bz, sx, sy, sz = BIG_BOX
    t0 = time.perf_counter()
    g = zarr.open_group(str(path), mode="w", zarr_format=3)
    shapes = [(nz, ny, nx)]
    for _ in range(BIG_LEVELS - 1):
        shapes.append(tuple(-(-n // 2) for n in shapes[-1]))
    written = []
    for k, shp in enumerate(shapes):
        ch = tuple(min(c, n) for c, n in zip(CHUNKS, shp, strict=True))
        a = g.create_array(str(k), shape=shp, chunks=ch, dtype="u2", fill_value=0,
                           dimension_names=("z", "y", "x"))
        a.attrs.update({"spacing": [float(2**k)] * 3, "origin": [0.0] * 3, "unit": "um",
                        "level": k})
        f = 2**k
        if k >= BIG_FULL_LEVEL:
            lo, hi = (0, 0, 0), shp
        else:  # the chunks over the box, in this level's voxels
            lo = tuple((o // f) // c * c for o, c in zip((bz, by, bx), ch, strict=True))
            hi = tuple(min(n, -(-((o + s) // f) // c) * c) for o, s, c, n in
                       zip((bz, by, bx), (sz, sy, sx), ch, shp, strict=True))
        for z in range(lo[0], hi[0], ch[0]):
            z1 = min(hi[0], z + ch[0])
            a[z:z1, lo[1]:hi[1], lo[2]:hi[2]] = ct_block(z, z1, lo[1], hi[1], lo[2], hi[2],
                                                         step=f)
        n_chunks = math.prod(-(-(h - l_) // c) for l_, h, c in zip(lo, hi, ch, strict=True))
        written.append({"level": k, "shape_zyx": list(shp), "chunks_written": n_chunks,
                        "chunks_total": math.prod(-(-n // c) for n, c in zip(shp, ch,
                                                                            strict=True))})
    from geoshade.io.stores.ome_zarr import multiscales_attrs

    g.attrs.update({"spacing": [1.0] * 3, "origin": [0.0] * 3, "unit": "um",
                    "value_range": [0, 65535], "axes": ["z", "y", "x"],
                    **multiscales_attrs("procedural", shapes, (1.0,) * 3, (0.0,) * 3, "um",
                                        "nearest"),
                    "ingest": {"complete": True, "version": 1, "source": "procedural (sparse)",
                               "levels": BIG_LEVELS, "chunks": list(CHUNKS),
                               "downsample": "nearest"}})
    return {"seconds": time.perf_counter() - t0, "levels": written,
            "disk_bytes": _du(path)}


def _du(path: Path) -> int:
    return sum(p.stat().st_size for p in Path(path).rglob("*") if p.is_file())


# ==============================================================================================
# worker side
# ==============================================================================================
class _AnonPeak:
    """Samples this process's anonymous resident memory (RssAnon) every 20 ms; ``peak`` MiB.

    VmHWM also counts the pages of mapped files (a raw file read through a memmap), which the
    kernel can drop at any time; RssAnon is the memory the process really holds.
    """

    def __init__(self):
        import threading

        self.peak = 0.0
        self._stop = threading.Event()
        self._t = threading.Thread(target=self._run, daemon=True)
        self._t.start()

    def _run(self):
        while not self._stop.is_set():
            self.peak = max(self.peak, (_kib("RssAnon") or 0) / 1024)
            self._stop.wait(0.02)

    def stop(self) -> float:
        self._stop.set()
        self._t.join()
        self.peak = max(self.peak, (_kib("RssAnon") or 0) / 1024)
        return self.peak


def _worker_peaks(client) -> list[float]:
    return sorted(v / 1024 for v in client.run(lambda: _kib("VmHWM") or 0).values())


def _warm() -> bool:
    import dask.array  # noqa: F401
    import zarr  # noqa: F401

    import geoshade.compute.voxels.lazy
    import geoshade.core
    import geoshade.io.stores.ingest  # noqa: F401

    return True


def _cluster(n: int, mem: str = "1GB"):
    """A LocalCluster of n worker processes (1 thread each), imports done before timing."""
    from distributed import Client, LocalCluster

    cl = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, memory_limit=mem,
                      dashboard_address=None, silence_logs=40)
    client = Client(cl)
    client.wait_for_workers(n)
    client.run(_warm)
    return cl, client


def worker_ingest(cfg: dict) -> dict:
    from geoshade.io.stores.ingest import ingest

    _warm()
    n = cfg.get("cluster")
    cl = client = None
    if n:
        cl, client = _cluster(n)
    t0 = time.perf_counter()
    rep = ingest(cfg["raw"], cfg["zarr"], chunks=CHUNKS, shape=cfg["shape"], dtype="uint16",
                 workers=cfg.get("workers", 1), scheduler=client, overwrite=True)
    sec = time.perf_counter() - t0
    out = {"seconds": sec, "voxels_per_s": math.prod(cfg["shape"]) / sec,
           "mib_per_s": rep.bytes_read / MiB / sec, "levels": len(rep.levels),
           "slabs": rep.slabs_written, "store_bytes": _du(Path(cfg["zarr"])),
           "peak_rss_mib": _peak_mib()}
    if client is not None:
        out["worker_peak_rss_mib"] = _worker_peaks(client)
        client.close()
        cl.close()
    return out


def worker_porosity(cfg: dict) -> dict:
    kind = cfg["how"]
    lo, hi = RANGE
    _warm()
    t0 = time.perf_counter()
    extra: dict = {}
    if kind in ("numpy", "porespy"):
        a = np.fromfile(cfg["raw"], np.uint16).reshape(cfg["shape"][::-1])
        extra["load_s"] = time.perf_counter() - t0
        t1 = time.perf_counter()
        sel = a >= lo
        sel &= a <= hi
        if kind == "numpy":
            counts = sel.sum(axis=(1, 2), dtype=np.int64)
        else:
            import porespy as ps

            prof = ps.metrics.porosity_profile(sel, axis=0)
            counts = np.rint(np.asarray(prof.porosity) * NX * NY).astype(np.int64)
            extra["porespy"] = ps.__version__
        extra["compute_s"] = time.perf_counter() - t1
    else:  # what `geoshade core porosity VOLUME --select LO HI [--scheduler S]` runs
        from geoshade.core import porosity
        from geoshade.io import load

        if kind == "memmap":  # no --scheduler: the slab loop over the raw file
            vol = load(cfg["raw"], shape=cfg["shape"], dtype="uint16")
            res = porosity(vol, (lo, hi), axis="z")
        elif kind == "slabs":  # no --scheduler: the slab loop over the store
            res = porosity(load(cfg["zarr"]), (lo, hi), axis="z")
        elif kind == "threads":  # --scheduler threads: dask tasks on local threads
            res = porosity(load(cfg["zarr"]), (lo, hi), axis="z", scheduler="threads")
        else:
            vol = load(cfg["zarr"])
            cl, client = _cluster(int(cfg["workers"]))
            t0 = time.perf_counter()  # the cluster's start is not the computation's
            res = porosity(vol, (lo, hi), axis="z", scheduler=client)
            extra["worker_peak_rss_mib"] = _worker_peaks(client)
            extra["workers_alive"] = len(client.nthreads())
            client.close()
            cl.close()
        counts = res.counts
        extra["sample"] = (res.sample or {}).get("status")
        assert res.total == math.prod(cfg["shape"]), "the sample detection left voxels out"
    sec = time.perf_counter() - t0
    n = math.prod(cfg["shape"])
    return {"seconds": sec, "voxels_per_s": n / sec, "count": int(np.sum(counts)),
            "counts_crc": int(np.bitwise_xor.reduce(np.asarray(counts, np.int64) * 2654435761
                                                   % 2**31)),
            "peak_rss_mib": _peak_mib(), **extra}


def worker_first_picture(cfg: dict) -> dict:
    import warnings

    warnings.simplefilter("ignore")
    import dask.array  # noqa: F401  (imports and the GL context are not the data path)
    import zarr  # noqa: F401

    from geoshade.core import CoreView, render_overview
    from geoshade.io import load
    from geoshade.render.context import get_context

    out: dict = {}
    t0 = time.perf_counter()
    get_context()
    out["context_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    vol = load(cfg["zarr"])
    t_open = time.perf_counter() - t0
    v = CoreView(vol, select=RANGE, box=list(BIG_BOX), size=IMAGE, bricks=cfg.get("bricks"))
    img, st = v.draw(frames=1, count=False)
    out["first_picture_s"] = time.perf_counter() - t0
    out.update(open_s=t_open, prepare_ms=st["prepare_ms"], upload_ms=st["upload_ms"],
               first_frame_ms=st["first_frame_ms"], gpu_bytes=st["gpu_bytes"],
               voxels_selected=st["voxels_selected"], method=st["method"],
               bricks=st.get("bricks"), brick_mode=st.get("brick_mode"),
               coverage=float(np.mean(np.any(img[..., :3] != 255, axis=-1))))
    v.release()
    if cfg.get("overview"):
        t1 = time.perf_counter()
        img, st = render_overview(cfg["zarr"], select=RANGE, size=IMAGE, frames=1, count=False)
        out["overview"] = {"seconds": time.perf_counter() - t1, "level": st["level"],
                           "level_shape_xyz": st["level_shape_xyz"],
                           "gpu_bytes": st["gpu_bytes"], "first_frame_ms": st["first_frame_ms"]}
    out["peak_rss_mib"] = _peak_mib()
    return out


WORKERS = {"ingest": worker_ingest, "porosity": worker_porosity,
           "picture": worker_first_picture}


def worker_main(config_json: str) -> int:
    cfg = json.loads(config_json)
    try:
        anon = _AnonPeak()
        out = {"ok": True, **WORKERS[cfg["kind"]](cfg)}
        out["peak_anon_mib"] = anon.stop()
    except Exception as exc:
        out = {"ok": False, "error": f"{type(exc).__name__}: {exc}",
               "traceback": traceback.format_exc()[-2000:]}
    sys.stdout.write("\n" + json.dumps(out) + "\n")
    return 0


# ==============================================================================================
# parent side
# ==============================================================================================
def run_worker(cfg: dict) -> dict:
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", json.dumps(cfg)]
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=WORKER_TIMEOUT_S,
                           stdin=subprocess.DEVNULL)
        lines = [ln for ln in p.stdout.splitlines() if ln.startswith("{")]
        res = json.loads(lines[-1]) if lines else {
            "ok": False, "error": f"exit {p.returncode}: "
            f"{(p.stderr.strip().splitlines() or ['no output'])[-1]}"}
    except subprocess.TimeoutExpired:
        res = {"ok": False, "error": f"timed out after {WORKER_TIMEOUT_S} s"}
    res["elapsed_s"] = time.perf_counter() - t0
    res["load_avg_1min"] = os.getloadavg()[0]
    return res


def _mem_available() -> int:
    return (_kib("MemAvailable", "/proc/meminfo") or 0) * 1024


def _log(msg: str) -> None:
    print(f"[bench scale] {msg}", file=sys.stderr, flush=True)


def machine_info() -> dict:
    import dask
    import distributed
    import zarr

    info = {"cpu": platform.processor() or platform.machine(),
            "cores": len(os.sched_getaffinity(0)), "ram_bytes": (_kib("MemTotal",
                                                                      "/proc/meminfo") or 0)
            * 1024, "python": platform.python_version(), "numpy": np.__version__,
            "dask": dask.__version__, "distributed": distributed.__version__,
            "zarr": zarr.__version__,
            "date": _dt.datetime.now().astimezone().isoformat(timespec="seconds")}
    try:
        import porespy

        info["porespy"] = porespy.__version__
    except ImportError:
        info["porespy"] = None
    try:
        from geoshade.render.context import get_context

        info["gl_renderer"] = get_context().info.get("GL_RENDERER")
    except Exception as exc:
        info["gl_renderer"] = f"unavailable ({exc})"
    return info


def run_sizes(sizes, tmp: Path, porespy_ok: bool) -> list[dict]:
    rows = []
    scaling_size = 2 if 2 in sizes else sizes[0]
    for gib in sizes:
        nz = round(gib * GIB / (NX * NY * 2))
        shape = [NX, NY, nz]
        raw, store = tmp / f"v{gib}.raw", tmp / f"v{gib}.zarr"
        free = shutil.disk_usage(tmp).free
        if free < 2.3 * gib * GIB:
            rows.append({"gib": gib, "what": "all", "ok": False,
                         "error": f"skipped: {free / GIB:.1f} GiB free on disk"})
            continue
        gen_s = write_raw(raw, nz)
        _log(f"{gib} GiB: raw written in {gen_s:.1f} s")
        base = {"raw": str(raw), "zarr": str(store), "shape": shape}
        ingests = [("2 threads", {"workers": 2})]
        if gib == scaling_size:
            ingests = [("1 thread", {"workers": 1}), ("2 threads", {"workers": 2}),
                       ("4 processes (LocalCluster)", {"cluster": 4})]
        for label, kw in ingests:
            r = run_worker({**base, "kind": "ingest", **kw})
            rows.append({"gib": gib, "what": "ingest", "how": label, **r})
            _log(f"  ingest {label}: {r.get('seconds', float('nan')):.1f} s "
                 f"{r.get('error', '')}")
        fits = 2.5 * gib * GIB <= 0.5 * _mem_available()
        configs = [("dask threads (--scheduler threads)", {"how": "threads"}),
                   ("geoshade slabs, zarr store (no --scheduler)", {"how": "slabs"}),
                   ("LocalCluster 1 worker", {"how": "cluster", "workers": 1}),
                   ("LocalCluster 2 workers", {"how": "cluster", "workers": 2}),
                   ("LocalCluster 4 workers (simulated)", {"how": "cluster", "workers": 4}),
                   ("geoshade slabs, raw memmap", {"how": "memmap"})]
        if fits:
            configs.append(("numpy in memory", {"how": "numpy"}))
            if porespy_ok:
                configs.append(("PoreSpy porosity_profile", {"how": "porespy"}))
        for label, kw in configs:
            r = run_worker({**base, "kind": "porosity", **kw})
            rows.append({"gib": gib, "what": "porosity", "how": label, **r})
            _log(f"  porosity {label}: {r.get('seconds', float('nan')):.1f} s "
                 f"{r.get('error', '')}")
        if not fits:
            rows.append({"gib": gib, "what": "porosity", "how": "numpy / PoreSpy", "ok": False,
                         "error": "skipped: does not fit (2.5 × size > half the free memory)"})
        shutil.rmtree(store, ignore_errors=True)
        raw.unlink(missing_ok=True)
    return rows


def check_counts(rows) -> None:
    """Mark each porosity row with whether it agrees with the reference of its size."""
    for gib in {r["gib"] for r in rows}:
        rs = [r for r in rows if r["gib"] == gib and r["what"] == "porosity" and r.get("ok")]
        ref = next((r for r in rs if r["how"] == "numpy in memory"), None) or \
            next((r for r in rs if r["how"].startswith("dask threads")), None)
        for r in rs:
            r["agrees"] = ref is not None and r["count"] == ref["count"] and \
                r["counts_crc"] == ref["counts_crc"]
            r["reference"] = ref["how"] if ref else None


def markdown(res: dict) -> str:
    m = res["machine"]
    lines = [MARK_BEGIN, "## scale — whole cores beyond memory (`geoshade bench scale`)", "",
             f"- date: {m['date']}; command: `{res['command']}`; total {res['elapsed_s'] / 60:.1f}"
             " min",
             f"- machine: {m['cpu']}, {m['cores']} cores usable, {m['ram_bytes'] / GIB:.1f} GiB "
             f"RAM, shared with other engineers (load average {res['load_avg'][0]:.1f} at the "
             f"start); disk: {res['disk_free_gib']:.0f} GiB free under {res['tmp']}",
             f"- Python {m['python']}, numpy {m['numpy']}, dask/distributed {m['dask']}, zarr "
             f"{m['zarr']}, PoreSpy {m['porespy'] or 'not installed'}; GL: {m['gl_renderer']}",
             f"- volumes: {NX}×{NY}×nz uint16 from `ct_block` (procedural CT-like: two grey "
             f"levels, pores ≈ {res.get('porosity', float('nan')):.3f}), range [{RANGE[0]}, "
             f"{RANGE[1]}], profile along z; chunks 128³ zstd; each row its own process "
             "(peak RSS = its VmHWM, which counts the pages of a memory-mapped file; in "
             "brackets the peak of its anonymous memory, RssAnon sampled every 20 ms; cluster "
             "rows list the workers' VmHWM; load = 1-min load average at the row's end)",
             "- the raw file was just written, so the page cache may hold part of it "
             "(throughput of ingest/memmap rows is then above what a cold disk gives)", "",
             "| size | step | how | seconds | M voxels/s | MiB/s | peak RSS MiB (anon) | workers' "
             "peak RSS MiB | load | result |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in res["rows"]:
        size = f"{r['gib']:g} GiB"
        if not r.get("ok"):
            lines.append(f"| {size} | {r['what']} | {r.get('how', '')} | — | — | — | — | — | — "
                         f"| {r.get('error', 'failed')} |")
            continue
        mvps = r["voxels_per_s"] / 1e6
        mibs = mvps * 1e6 * 2 / MiB
        wk = r.get("worker_peak_rss_mib")
        wks = "—" if not wk else f"{' + '.join(f'{v:.0f}' for v in wk)}"
        if r["what"] == "ingest":
            result = (f"{r['levels']} levels, store {r['store_bytes'] / GIB:.2f} GiB "
                      f"({r['gib'] * GIB / max(r['store_bytes'], 1):.2f}× smaller)")
        else:
            result = "same counts" if r.get("agrees") else f"DIFFERS from {r.get('reference')}"
            if r["how"] == r.get("reference"):
                result = "reference"
            if "load_s" in r:
                result += f"; load {r['load_s']:.1f} s + compute {r['compute_s']:.1f} s"
        lines.append(f"| {size} | {r['what']} | {r['how']} | {r['seconds']:.1f} | {mvps:.0f} | "
                     f"{mibs:.0f} | {r['peak_rss_mib']:.0f} ({r.get('peak_anon_mib', 0):.0f}) | "
                     f"{wks} | {r.get('load_avg_1min', 0):.1f} | {result} |")
    pic = res.get("picture") or {}
    lines += ["", "Time to the first picture of a 1000³ box (offset 800, 800, 1000) from a "
              f"{math.prod(BIG_SHAPE) / 1e9:.1f} G-voxel store ({BIG_SHAPE[0]}×{BIG_SHAPE[1]}×"
              f"{BIG_SHAPE[2]} uint16, 1024×768):", ""]
    st = res.get("big_store") or {}
    if st:
        lv = "; ".join(f"level {d['level']}: {d['chunks_written']:,} of {d['chunks_total']:,} "
                       "chunks" for d in st["levels"])
        lines.append(f"- store written sparsely in {st['seconds']:.0f} s "
                     f"({st['disk_bytes'] / GIB:.2f} GiB on disk): {lv}; unwritten chunks read "
                     "as 0 (see the docstring of `benchmarks/bench_scale.py`)")
    lines += ["", "| render | first picture s | open s | maps (prepare) s | upload s | first frame"
              " s | GPU MiB | voxels selected | peak RSS MiB (anon) |",
              "|---|---|---|---|---|---|---|---|---|"]
    for label, r in pic.items():
        if not r.get("ok"):
            lines.append(f"| {label} | {r.get('error')} | | | | | | | |")
            continue
        lines.append(f"| {label} | {r['first_picture_s']:.1f} | {r['open_s']:.2f} | "
                     f"{r['prepare_ms'] / 1e3:.1f} | {r['upload_ms'] / 1e3:.2f} | "
                     f"{r['first_frame_ms'] / 1e3:.2f} | {r['gpu_bytes'] / MiB:.0f} | "
                     f"{r['voxels_selected']:,} | {r['peak_rss_mib']:.0f} "
                     f"({r.get('peak_anon_mib', 0):.0f}) |")
        ov = r.get("overview")
        if ov:
            lines.append(f"| overview: whole core from level {ov['level']} "
                         f"({'×'.join(map(str, ov['level_shape_xyz']))}) | {ov['seconds']:.1f} |"
                         f" | | | {ov['first_frame_ms'] / 1e3:.2f} | {ov['gpu_bytes'] / MiB:.0f}"
                         " | | |")
    fit = res.get("fits") or {}
    if fit:
        lines += ["", f"How large a box fits: 3D-texture limit {fit['tex_limit']} per axis; "
                  f"raycast ≈ {fit['bytes_per_voxel']:.3f} B/voxel. Unbricked: up to "
                  f"{fit['unbricked']}³; resident bricks within "
                  f"{fit['budget_gib']:.1f} GiB: up to {fit['resident_bricks']}³; streamed "
                  "bricks: any size (one brick on the GPU at a time). On an 11 GiB GTX 1080 Ti: "
                  f"unbricked {fit['gtx_unbricked']}³, resident bricks {fit['gtx_resident']}³."]
    lines += ["", MARK_END]
    return "\n".join(lines)


def main(args, folder: Path) -> int:
    from geoshade.compute.voxels.bitmaps import gpu_bytes_estimate
    from geoshade.compute.voxels.bricks import largest_box
    from geoshade.io.output import write_json
    from geoshade.render.visuals.bricked.visual import gpu_budget

    t_start = time.perf_counter()
    out_dir = Path(args.output) if getattr(args, "output", None) else Path(folder)
    (out_dir / "results").mkdir(parents=True, exist_ok=True)
    mode = "quick" if args.quick else "full" if args.full else "default"
    tmp = Path(tempfile.mkdtemp(prefix="geoshade-bench-scale-"))
    free = shutil.disk_usage(tmp).free
    sizes = [s for s in SIZES[mode] if 2.3 * s * GIB <= 0.8 * free] or [SIZES["quick"][0]]
    machine = machine_info()
    porespy_ok = machine["porespy"] is not None
    _log(f"sizes {sizes} GiB, {free / GIB:.0f} GiB free in {tmp}")
    res = {"part": PART, "mode": mode, "command": "geoshade bench scale"
           + (" --" + mode if mode != "default" else ""), "machine": machine,
           "load_avg": list(os.getloadavg()), "tmp": str(tmp), "disk_free_gib": free / GIB,
           "sizes_gib": sizes, "range": list(RANGE), "chunks": list(CHUNKS)}
    try:
        sample = ct_block(0, 64, 0, NY, 0, NX)
        res["porosity"] = float(np.mean(sample <= RANGE[1]))
        res["rows"] = run_sizes(sizes, tmp, porespy_ok)
        check_counts(res["rows"])
        if mode != "quick":
            _log("writing the sparse 20 G-voxel store ...")
            big = tmp / "big.zarr"
            res["big_store"] = write_sparse_store(big)
            _log(f"  written in {res['big_store']['seconds']:.0f} s; first pictures ...")
            res["picture"] = {
                "auto (raycast), unbricked": run_worker({"kind": "picture", "zarr": str(big),
                                                         "overview": True}),
                "raycast in 512³ bricks (8, resident)": run_worker(
                    {"kind": "picture", "zarr": str(big), "bricks": 512}),
            }
            shutil.rmtree(big, ignore_errors=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    try:
        from geoshade.render.context import get_context

        budget = gpu_budget(get_context())
    except Exception:
        budget = None
    fit = largest_box("raycast", budget, 2048)
    gtx = largest_box("raycast", 11 * GIB, 2048)
    res["fits"] = {"tex_limit": 2048, "budget_gib": (budget or 0) / GIB,
                   "bytes_per_voxel": gpu_bytes_estimate((1000, 1000, 1000), "raycast") / 1e9,
                   "unbricked": fit["unbricked"], "resident_bricks": fit["resident_bricks"],
                   "gtx_unbricked": gtx["unbricked"], "gtx_resident": gtx["resident_bricks"]}
    res["elapsed_s"] = time.perf_counter() - t_start
    md = markdown(res)
    print(md)
    write_json(out_dir / "results" / "scale.json", res)
    res_md = harness.write_results(out_dir, "scale", md, out_dir / "results" / "scale.json")
    _log(f"wrote {res_md} and {out_dir / 'results' / 'scale.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(harness.script_main(worker_main, "scale"))
