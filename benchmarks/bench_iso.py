"""``geoshade bench iso``: tessellation marching cubes against VTK flying edges, side by side.

For synthetic displacement fields (:func:`geoshade.compute.mesh.displacement.displacement_field`,
3 time steps, level S* = 0.5) of 100³ and 256³ nodes (64³ with ``--quick``, also 512³ with
``--full``) at 3840×2160 and 1920×1080, each config runs in its own subprocess so that the peak
RSS of a row is that row's alone:

- geoshade ``default`` (what ``geoshade iso`` uses): patch level 8, per-patch min/max skipping,
  patch slices stacked along the axis that leaves the fewest cells to march; and ``paper``:
  patch level 64, no skipping, slices along z (the paper's method as printed);
- VTK: ``vtkFlyingEdges3D`` (normals on) → ``vtkPolyDataMapper`` → offscreen render window
  (EGL through PyVista's ``Plotter``, MSAA off).

Per row: first frame, re-render (median; geoshade's default re-draws the triangles it captured
when it marched the step, the paper's method marches every frame, VTK draws its stored mesh),
step switch (geoshade: swap to the step prepared ahead + one frame, and a cold switch that
reads, prepares and uploads; VTK: new scalars → flying edges → upload → one frame), GPU bytes
(geoshade, exact), triangles (both counted by the producer: a primitives query / the polydata),
and peak RSS. Writes ``RESULTS.md`` (iso section), ``results/iso.json`` and prints the table.

A worker alone: ``python benchmarks/bench_iso.py --worker '{"kind": "geoshade", ...}'``.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

PART = "iso"
MARK_BEGIN, MARK_END = "<!-- iso:begin -->", "<!-- iso:end -->"

sys.path.insert(0, str(Path(__file__).resolve().parent))  # harness.py, for workers too
import harness
from harness import peak_rss_mib as _peak_rss_mib
from harness import status_kib


def _mark(marks: dict, name: str) -> None:
    """The process's RSS now (MiB) under ``name``: where the peak goes, stage by stage."""
    marks[name] = (status_kib("VmRSS") or 0) / 1024

SIZES = {"quick": (64,), "default": (100, 256), "full": (100, 256, 512)}
IMAGES = ((3840, 2160), (1920, 1080))
LEVEL, STEPS, SEED = 0.5, 3, 0
METHODS = {"default": {"patch_level": 8, "skip_patches": True, "slice_axis": "auto",
                       "mesh_cache": True},
           "paper": {"patch_level": 64, "skip_patches": False, "slice_axis": "z",
                     "mesh_cache": False}}
WORKER_TIMEOUT_S = 1200
#: runs of every config (each its own process) unless ``--repeats`` says otherwise
REPEATS = 3


# ==============================================================================================
# worker side
# ==============================================================================================
def _load(cfg: dict) -> np.ndarray:
    """(T, n, n, n) float32 steps, fully in memory (as a user would hold them)."""
    if cfg.get("field"):
        return np.load(cfg["field"])
    from geoshade.compute.mesh.displacement import displacement_field

    f = displacement_field((cfg["n"],) * 3, steps=STEPS, seed=SEED)
    return np.stack([f.step(k) for k in range(STEPS)])


