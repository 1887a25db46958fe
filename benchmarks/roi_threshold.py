"""Regions of interest and suggested thresholds on a core scanned in air, beside numpy and
scikit-image (issue 15).

A procedural uint16 core (a smoothed random field split into grains and pores, a cylinder of it
in dark air) is written as a raw file and opened as a memory map, as a user's scan is. Rows:

- Otsu: geoshade's streamed histogram + ``threshold_otsu(hist=...)`` over the whole volume and
  inside the fitted cylinder, beside ``skimage.filters.threshold_otsu`` on the array in memory
  (equal values are checked);
- porosity of the whole box, and inside the cylinder ROI, beside numpy with the same mask;
- the cylinder fit (8 slices): time and the error of its centre and radius.

Not a test: it prints a Markdown table and writes ``results/roi_threshold.json``.
Run: ``python benchmarks/roi_threshold.py [N]`` (N³ voxels, default 256).
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def procedural_core(n: int, seed: int = 0):
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    field = ndimage.gaussian_filter(rng.standard_normal((n, n, n), np.float32), 2.5)
    a = np.where(field > np.quantile(field[::4, ::4, ::4], 0.2), 30000, 9000).astype(np.uint16)
    a += rng.integers(0, 1500, a.shape, dtype=np.uint16)
    cx, cy, r = n / 2 + 3.5, n / 2 - 2.0, 0.4 * n
    y, x = np.mgrid[0:n, 0:n] + 0.5
    inside = (x - cx) ** 2 + (y - cy) ** 2 <= r * r
    a[:, ~inside] = 2000 + rng.integers(0, 500, (int((~inside).sum()),), dtype=np.uint16)
    return a, (cx, cy, r), inside


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def main(n: int = 256) -> dict:
    from skimage.filters import threshold_otsu

    import geoshade
    from geoshade.compute.voxels.roi import fit_cylinder

    a, (cx, cy, r), inside = procedural_core(n)
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "core.raw"
        a.tofile(f)
        vol = geoshade.load(f, dtype="uint16", spacing=(2.5, 2.5, 2.5), unit="um")
        rows = []
        cyl, t_fit = timed(lambda: fit_cylinder(vol.data))
        rows.append(("fit cylinder (8 slices)", t_fit, None,
                     f"centre off by {np.hypot(cyl.cx - cx, cyl.cy - cy):.3f}, radius off by "
                     f"{cyl.r - r:+.3f} voxels"))
        t_g, s_g = timed(lambda: geoshade.core.thresholds(vol))
        ref, s_ref = timed(lambda: threshold_otsu(a))
        rows.append(("Otsu, whole volume", s_g, s_ref,
                     f"{t_g.otsu:g} vs scikit-image {ref:g}: "
                     f"{'equal' if t_g.otsu == float(ref) else 'DIFFERENT'}"))
        mask = np.broadcast_to(inside, a.shape)
        t_c, s_c = timed(lambda: geoshade.core.thresholds(vol, roi=cyl))
        ins = np.broadcast_to((np.mgrid[0:n, 0:n][1] + 0.5 - cyl.cx) ** 2
                              + (np.mgrid[0:n, 0:n][0] + 0.5 - cyl.cy) ** 2 <= cyl.r**2,
                              a.shape)
        ref_c, s_refc = timed(lambda: threshold_otsu(a[ins]))
        rows.append(("Otsu, inside the fitted cylinder", s_c, s_refc,
                     f"{t_c.otsu:g} vs scikit-image {ref_c:g}: "
                     f"{'equal' if t_c.otsu == float(ref_c) else 'DIFFERENT'}"))
        lo, hi = 0, t_c.otsu
        p_all, s_all = timed(lambda: geoshade.core.porosity(vol, (lo, hi)))
        np_all, s_np_all = timed(lambda: float(((a >= lo) & (a <= hi)).mean()))
        rows.append(("porosity, whole box", s_all, s_np_all,
                     f"{p_all.porosity:.4f} (numpy {np_all:.4f}; the air counted)"))
        p_roi, s_roi = timed(lambda: geoshade.core.porosity(vol, (lo, hi), roi=cyl))
        np_roi, s_np_roi = timed(lambda: float(((a <= hi) & ins).sum() / ins.sum()))
        rows.append(("porosity, cylinder ROI", s_roi, s_np_roi,
                     f"{p_roi.porosity:.4f} (numpy {np_roi:.4f}; true pore share "
                     f"{float(((a < 20000) & mask).sum() / mask.sum()):.4f})"))
    print(f"{n}³ uint16 ({a.nbytes / 2**20:.0f} MiB), memory-mapped raw file\n")
    print("| step | geoshade s | numpy / scikit-image s (in memory) | result |")
    print("|---|---|---|---|")
    for name, s, ref_s, note in rows:
        print(f"| {name} | {s:.3f} | {'-' if ref_s is None else f'{ref_s:.3f}'} | {note} |")
    out = {"n": n, "rows": [{"step": a_, "seconds": b, "reference_seconds": c, "result": d_}
                            for a_, b, c, d_ in rows]}
    res = Path(__file__).resolve().parent / "results"
    res.mkdir(exist_ok=True)
    (res / "roi_threshold.json").write_text(json.dumps(out, indent=2))
    return out


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 256)
