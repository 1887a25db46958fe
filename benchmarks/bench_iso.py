"""``geoshade bench iso``: tessellation marching cubes against VTK flying edges, side by side.

For synthetic displacement fields (:func:`geoshade.compute.displacement.displacement_field`,
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

SIZES = {"quick": (64,), "default": (100, 256), "full": (100, 256, 512)}
IMAGES = ((3840, 2160), (1920, 1080))
LEVEL, STEPS, SEED = 0.5, 3, 0
METHODS = {"default": {"patch_level": 8, "skip_patches": True, "slice_axis": "auto",
                       "mesh_cache": True},
           "paper": {"patch_level": 64, "skip_patches": False, "slice_axis": "z",
                     "mesh_cache": False}}
WORKER_TIMEOUT_S = 1200


# ==============================================================================================
# worker side
# ==============================================================================================
def _load(cfg: dict) -> np.ndarray:
    """(T, n, n, n) float32 steps, fully in memory (as a user would hold them)."""
    if cfg.get("field"):
        return np.load(cfg["field"])
    from geoshade.compute.displacement import displacement_field

    f = displacement_field((cfg["n"],) * 3, steps=STEPS, seed=SEED)
    return np.stack([f.step(k) for k in range(STEPS)])


def worker_geoshade(cfg: dict) -> dict:
    import warnings

    from geoshade.iso import IsoView
    from geoshade.models import FieldSeries
    from geoshade.render.context import get_context

    warnings.simplefilter("ignore")
    data = _load(cfg)
    field = FieldSeries(data, name="SWAT")
    ctx = get_context()
    size = tuple(cfg["size"])
    t0 = time.perf_counter()
    view = IsoView(field, LEVEL, step=1, size=size, ctx=ctx, **METHODS[cfg["method"]])
    init_ms = (time.perf_counter() - t0) * 1000
    _, st = view.draw(frames=int(cfg.get("frames", 3)), count=True)
    view.wait_prefetch()  # the user looked at step 1 long enough for step 2 to be ready
    t0 = time.perf_counter()
    view.update(step=2)
    swap_ms = view.switch_ms
    _, st2 = view.draw(frames=1, count=False)
    switch_ms = (time.perf_counter() - t0) * 1000
    t0 = time.perf_counter()
    view.update(step=0)  # not prepared ahead: read + prepare + upload
    cold_upload_ms = view.switch_ms
    view.draw(frames=1, count=False)
    cold_ms = (time.perf_counter() - t0) * 1000
    gpu_bytes = view.visual.gpu_bytes  # both slots filled: the steady state
    out = {
        "kind": "geoshade", "n": cfg["n"], "method": cfg["method"], **METHODS[cfg["method"]],
        "slice_axis": st["slice_axis"],
        "width": st["width"], "height": st["height"], "cells": st["cells"],
        "cells_marched": st["cells_marched"], "triangles": st["triangles"],
        "init_ms": init_ms, "first_frame_ms": st["first_frame_ms"], "rerender_ms": st["frame_ms"],
        "step_switch_ms": switch_ms, "step_swap_ms": swap_ms, "prefetched": st2["prefetched"],
        "step_switch_cold_ms": cold_ms, "step_upload_cold_ms": cold_upload_ms,
        "gpu_bytes": gpu_bytes, "gpu_bytes_per_node": gpu_bytes / field.nodes,
        "peak_rss_mib": _peak_rss_mib(), "renderer": st["renderer"],
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
    data = _load(cfg)
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


def _peer(rows, r):
    return next((p for p in rows if p.get("kind") == "vtk" and p.get("ok")
                 and p["n"] == r["n"] and (p["width"], p["height"]) == (r["width"], r["height"])),
                None)


HEAD = ("| field | image | method | triangles | cells marched | first frame ms | re-render ms "
        "| step switch ms (prepared ahead / cold) | GPU bytes (B/node) | peak RSS MiB "
        "| re-render ours / VTK | RSS ours / VTK |")


def table(rows) -> list[str]:
    lines = [HEAD, "|" + "---|" * 12]
    for r in rows:
        img = f"{r['width']}×{r['height']}"
        head = f"| {r['n']}³ | {img} | "
        if not r.get("ok"):
            lines.append(head + f"{r.get('method')}: {r.get('error', 'failed')} |"
                         + " — |" * 9)
            continue
        if r["kind"] == "vtk":
            lines.append(head + f"VTK {r['vtk']} flying edges (extract {_ms(r['extract_ms'])} ms)"
                         f" | {_int(r['triangles'])} | {_int(r['cells'])} "
                         f"| {_ms(r['first_frame_ms'])} | {_ms(r['rerender_ms'])} "
                         f"| {_ms(r['step_switch_ms'])} | — | {r['peak_rss_mib']:,.0f} | 1 | 1 |")
            continue
        p = _peer(rows, r)
        name = (f"**default** (L=8, skip, slices ⟂ {r.get('slice_axis', '?')}, mesh cache)"
                if r["method"] == "default" else "paper (L=64, no skip, slices ⟂ z)")
        ratio = f"{r['rerender_ms'] / p['rerender_ms']:.2f}" if p else "—"
        rss = f"{r['peak_rss_mib'] / p['peak_rss_mib']:.2f}" if p else "—"
        lines.append(head + f"{name} | {_int(r['triangles'])} | {_int(r['cells_marched'])} "
                     f"| {_ms(r['first_frame_ms'])} | {_ms(r['rerender_ms'])} "
                     f"| {_ms(r['step_switch_ms'])} / {_ms(r['step_switch_cold_ms'])} "
                     f"| {_int(r['gpu_bytes'])} ({r['gpu_bytes_per_node']:.2f}) "
                     f"| {r['peak_rss_mib']:,.0f} | {ratio} | {rss} |")
    return lines


def targets(rows, software: bool) -> list[str]:
    out = []
    for r in rows:
        if r.get("kind") != "geoshade" or r.get("method") != "default" or not r.get("ok"):
            continue
        p = _peer(rows, r)
        if p is None:
            continue
        tr = r["rerender_ms"] / p["rerender_ms"]
        mr = r["peak_rss_mib"] / p["peak_rss_mib"]
        ok = tr <= 2.0 and mr < 1.0
        out.append(f"- {'✔' if ok else '✘'} {r['n']}³ at {r['width']}×{r['height']}: re-render "
                   f"{tr:.2f}× VTK's ({_ms(r['rerender_ms'])} vs {_ms(p['rerender_ms'])} ms; "
                   f"target ≤ 2×), peak RSS {mr:.2f}× VTK's ({r['peak_rss_mib']:,.0f} vs "
                   f"{p['peak_rss_mib']:,.0f} MiB; target < 1)")
    gpu = ("– on a real GPU: ≥ 100 fps for 100³ at 3840×2160 and ≥ 25 fps for 512³ — not "
           "measurable here (llvmpipe; no GPU in this session)" if software else
           "- real-GPU targets: see the 100³ 3840×2160 and 512³ rows (≥ 100 fps, ≥ 25 fps)")
    return [*out, gpu]


def markdown(result: dict) -> str:
    m = result["machine"]
    loads = [x for r in result["rows"] for x in r.get("load_avg_1min", [])]
    lines = [MARK_BEGIN, "## iso — saturation isosurfaces (`geoshade bench iso`)", "",
             f"- date: {m['date']}; command: `{result['command']}`",
             f"- machine: {m['cpu']}, {m['cores_usable']} cores usable; GL: "
             f"{m.get('gl_renderer')} ({m.get('gl_version')})",
             f"- fields: `displacement_field((n, n, n), steps={STEPS}, seed={SEED})` float32 "
             f"(water fingers), level S* = {LEVEL}; step 1 drawn, switch to step 2 (prepared "
             "ahead while step 1 was shown) and to step 0 (cold: read, prepare, upload); each "
             "row its own subprocess (peak RSS = VmHWM), the field in memory in both",
             "- geoshade's default marches a new step or level once on the GPU, capturing the "
             "triangles while drawing, and re-draws them (mesh cache); the paper's method "
             "marches every frame; VTK re-renders its stored mesh (its step switch "
             "re-extracts). VTK offscreen through EGL, MSAA off",
             "- step switch = time from the new step to its picture; geoshade's column gives "
             "the step prepared ahead (a swap of textures) / a cold step (read, prepare, "
             "upload); `results/iso.json` splits both into switch and frame",
             f"- noisy machine: 2 shared cores (1-min load {min(loads, default=0):.1f}–"
             f"{max(loads, default=0):.1f} during the run); compare ratios. Total "
             f"{result['elapsed_s'] / 60:.1f} min.", "", *table(result["rows"]), "",
             "Targets (from the issue):", "", *targets(result["rows"],
                                                       m.get("gl_software", True)),
             "", MARK_END]
    return "\n".join(lines) + "\n"


def _log(msg: str) -> None:
    print(f"[bench iso] {msg}", file=sys.stderr, flush=True)


def main(args, folder) -> int:
    """Entry point of ``geoshade bench iso`` (args: full, quick, no_peers, size, output)."""
    from geoshade.cli.main import main as _unused  # noqa: F401  (the CLI is importable)
    from geoshade.io.output import write_json

    t_start = time.perf_counter()
    mode = "quick" if args.quick else "full" if args.full else "default"
    images = ((1920, 1080),) if mode == "quick" else IMAGES
    out_dir = Path(args.output) if getattr(args, "output", None) else Path(folder)
    out_dir.mkdir(parents=True, exist_ok=True)
    machine = machine_info()
    rows = []
    with tempfile.TemporaryDirectory(prefix="geoshade-bench-iso-") as tmp:
        for n in SIZES[mode]:
            from geoshade.compute.displacement import displacement_field

            f = displacement_field((n, n, n), steps=STEPS, seed=SEED)
            path = Path(tmp) / f"field_{n}.npy"
            np.save(path, np.stack([f.step(k) for k in range(STEPS)]))
            del f
            imgs = ((1920, 1080),) if n >= 512 else images
            for w, h in imgs:
                kinds = [("geoshade", "default"), ("geoshade", "paper")]
                if n >= 512:
                    kinds = [("geoshade", "default")]
                if not args.no_peers:
                    kinds.append(("vtk", "vtk"))
                for kind, method in kinds:
                    cfg = {"kind": kind, "method": method, "n": n, "size": [w, h],
                           "field": str(path), "frames": frames_for(n, method)}
                    _log(f"{n}³ {w}×{h} {method} ...")
                    r = run_worker(cfg)
                    _log(f"  -> {'ok' if r.get('ok') else r.get('error')} "
                         f"({r['elapsed_s']:.0f} s)")
                    rows.append(r)
    result = {"part": PART, "command": _command(args), "mode": mode, "machine": machine,
              "rows": rows, "elapsed_s": time.perf_counter() - t_start}
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
    return " ".join(parts)


if __name__ == "__main__":
    sys.exit(harness.script_main(worker_main, "iso"))