def worker_geoshade(cfg: dict) -> dict:
    import warnings

    from geoshade.iso import IsoView
    from geoshade.models import FieldSeries
    from geoshade.render.context import get_context

    warnings.simplefilter("ignore")
    marks: dict = {}
    _mark(marks, "start")
    data = _load(cfg)
    field = FieldSeries(data, name="SWAT")
    _mark(marks, "data")
    ctx = get_context()
    _mark(marks, "context")
    size = tuple(cfg["size"])
    t0 = time.perf_counter()
    view = IsoView(field, LEVEL, step=1, size=size, ctx=ctx, **METHODS[cfg["method"]])
    init_ms = (time.perf_counter() - t0) * 1000
    _mark(marks, "view")
    _, st = view.draw(frames=int(cfg.get("frames", 3)), count=True)
    _mark(marks, "frames")
    view.wait_prefetch()  # the user looked at step 1 long enough for step 2 to be ready
    _mark(marks, "ahead")
    # a switch = the new step's update + its frame drawn into the framebuffer (the frame of
    # draw(), ``first_frame_ms``: what VTK's render + WaitForCompletion measures); draw() also
    # reads the picture back and composites the annotations, timed apart (``*_draw_ms``)
    t0 = time.perf_counter()
    view.update(step=2)
    update_ms = (time.perf_counter() - t0) * 1000
    swap_ms = view.switch_ms
    t1 = time.perf_counter()
    _, st2 = view.draw(frames=1, count=False)
    draw_ms = (time.perf_counter() - t1) * 1000
    _mark(marks, "switch")
    switch_ms = update_ms + st2["first_frame_ms"]
    t0 = time.perf_counter()
    view.update(step=0)  # not prepared ahead: read + prepare + upload
    cold_update_ms = (time.perf_counter() - t0) * 1000
    cold_upload_ms = view.switch_ms
    t1 = time.perf_counter()
    _, st0 = view.draw(frames=1, count=False)
    cold_draw_ms = (time.perf_counter() - t1) * 1000
    cold_ms = cold_update_ms + st0["first_frame_ms"]
    _mark(marks, "cold")
    gpu_bytes = view.visual.gpu_bytes  # both slots filled: the steady state
    breakdown = view.visual.cache.breakdown()
    out = {
        "kind": "geoshade", "n": cfg["n"], "method": cfg["method"], **METHODS[cfg["method"]],
        "slice_axis": st["slice_axis"],
        "width": st["width"], "height": st["height"], "cells": st["cells"],
        "cells_marched": st["cells_marched"], "triangles": st["triangles"],
        "init_ms": init_ms, "first_frame_ms": st["first_frame_ms"], "rerender_ms": st["frame_ms"],
        "step_switch_ms": switch_ms, "step_swap_ms": swap_ms, "prefetched": st2["prefetched"],
        "premarched": st2["premarched"], "step_update_ms": update_ms,
        "step_frame_ms": st2["first_frame_ms"], "step_switch_draw_ms": update_ms + draw_ms,
        "step_switch_cold_ms": cold_ms, "step_upload_cold_ms": cold_upload_ms,
        "step_switch_cold_draw_ms": cold_update_ms + cold_draw_ms,
        "gpu_bytes": gpu_bytes, "gpu_bytes_per_node": gpu_bytes / field.nodes,
        "peak_rss_mib": _peak_rss_mib(), "renderer": st["renderer"], "rss_marks_mib": marks,
        "gpu_breakdown": breakdown,
    }
    view.release()
    return out


