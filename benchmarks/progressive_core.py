"""A picture at once from a 50 G-voxel core store (issue 26, target 4): time to the coarse
preview (target <= 5 s) and to the full picture, with ``CoreView(progressive=True)``.

The store is written as ``bench_scale.write_sparse_store`` writes its 20 G-voxel one, only
larger: 3700 × 3700 × 3660 uint16 (50.1 G voxels, 100 GB if dense), 6 levels; levels 0-2 hold
only the 128³ chunks over the box [1400, 1400, 1300] + 1000³, levels 3-5 are written whole;
unwritten chunks read as 0 (below the selection, so they draw nothing).  Each measurement runs
in a fresh process (imports and the GL context timed apart, as in bench_scale):

- box: ``load`` + ``CoreView(box=1000³, progressive=True)`` + ``draw`` (the preview), then
  ``refine`` + ``draw`` (the full picture); and the plain View (no preview) for comparison;
- whole core: the preview of the whole 50 G-voxel box (its full picture would build bit maps
  of 50 G voxels: not run here).

Run: ``python benchmarks/progressive_core.py [--keep] [-o DIR]`` (writes ``progressive.json``
and the pictures into DIR, default /tmp/progressive_core; the store in /tmp, removed at the
end unless ``--keep``).
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_scale as bs

SHAPE = (3700, 3700, 3660)          # x, y, z: 50.1 G voxels
BOX = (1400, 1400, 1300, 1000, 1000, 1000)
SELECT = (1, bs.THRESHOLD)          # pores and grains below the threshold; 0 (unwritten) not
IMAGE = (1024, 768)


def configure() -> None:
    bs.BIG_SHAPE, bs.BIG_BOX, bs.BIG_LEVELS, bs.BIG_FULL_LEVEL = SHAPE, BOX, 6, 3


def worker(store: str, case: str, out_dir: str) -> dict:
    """One measurement in this (fresh) process."""
    import numpy as np

    from geoshade.core import CoreView
    from geoshade.io import load
    from geoshade.io.output import write_png
    from geoshade.render.context import get_context

    res: dict = {"case": case}
    t0 = time.perf_counter()
    get_context()
    res["context_s"] = round(time.perf_counter() - t0, 3)
    t0 = time.perf_counter()
    vol = load(store)
    box = list(BOX) if case.startswith("box") else None
    progressive = case != "box-plain"
    view = CoreView(vol, select=SELECT, box=box, size=IMAGE, progressive=progressive,
                    annotations=True)
    res["open_s"] = round(time.perf_counter() - t0, 3)
    img, st = view.draw(frames=1, count=False)
    first = time.perf_counter() - t0
    res.update(first_picture_s=round(first, 3), coarse=bool(st.get("coarse")),
               level=st.get("level"), gpu_bytes=st["gpu_bytes"],
               voxels_selected=st["voxels_selected"],
               coverage=round(float(np.mean(np.any(img[..., :3] != 255, axis=-1))), 4))
    write_png(Path(out_dir) / f"{case}-first.png", img)
    if progressive and case == "box":
        view.refine()
        img, st = view.draw(frames=1, count=False)
        res.update(full_picture_s=round(time.perf_counter() - t0, 3),
                   full_voxels_selected=st["voxels_selected"], full_gpu_bytes=st["gpu_bytes"])
        write_png(Path(out_dir) / f"{case}-full.png", img)
    view.release()
    res["peak_rss_mib"] = round(bs._peak_mib(), 1)
    return res


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("-o", "--out", default="/tmp/progressive_core")
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--worker", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args()
    configure()
    if args.worker:
        print(json.dumps(worker(*args.worker)))
        return 0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    store = Path("/tmp/progressive_core_50g.zarr")
    shutil.rmtree(store, ignore_errors=True)
    results: dict = {"shape_xyz": SHAPE, "box": BOX, "select": SELECT, "image": IMAGE}
    try:
        results["store"] = bs.write_sparse_store(store)
        print(f"store written in {results['store']['seconds']:.0f} s", flush=True)
        rows = []
        for case in ("box", "box-plain", "whole"):
            p = subprocess.run([sys.executable, __file__, "--worker", str(store), case,
                                str(out)], capture_output=True, text=True, timeout=1800)
            if p.returncode:
                print(p.stderr[-3000:])
                return 1
            rows.append(json.loads(p.stdout.strip().splitlines()[-1]))
            print(json.dumps(rows[-1]), flush=True)
        results["rows"] = rows
    finally:
        if not args.keep:
            shutil.rmtree(store, ignore_errors=True)
    (out / "progressive.json").write_text(json.dumps(results, indent=1))
    print("| case | first picture s | coarse level | full picture s | voxels (first / full) "
          "| peak RSS MiB |")
    print("|---|---|---|---|---|---|")
    for r in results["rows"]:
        print(f"| {r['case']} | {r['first_picture_s']:.1f} | {r.get('level') or '—'} | "
              f"{r.get('full_picture_s', '—')} | {r['voxels_selected']:,} / "
              f"{r.get('full_voxels_selected', '—')} | {r['peak_rss_mib']} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
