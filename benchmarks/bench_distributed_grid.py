"""``geoshade bench distributed``, the grid half: a grid store drawn on 1 and 2 dask workers
beside one process.

Each size (``--quick``: 1000×1000×8; default: 1000×1000×40; ``--full``: 1000×1000×100 = 1e8
cells) is written as a grid store by ``grid_store_case.write_store_case`` (two faults, inactive
blobs, PORO/PERMX, SWAT at two steps; written chunk by chunk, independent of geoshade's readers)
and drawn with PORO, faults highlighted, at the bench size:

- one process: :class:`~geoshade.grid.GridView` on the store (faces chunk by chunk on dask
  threads, then drawn), first picture, an orbit of frames, a property switch and a filter;
- a LocalCluster of 1 and 2 worker processes (1 thread each):
  ``GridView(..., distributed=True)`` (the cluster faces backend) — each worker computes and
  draws its layer ranges; the same orbit, checked pixel for pixel against one process, with the
  bytes moved per frame, the slowest worker and the compositing time, then the same switches.

``run(mode, size, tmp) -> rows`` and ``markdown(rows, size) -> lines`` are called by
``bench_distributed.main``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

DIMS = {"quick": [(1000, 1000, 8)], "default": [(1000, 1000, 40)],
        "full": [(1000, 1000, 40), (1000, 1000, 100)]}
AZIMUTHS = (30.0, 75.0, 120.0, 165.0)
OPTIONS = {"property": "PORO", "faults": "highlight", "exaggeration": 5.0, "annotations": False}
FILTER = "PERMX > 100"


def _log(msg: str) -> None:
    print(f"[bench distributed grid] {msg}", file=sys.stderr, flush=True)


def make_store(dims, tmp: Path):
    from grid_store_case import write_store_case

    from geoshade.io.stores.grid_store import open_grid_store

    path = tmp / f"grid{'x'.join(map(str, dims))}.zarr"
    write_store_case(path, *dims, steps=2, chunks=(250, 250, 20))
    return open_grid_store(path)


def _session(view, size) -> dict:
    """An orbit of plain frames, a property switch and a filter, each to its next picture."""
    cams = [view.camera("iso", azimuth=a, elevation=30.0) for a in AZIMUTHS]
    view.draw(cams[0], frames=1, count=False)   # warm-up (shaders)
    imgs, ms, frames = [], [], []
    for cam in cams:
        t0 = time.perf_counter()
        img, st = view.draw(cam, frames=1, count=False)
        ms.append((time.perf_counter() - t0) * 1000)
        imgs.append(img)
        frames.append(st.get("distributed"))
    out: dict = {"frame_ms": float(np.median(ms)), "frames_ms": ms, "faces": st["faces"],
                 "gpu_bytes": st["gpu_bytes"]}
    t0 = time.perf_counter()
    view.update(property="PERMX")
    view.draw(cams[0], frames=1, count=False)
    out["property_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    view.update(filter=FILTER)
    img, st = view.draw(cams[0], frames=1, count=False)
    out["filter_s"] = time.perf_counter() - t0
    out["filter_faces"] = st["faces"]
    imgs.append(img)
    if frames[0] is not None:
        def med(key):
            return float(np.median([f[key] for f in frames]))

        out.update(bytes_per_frame=med("bytes_moved"), request_bytes=med("request_bytes"),
                   slowest_worker_ms=med("slowest_worker_ms"), composite_ms=med("composite_ms"),
                   round_trip_ms=med("round_trip_ms"),
                   parts_per_worker=list(frames[0]["bricks_per_worker"].values()),
                   parts=frames[0]["parts"],
                   worker_gpu_bytes=list(st["distributed"]["worker_gpu_bytes"].values()))
    return out, imgs


def run_single(grid, size) -> tuple[dict, list]:
    from geoshade.grid import GridView

    t0 = time.perf_counter()
    with GridView(grid, size=size, **OPTIONS) as v:
        first = time.perf_counter() - t0
        res, imgs = _session(v, size)
    return {"how": "one process", "workers": 0, "first_s": first, **res}, imgs


def run_cluster(grid, size, n_workers: int, ref_imgs) -> dict:
    from distributed import Client, LocalCluster

    from geoshade.grid import GridView

    cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=50)
    client = Client(cluster, set_as_default=False)
    try:
        t0 = time.perf_counter()
        with GridView(grid, distributed=True, scheduler=client, size=size, **OPTIONS) as v:
            first = time.perf_counter() - t0
            res, imgs = _session(v, size)
    finally:
        client.close()
        cluster.close()
    equal = all(np.array_equal(a, b) for a, b in zip(imgs, ref_imgs, strict=True))
    return {"how": f"LocalCluster {n_workers}×1 thread", "workers": n_workers,
            "first_s": first, "equal": equal, **res}


def run(mode: str, size, tmp: Path) -> list[dict]:
    import shutil

    rows = []
    for dims in DIMS[mode]:
        cells = int(np.prod(dims))
        _log(f"{dims}: writing the store")
        t0 = time.perf_counter()
        grid = make_store(dims, tmp)
        write_s = time.perf_counter() - t0
        _log(f"{dims}: one process")
        single, imgs = run_single(grid, size)
        rows.append({"dims": list(dims), "cells": cells, "write_s": write_s, **single})
        for nw in (1, 2):
            _log(f"{dims}: {nw} worker(s)")
            rows.append({"dims": list(dims), "cells": cells,
                         **run_cluster(grid, size, nw, imgs)})
            _log(f"  first {rows[-1]['first_s']:.1f} s, {rows[-1]['frame_ms']:.0f} ms/frame, "
                 f"equal {rows[-1]['equal']}")
        shutil.rmtree(grid.meta["store"], ignore_errors=True)
    return rows


def markdown(rows: list[dict], size) -> list[str]:
    lines = ["", "### A grid store drawn on dask workers", "",
             f"Grid stores written by `benchmarks/grid_store_case.py` (two faults, 5 % inactive "
             f"blobs; chunks 250×250×20), PORO with faults highlighted, exaggeration 5, "
             f"{size[0]}×{size[1]}: the first picture (faces computed: by one process on dask "
             f"threads, or by each worker for its layer ranges), the median plain frame of an "
             f"orbit of {len(AZIMUTHS)} cameras, a property switch (PORO → PERMX) and a filter "
             f"(`{FILTER}`) to their next picture. 'equal': every picture of the cluster equals "
             f"one process's, pixel for pixel.", "",
             "| cells | how | first picture s | frame ms | bytes/frame | slowest worker ms | "
             "composite ms | property s | filter s | faces | parts/worker | equal |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        dist = r["workers"] > 0
        lines.append(
            f"| {r['cells']:.0e} | {r['how']} | {r['first_s']:.1f} | {r['frame_ms']:.0f} | "
            + (f"{r['bytes_per_frame'] / 2**20:.2f} MiB | {r['slowest_worker_ms']:.0f} | "
               f"{r['composite_ms']:.1f} | " if dist else "— | — | — | ")
            + f"{r['property_s']:.1f} | {r['filter_s']:.1f} | {r['faces']:,} → "
            f"{r['filter_faces']:,} | "
            + (f"{'/'.join(map(str, r['parts_per_worker']))} | {'yes' if r['equal'] else 'NO'} |"
               if dist else "— | (reference) |"))
    lines += ["", "Reading: the parts are layer ranges across the whole grid, so each worker's "
              "tile covers most of the picture (bytes per frame ≈ workers × picture × 10 "
              "bytes); on this 2-core machine the workers share the client's cores, so the "
              "cluster shows that the faces are computed and drawn where the parts live and "
              "the picture is exact, not a speed-up (each worker would have its own GPU)."]
    return lines


__all__ = ["markdown", "run"]