def worker_vtk(cfg: dict) -> dict:
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv
    import vtk
    from vtk.util import numpy_support

    pv.OFF_SCREEN = True
    pv.global_theme.multi_samples = 0
    marks: dict = {}
    _mark(marks, "start")
    data = _load(cfg)
    _mark(marks, "data")
    _, nz, ny, nx = data.shape
    size = tuple(cfg["size"])
    img = vtk.vtkImageData()
    img.SetDimensions(nx, ny, nz)
    keep = [numpy_support.numpy_to_vtk(np.ascontiguousarray(data[1]).ravel(), deep=False)]
    img.GetPointData().SetScalars(keep[-1])
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(img)
    fe.SetValue(0, LEVEL)
    fe.ComputeNormalsOn()
    fe.ComputeScalarsOff()
    t0 = time.perf_counter()
    fe.Update()
    extract_ms = (time.perf_counter() - t0) * 1000
    _mark(marks, "extract")
    triangles = int(fe.GetOutput().GetNumberOfCells())
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputConnection(fe.GetOutputPort())
    mapper.ScalarVisibilityOff()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.SetColor(0.16, 0.45, 0.80)
    prop.SetInterpolationToPhong()
    prop.SetSpecular(0.2)
    prop.SetSpecularPower(32)
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    plotter.background_color = "white"
    plotter.renderer.AddActor(actor)
    plotter.view_isometric()
    plotter.reset_camera()
    finish = getattr(plotter.ren_win, "WaitForCompletion", lambda: None)
    t0 = time.perf_counter()
    plotter.show(auto_close=False)
    finish()
    first_ms = (time.perf_counter() - t0) * 1000
    _mark(marks, "drawn")
    times = []
    for _ in range(max(1, int(cfg.get("frames", 3)) - 1)):
        t0 = time.perf_counter()
        plotter.render()
        finish()
        times.append((time.perf_counter() - t0) * 1000)
    # a new step: new scalars, flying edges, upload, one frame
    t0 = time.perf_counter()
    keep.append(numpy_support.numpy_to_vtk(np.ascontiguousarray(data[2]).ravel(), deep=False))
    img.GetPointData().SetScalars(keep[-1])
    img.Modified()
    plotter.render()
    finish()
    switch_ms = (time.perf_counter() - t0) * 1000
    _mark(marks, "switch")
    t0 = time.perf_counter()
    keep.append(numpy_support.numpy_to_vtk(np.ascontiguousarray(data[0]).ravel(), deep=False))
    img.GetPointData().SetScalars(keep[-1])
    img.Modified()
    fe.Update()
    extract2_ms = (time.perf_counter() - t0) * 1000
    out = {
        "kind": "vtk", "n": cfg["n"], "method": "vtk", "vtk": vtk.vtkVersion.GetVTKVersion(),
        "pyvista": pv.__version__, "width": size[0], "height": size[1],
        "cells": (nx - 1) * (ny - 1) * (nz - 1), "triangles": triangles,
        "extract_ms": extract_ms, "extract_step0_ms": extract2_ms, "first_frame_ms": first_ms,
        "rerender_ms": float(np.median(times)), "rerender_all_ms": times,
        "step_switch_ms": switch_ms, "gpu_bytes": None, "peak_rss_mib": _peak_rss_mib(),
        "rss_marks_mib": marks,
    }
    plotter.close()
    return out


def worker_main(config_json: str) -> int:
    """Run one config and print exactly one JSON line (errors included)."""
    return harness.worker_main(
        config_json, lambda cfg: worker_vtk if cfg.get("kind") == "vtk" else worker_geoshade,
        keep=('kind', 'n', 'method'))


# ==============================================================================================
# parent side
# ==============================================================================================
def run_worker(cfg: dict, timeout_s: float = WORKER_TIMEOUT_S) -> dict:
    """One config in a subprocess with a time limit; its JSON dict."""
    res = harness.run_worker(__file__, cfg, timeout_s, keep=("kind", "n", "method"),
                             drop=("field",))
    res.setdefault("width", cfg["size"][0])
    res.setdefault("height", cfg["size"][1])
    return res


machine_info = harness.machine_info


def frames_for(n: int, method: str) -> int:
    """Frames per timing (first + median of the rest). With the mesh cache frame 1 marches and
    counts, frame 2 marches and captures, frames 3+ re-draw: 6 frames give a steady median."""
    if method == "default":
        return 6
    return 4 if n <= 100 else 2


def _ms(v):
    if v is None:
        return "—"
    return f"{v:,.0f}" if v >= 100 else f"{v:.1f}"


def _int(v):
    return "—" if v is None else f"{int(v):,}"


REPEATED = ("step_switch_ms", "peak_rss_mib", "step_switch_cold_ms", "step_switch_draw_ms",
            "rerender_ms", "first_frame_ms")


def _key(r) -> tuple:
    return (r.get("kind"), r.get("method"), r["n"], r["width"], r["height"])


def aggregate(runs: list[dict]) -> list[dict]:
    """One row per config from its repeats (each its own process): the first run's counts,
    ``<figure>_runs`` with every repeat's value and the figure itself the median, for the
    figures in :data:`REPEATED`. A config with a failed repeat keeps the failure."""
    order, groups = [], {}
    for r in runs:
        k = _key(r)
        if k not in groups:
            order.append(k)
            groups[k] = []
        groups[k].append(r)
    rows = []
    for k in order:
        g = groups[k]
        ok = [r for r in g if r.get("ok")]
        if len(ok) < len(g) or not ok:
            bad = next(r for r in g if not r.get("ok"))
            rows.append({**bad, "repeats": len(g), "failed": len(g) - len(ok)})
            continue
        row = dict(ok[0])
        row["repeats"] = len(ok)
        for name in REPEATED:
            vals = [r[name] for r in ok if r.get(name) is not None]
            if vals:
                row[name + "_runs"] = vals
                row[name] = float(np.median(vals))
        rows.append(row)
    return rows


def _spread(r, name, fmt=_ms) -> str:
    """``median (min–max)`` of a repeated figure; the value alone for one run."""
    vals = r.get(name + "_runs") or ([r[name]] if r.get(name) is not None else [])
    if not vals:
        return "—"
    med = fmt(float(np.median(vals)))
    return med if len(vals) == 1 else f"{med} ({fmt(min(vals))}–{fmt(max(vals))})"


def _mib(v) -> str:
    return f"{v:,.0f}"


def _peer(rows, r):
    return next((p for p in rows if p.get("kind") == "vtk" and p.get("ok")
                 and p["n"] == r["n"] and (p["width"], p["height"]) == (r["width"], r["height"])),
                None)


HEAD = ("| field | image | method | triangles | cells marched | first frame ms | re-render ms "
        "| step switch ms, prepared ahead | step switch ms, cold | prepared ahead + read back "
        "+ annotations ms | GPU bytes (B/node) | peak RSS MiB | re-render ours / VTK "
        "| switch ours / VTK | RSS ours / VTK |")


def table(rows) -> list[str]:
    lines = [HEAD, "|" + "---|" * 15]
    for r in rows:
        img = f"{r['width']}×{r['height']}"
        head = f"| {r['n']}³ | {img} | "
        if not r.get("ok"):
            lines.append(head + f"{r.get('method')}: {r.get('error', 'failed')} |"
                         + " — |" * 12)
            continue
        if r["kind"] == "vtk":
            lines.append(head + f"VTK {r['vtk']} flying edges (extract {_ms(r['extract_ms'])} ms)"
                         f" | {_int(r['triangles'])} | {_int(r['cells'])} "
                         f"| {_ms(r['first_frame_ms'])} | {_ms(r['rerender_ms'])} "
                         f"| {_spread(r, 'step_switch_ms')} (re-extract) | — | — | — "
                         f"| {_spread(r, 'peak_rss_mib', _mib)} | 1 | 1 | 1 |")
            continue
        p = _peer(rows, r)
        name = (f"**default** (L=8, skip, slices ⟂ {r.get('slice_axis', '?')}, mesh cache)"
                if r["method"] == "default" else "paper (L=64, no skip, slices ⟂ z)")
        ratio = f"{r['rerender_ms'] / p['rerender_ms']:.2f}" if p else "—"
        sw = f"{r['step_switch_ms'] / p['step_switch_ms']:.2f}" if p else "—"
        rss = f"{r['peak_rss_mib'] / p['peak_rss_mib']:.2f}" if p else "—"
        lines.append(head + f"{name} | {_int(r['triangles'])} | {_int(r['cells_marched'])} "
                     f"| {_ms(r['first_frame_ms'])} | {_ms(r['rerender_ms'])} "
                     f"| {_spread(r, 'step_switch_ms')} | {_spread(r, 'step_switch_cold_ms')} "
                     f"| {_spread(r, 'step_switch_draw_ms')} "
                     f"| {_int(r['gpu_bytes'])} ({r['gpu_bytes_per_node']:.2f}) "
                     f"| {_spread(r, 'peak_rss_mib', _mib)} | {ratio} | {sw} | {rss} |")
    return lines


def _runs(r, name) -> list[float]:
    return r.get(name + "_runs") or [r[name]]


def targets(rows, software: bool) -> list[str]:
    """The issues' targets, each ✔/✘ on the medians, with min/max over the repeats."""
    out = []
    for r in rows:
        if r.get("kind") != "geoshade" or r.get("method") != "default" or not r.get("ok"):
            continue
        p = _peer(rows, r)
        if p is None:
            continue
        where = f"{r['n']}³ at {r['width']}×{r['height']}"
        tr = r["rerender_ms"] / p["rerender_ms"]
        out.append(f"- {'✔' if tr <= 2.0 else '✘'} {where}: re-render {tr:.2f}× VTK's "
                   f"({_ms(r['rerender_ms'])} vs {_ms(p['rerender_ms'])} ms; target ≤ 2×)")
        ours, theirs = _runs(r, "peak_rss_mib"), _runs(p, "peak_rss_mib")
        mr = r["peak_rss_mib"] / p["peak_rss_mib"]
        every = max(ours) < min(theirs)
        out.append(f"- {'✔' if mr < 1.0 else '✘'} {where}: peak RSS {mr:.2f}× VTK's (median "
                   f"{_mib(r['peak_rss_mib'])} vs {_mib(p['peak_rss_mib'])} MiB, ours "
                   f"{_mib(min(ours))}–{_mib(max(ours))}, VTK's {_mib(min(theirs))}–"
                   f"{_mib(max(theirs))}; target < 1{', in every repeat' if every else ''})")
        ours, theirs = _runs(r, "step_switch_ms"), _runs(p, "step_switch_ms")
        ms = r["step_switch_ms"] / p["step_switch_ms"]
        every = max(ours) <= min(theirs)
        out.append(f"- {'✔' if ms <= 1.0 else '✘'} {where}: step switch prepared ahead "
                   f"{ms:.2f}× VTK's re-extract (median {_ms(r['step_switch_ms'])} vs "
                   f"{_ms(p['step_switch_ms'])} ms, ours {_ms(min(ours))}–{_ms(max(ours))}, "
                   f"VTK's {_ms(min(theirs))}–{_ms(max(theirs))}; target ≤ 1"
                   f"{', in every repeat' if every else ''})")
    gpu = ("– on a real GPU: ≥ 100 fps for 100³ at 3840×2160 and ≥ 25 fps for 512³ — not "
           "measurable here (llvmpipe; no GPU in this session)" if software else
           "- real-GPU targets: see the 100³ 3840×2160 and 512³ rows (≥ 100 fps, ≥ 25 fps)")
    return [*out, gpu]


STAGES = {"geoshade": (("data", "the field read"), ("context", "GL context"),
                        ("view", "IsoView opened (step 1 prepared, ranges on the GPU)"),
                        ("frames", "its frames (march, capture, re-draws; read-back, "
                                   "annotations)"),
                        ("ahead", "step 2 prepared and marched ahead"),
                        ("switch", "switch to step 2 drawn"),
                        ("cold", "cold switch to step 0 drawn")),
          "vtk": (("data", "the field read"), ("extract", "flying edges"),
                  ("drawn", "first render (context, upload)"), ("switch", "re-extract + render"))}


def _gpu_text(breakdown: dict) -> str:
    """The GPU objects of a row grouped: field slab, meshes, patch ranges, the rest."""
    groups = {"field texture": 0, "meshes": 0, "patch ranges": 0, "other": 0}
    for name, n in breakdown.items():
        key = ("meshes" if name.startswith("mesh") else "patch ranges"
               if name.startswith("ranges") else "field texture"
               if name.startswith(("field", "property")) else "other")
        groups[key] += n
    return ", ".join(f"{k} {v / 2**20:.1f}" for k, v in groups.items() if v)


def where(rows) -> list[str]:
    """Per 256³/512³ row of the default method and VTK: the RSS after each stage, the GPU
    objects at the end, and the prepared-ahead switch split into update and frame."""
    out = []
    for r in rows:
        if not r.get("ok") or r["n"] < 256 or r.get("method") == "paper":
            continue
        marks = r.get("rss_marks_mib") or {}
        prev = marks.get("start", 0.0)
        parts = [f"Python and imports {prev:,.0f}"]
        for key, text in STAGES[r["kind"]]:
            if key in marks:
                parts.append(f"{text} {marks[key] - prev:+,.0f}")
                prev = marks[key]
        who = "ours" if r["kind"] == "geoshade" else "VTK"
        line = (f"- {r['n']}³ {r['width']}×{r['height']}, {who}: " + "; ".join(parts)
                + f" (peak {r['peak_rss_mib']:,.0f})")
        if r["kind"] == "geoshade":
            line += (f". GPU objects at the end (MiB): {_gpu_text(r.get('gpu_breakdown', {}))}"
                     f". Switch prepared ahead: update {r['step_update_ms']:.1f} ms (swap "
                     f"{r['step_swap_ms']:.2f}), frame {r['step_frame_ms']:.1f} ms, draw()'s "
                     f"read-back + annotations {r['step_switch_draw_ms'] - r['step_switch_ms']:.1f}"
                     " ms")
        out.append(line)
    return out


def _load_text(result: dict) -> str:
    loads = [x for r in result["runs"] for x in r.get("load_avg_1min", [])]
    before, after = result.get("load_before"), result.get("load_after")
    text = (f"1-min load {min(loads, default=0):.1f}–{max(loads, default=0):.1f} during the "
            "workers")
    if before and after:
        text += (f"; `uptime` load averages (1, 5, 15 min) before {before[0]:.2f}, "
                 f"{before[1]:.2f}, {before[2]:.2f} and after {after[0]:.2f}, {after[1]:.2f}, "
                 f"{after[2]:.2f}")
    return text


def markdown(result: dict) -> str:
    m = result["machine"]
    mem = f", {m['ram_gib']:.1f} GiB RAM" if m.get("ram_gib") else ""
    lines = [MARK_BEGIN, "## iso — saturation isosurfaces (`geoshade bench iso`)", "",
             f"- date: {m['date']}; command: `{result['command']}`; "
             f"{result['repeats']} repeats of every row, each its own process, rounds "
             "interleaved; a figure given as *median (min–max)* over them",
             f"- machine: {m['cpu']}, {m['cores_usable']} cores usable{mem}; GL: "
             f"{m.get('gl_renderer')} ({m.get('gl_version')})",
             f"- fields: `displacement_field((n, n, n), steps={STEPS}, seed={SEED})` float32 "
             f"(water fingers), level S* = {LEVEL}; step 1 drawn, switch to step 2 (prepared "
             "ahead while step 1 was shown) and to step 0 (cold: read, prepare, upload); each "
             "row its own subprocess (peak RSS = VmHWM; llvmpipe's textures and buffers are in "
             "that RAM too), the field in memory in both",
             "- geoshade's default marches a new step or level once on the GPU, in slabs of "
             "slices through one 16 MiB field texture, capturing the triangles while drawing, "
             "and re-draws them (mesh cache); the paper's method marches every frame from two "
             "whole field textures; VTK re-renders its stored mesh (its step switch "
             "re-extracts). VTK offscreen through EGL, MSAA off",
             "- step switch = from the new step to its frame drawn and finished in the "
             "framebuffer (ours: `update(step=)` + the frame of `draw()`; VTK: new scalars + "
             "`render()` + `WaitForCompletion`, which re-extracts). Our `draw()` also reads the "
             "picture back into numpy and composites the title, colour key and triad: the "
             "column *+ read back + annotations* gives that whole call (VTK's row has neither); "
             "`results/iso.json` splits every switch into update, swap and frame",
             f"- noisy machine: 2 shared cores ({_load_text(result)}); compare ratios. Total "
             f"{result['elapsed_s'] / 60:.1f} min.", "", *table(result["rows"]), "",
             "Where it goes (first repeat of each row; RSS in MiB after each stage, "
             "`rss_marks_mib` in the JSON):", "", *where(result["rows"]), "",
             "Targets (issue 5: re-render ≤ 2× VTK, RSS < VTK; issue 34: peak RSS < VTK at "
             "256³ and 512³, the step switch prepared ahead ≤ VTK's re-extract at every size "
             "and image; ✔/✘ on the medians):", "",
             *targets(result["rows"], m.get("gl_software", True)), "", MARK_END]
    return "\n".join(lines) + "\n"


def _log(msg: str) -> None:
    print(f"[bench iso] {msg}", file=sys.stderr, flush=True)


def configs(mode: str, no_peers: bool, paths: dict) -> list[dict]:
    """Every row's config: sizes of ``mode`` at both images (512³: 1920×1080, default only)."""
    images = ((1920, 1080),) if mode == "quick" else IMAGES
    out = []
    for n in SIZES[mode]:
        for w, h in ((1920, 1080),) if n >= 512 else images:
            kinds = [("geoshade", "default")] + ([] if n >= 512 else [("geoshade", "paper")])
            if not no_peers:
                kinds.append(("vtk", "vtk"))
            out += [{"kind": kind, "method": method, "n": n, "size": [w, h],
                     "field": str(paths[n]), "frames": frames_for(n, method)}
                    for kind, method in kinds]
    return out


def main(args, folder) -> int:
    """Entry point of ``geoshade bench iso`` (args: full, quick, no_peers, repeats, output)."""
    from geoshade.cli.main import main as _unused  # noqa: F401  (the CLI is importable)
    from geoshade.compute.mesh.displacement import displacement_field
    from geoshade.io.output import write_json

    t_start = time.perf_counter()
    load_before = list(os.getloadavg())
    mode = "quick" if args.quick else "full" if args.full else "default"
    repeats = max(1, int(getattr(args, "repeats", None) or REPEATS))
    out_dir = Path(args.output) if getattr(args, "output", None) else Path(folder)
    out_dir.mkdir(parents=True, exist_ok=True)
    machine = machine_info()
    runs = []
    with tempfile.TemporaryDirectory(prefix="geoshade-bench-iso-") as tmp:
        paths = {}
        for n in SIZES[mode]:
            f = displacement_field((n, n, n), steps=STEPS, seed=SEED)
            paths[n] = Path(tmp) / f"field_{n}.npy"
            np.save(paths[n], np.stack([f.step(k) for k in range(STEPS)]))
            del f
        todo = configs(mode, args.no_peers, paths)
        for rep in range(repeats):   # rounds: each config once per round
            for cfg in todo:
                _log(f"[{rep + 1}/{repeats}] {cfg['n']}³ {cfg['size'][0]}×{cfg['size'][1]} "
                     f"{cfg['method']} ...")
                r = run_worker(cfg)
                r["repeat"] = rep
                _log(f"  -> {'ok' if r.get('ok') else r.get('error')} ({r['elapsed_s']:.0f} s)")
                runs.append(r)
    result = {"part": PART, "command": _command(args), "mode": mode, "machine": machine,
              "repeats": repeats, "rows": aggregate(runs), "runs": runs,
              "load_before": load_before, "load_after": list(os.getloadavg()),
              "elapsed_s": time.perf_counter() - t_start}
    section = markdown(result)
    print(section)
    write_json(out_dir / "results" / "iso.json" if (out_dir / "results").is_dir()
               else out_dir / "iso.json", result)
    harness.write_results(out_dir, "iso", section)
    return 0


def _command(args) -> str:
    parts = ["geoshade bench iso"]
    for flag in ("full", "quick", "no_peers"):
        if getattr(args, flag, False):
            parts.append("--" + flag.replace("_", "-"))
    if getattr(args, "repeats", None):
        parts.append(f"--repeats {args.repeats}")
    return " ".join(parts)


if __name__ == "__main__":
    sys.exit(harness.script_main(worker_main, "iso"))
