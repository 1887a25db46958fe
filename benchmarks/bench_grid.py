"""``geoshade bench grid``: corner-point grids — parsing, GPU memory per approach, and frame /
property-switch times side by side with PyVista's ExplicitStructuredGrid.

1. Parse speed and peak memory: ``benchmarks/grid_parse.py`` (``run(args) -> (markdown,
   results)``), written with the readers.
2. GPU bytes per approach for the paper's (1000, 1000, 100) grid, from
   :func:`geoshade.render.visuals.grid.layout.gpu_plan` — the function whose sizes the renderer
   allocates (a test checks ``GpuCache.breakdown() == plan``) — without allocating anything:
   the paper's all-active shell (2.4e6 faces, exact), and the synthetic grid with two faults
   and 5 % inactive blobs, whose face counts are measured on a 250×250×25 grid and scaled by
   16 (every face family scales with the area: (1000/250)² = (1000·100)/(250·25)).
3. For synthetic grids (``compute.grid.synthetic``, faults and 5 % inactive cells), each
   approach and PyVista run in their own subprocess (peak RSS = VmHWM of that process): first
   frame, re-render, property switch (PORO -> PERMX), step switch (SWAT step 0 -> 1), filter
   change (``PORO > 0.2``), and frames with cell edges.

Writes ``RESULTS.md`` (between ``<!-- grid:begin -->`` and ``<!-- grid:end -->``) and
``results/grid.json``. Run: ``geoshade bench grid [--quick|--full] [--no-peers] [--size WxH]``.
A worker alone: ``python benchmarks/bench_grid.py --worker '{"kind": "geoshade", ...}'``.
"""

from __future__ import annotations

import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

PART = "grid"
MARK_BEGIN, MARK_END = "<!-- grid:begin -->", "<!-- grid:end -->"

sys.path.insert(0, str(Path(__file__).resolve().parent))  # harness.py, for workers too
import harness
from harness import peak_rss_mib as _peak_rss_mib
from harness import status_kib as _status_kib

SIZES = {"quick": ((40, 40, 10),), "default": ((100, 100, 50),),
         "full": ((100, 100, 50), (200, 200, 100))}
#: (label, approach, zcorn_store, zcorn_bits)
VARIANTS = (("1 (smeared)", 1, "faces", 16), ("2", 2, "faces", 16), ("3 grid", 3, "grid", 16),
            ("3 faces", 3, "faces", 16))
PAPER_DIMS = (1000, 1000, 100)
SAMPLE_DIMS = (250, 250, 25)
SCALE = 16
INACTIVE, SEED, STEPS = 0.05, 0, 2
WORKER_TIMEOUT_S = 600
#: every config runs this many times, the rounds interleaved (all configs, then again); each
#: timing reported is its best round (the machine is shared: load spikes only add time)
REPEATS = 2
TIMINGS = ("init_ms", "geometry_ms", "faces_ms", "first_frame_ms", "frame_ms", "edges_frame_ms",
           "property_switch_ms", "property_upload_ms", "step_switch_ms", "filter_ms",
           "filter_faces_ms")
MEM_FRACTION = 0.6
GB, GiB, MiB = 1e9, 2**30, 2**20


# ==============================================================================================
# workers (each in a fresh process; print one JSON line)
# ==============================================================================================
def _grid(cfg):
    from geoshade.compute.grid.synthetic import synthetic_grid

    t0 = time.perf_counter()
    g = synthetic_grid(*cfg["dims"], faults=True, inactive_fraction=INACTIVE, seed=SEED,
                       steps=STEPS)
    return g, (time.perf_counter() - t0) * 1000


def _coverage(img) -> float:
    return float(np.mean(np.any(np.asarray(img)[..., :3] != 255, axis=-1)))


def worker_geoshade(cfg: dict) -> dict:
    import warnings

    from geoshade.grid import GridView
    from geoshade.render.context import get_context

    warnings.simplefilter("ignore")
    g, gen_ms = _grid(cfg)
    ctx = get_context()
    rss0 = (_status_kib("VmRSS") or 0) / 1024
    frames = int(cfg.get("frames", 5))
    t0 = time.perf_counter()
    view = GridView(g, property="PORO", approach=cfg["approach"], zcorn_store=cfg["store"],
                    zcorn_bits=cfg["bits"], size=tuple(cfg["size"]), smear_faults=True, ctx=ctx)
    init_ms = (time.perf_counter() - t0) * 1000
    geometry_ms, faces_ms = view.geometry_ms, view.faces_ms
    img, st = view.draw(frames=frames)
    plan = sum(view.visual.plan().values())

    def timed(change):
        t = time.perf_counter()
        change()
        _, s = view.draw(frames=1, count=False)
        return (time.perf_counter() - t) * 1000, s

    prop_ms, _ = timed(lambda: view.update(property="PERMX"))
    prop_upload_ms = view.colors_ms
    step_ms, _ = timed(lambda: view.update(property="SWAT", step=1))
    view.update(property="PORO")
    filter_ms, sf = timed(lambda: view.update(filter="PORO > 0.2"))
    filter_faces_ms = view.faces_ms
    view.update(filter=None)
    view.update(edges=True)
    _, se = view.draw(frames=frames, count=False)
    view.release()
    return {
        "kind": "geoshade", "label": cfg["label"], "dims": cfg["dims"],
        "approach": cfg["approach"], "store": cfg["store"], "bits": cfg["bits"],
        "width": st["width"], "height": st["height"], "frames": frames,
        "cells": st["cells"], "active_cells": st["active_cells"], "faces": st["faces"],
        "faces_drawn": st["faces_drawn"], "generate_ms": gen_ms, "init_ms": init_ms,
        "geometry_ms": geometry_ms, "faces_ms": faces_ms,
        "first_frame_ms": st["first_frame_ms"], "frame_ms": st["frame_ms"],
        "edges_frame_ms": se["frame_ms"], "property_switch_ms": prop_ms,
        "property_upload_ms": prop_upload_ms, "step_switch_ms": step_ms,
        "filter_ms": filter_ms, "filter_faces_ms": filter_faces_ms,
        "filter_faces": sf["faces"], "gpu_bytes": st["gpu_bytes"], "gpu_plan": plan,
        "zcorn_max_error": st["zcorn_max_error"], "coverage": _coverage(img),
        "rss_base_mib": rss0, "peak_rss_mib": _peak_rss_mib(), "renderer": st["renderer"],
    }


def corner_points(g) -> np.ndarray:
    """(8·ncells, 3) corner points in ZCORN order (i fastest): the ExplicitStructuredGrid
    ``corners`` layout."""
    nx, ny, _ = g.dims
    coord = np.asarray(g.coord, np.float64)
    pi = (np.arange(2 * nx) + 1) // 2
    pj = (np.arange(2 * ny) + 1) // 2
    pil = coord[pi][:, pj]                                   # (2nx, 2ny, 6)
    z = np.asarray(g.zcorn, np.float64)
    top, bot = pil[..., None, :3], pil[..., None, 3:]
    dz = bot[..., 2] - top[..., 2]
    t = np.where(dz != 0, (z - top[..., 2]) / np.where(dz != 0, dz, 1.0), 0.0)
    pts = np.stack([top[..., 0] + t * (bot[..., 0] - top[..., 0]),
                    top[..., 1] + t * (bot[..., 1] - top[..., 1]), -z], axis=-1)
    return pts.reshape(-1, 3, order="F")


def worker_pyvista(cfg: dict) -> dict:
    import pyvista as pv
    import vtk

    pv.OFF_SCREEN = True
    pv.global_theme.multi_samples = 0
    g, gen_ms = _grid(cfg)
    rss0 = (_status_kib("VmRSS") or 0) / 1024
    frames = int(cfg.get("frames", 5))
    nx, ny, nz = g.dims
    t0 = time.perf_counter()
    mesh = pv.ExplicitStructuredGrid(np.array([nx + 1, ny + 1, nz + 1]), corner_points(g))
    mesh.cell_data["PORO"] = np.asarray(g.properties["PORO"]).ravel(order="F")
    mesh.cell_data["PERMX"] = np.asarray(g.properties["PERMX"]).ravel(order="F")
    mesh.cell_data["SWAT0"] = np.asarray(g.steps[0]["SWAT"]).ravel(order="F")
    mesh.cell_data["SWAT1"] = np.asarray(g.steps[1]["SWAT"]).ravel(order="F")
    inactive = np.flatnonzero(~g.active.ravel(order="F"))
    mesh = mesh.hide_cells(inactive).compute_connectivity()
    build_ms = (time.perf_counter() - t0) * 1000
    plotter = pv.Plotter(off_screen=True, window_size=list(cfg["size"]))
    plotter.background_color = "white"
    finish = getattr(plotter.ren_win, "WaitForCompletion", lambda: None)

    def rng(name):
        v = mesh.cell_data[name][g.active.ravel(order="F")]
        return [float(v.min()), float(v.max())]

    t0 = time.perf_counter()
    actor = plotter.add_mesh(mesh, scalars="PORO", cmap="viridis", clim=rng("PORO"),
                             show_scalar_bar=False)
    plotter.view_isometric()
    plotter.show(auto_close=False)
    finish()
    first_ms = (time.perf_counter() - t0) * 1000
    times = []
    for _ in range(max(1, frames - 1)):
        t0 = time.perf_counter()
        plotter.render()
        finish()
        times.append((time.perf_counter() - t0) * 1000)
    coverage = _coverage(plotter.screenshot(return_img=True))

    def switch(name):
        t = time.perf_counter()
        mesh.set_active_scalars(name, preference="cell")
        actor.mapper.array_name = name
        actor.mapper.scalar_range = rng(name)
        plotter.render()
        finish()
        return (time.perf_counter() - t) * 1000

    prop_ms = switch("PERMX")
    step_ms = switch("SWAT1")
    switch("PORO")
    t0 = time.perf_counter()
    th = mesh.threshold(0.2, scalars="PORO", preference="cell", method="upper")
    plotter.remove_actor(actor, render=False)
    actor2 = plotter.add_mesh(th, scalars="PORO", cmap="viridis", clim=rng("PORO"),
                              show_scalar_bar=False)
    plotter.render()
    finish()
    filter_ms = (time.perf_counter() - t0) * 1000
    plotter.remove_actor(actor2, render=False)
    plotter.add_mesh(mesh, scalars="PORO", cmap="viridis", clim=rng("PORO"), show_edges=True,
                     show_scalar_bar=False)
    plotter.render()
    finish()
    etimes = []
    for _ in range(max(1, frames - 1)):
        t0 = time.perf_counter()
        plotter.render()
        finish()
        etimes.append((time.perf_counter() - t0) * 1000)
    plotter.close()
    return {
        "kind": "pyvista", "label": "PyVista ExplicitStructuredGrid", "dims": cfg["dims"],
        "pyvista": pv.__version__, "vtk": vtk.vtkVersion.GetVTKVersion(),
        "width": cfg["size"][0], "height": cfg["size"][1], "frames": frames,
        "cells": g.ncells, "active_cells": g.nactive, "generate_ms": gen_ms,
        "init_ms": build_ms, "first_frame_ms": first_ms, "frame_ms": float(np.median(times)),
        "edges_frame_ms": float(np.median(etimes)), "property_switch_ms": prop_ms,
        "step_switch_ms": step_ms, "filter_ms": filter_ms, "filter_faces": None,
        "gpu_bytes": None, "coverage": coverage, "rss_base_mib": rss0,
        "peak_rss_mib": _peak_rss_mib(),
    }


def worker_main(config_json: str) -> int:
    """Run one config and print exactly one JSON line (errors included)."""
    return harness.worker_main(
        config_json,
        lambda cfg: worker_pyvista if cfg.get("kind") == "pyvista" else worker_geoshade,
        keep=('kind', 'label', 'dims'))


# ==============================================================================================
# parent
# ==============================================================================================
def run_worker(cfg: dict, timeout_s=WORKER_TIMEOUT_S, mem_limit=None) -> dict:
    """Run one config in a subprocess (time and memory limits); its JSON line as a dict."""
    return harness.run_worker(__file__, cfg, timeout_s, mem_limit,
                              keep=("kind", "label", "dims"))


def merge_runs(runs: list) -> dict:
    """One row from the rounds of a config: each timing its best, RSS its largest."""
    ok = [r for r in runs if r.get("ok")]
    if not ok:
        return runs[0]
    row = dict(ok[0])
    for key in TIMINGS:
        vals = [r[key] for r in ok if r.get(key) is not None]
        if vals:
            row[key] = min(vals)
            row[key + "_rounds"] = vals
    row["peak_rss_mib"] = max(r["peak_rss_mib"] for r in ok)
    row["rounds"] = len(ok)
    row["load_avg_1min"] = [v for r in runs for v in r.get("load_avg_1min") or []]
    return row


def memory_table() -> dict:
    """GPU bytes per approach for the paper's (1000, 1000, 100) grid (no allocation)."""
    from geoshade.compute.grid.faces import visible_faces
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.render.visuals.grid.layout import gpu_plan

    nx, ny, nz = PAPER_DIMS
    shell_faces = 2 * (nx * ny + nx * nz + ny * nz)
    shell_cells = nx * ny * nz - (nx - 2) * (ny - 2) * (nz - 2)
    g = synthetic_grid(*SAMPLE_DIMS, faults=True, inactive_fraction=INACTIVE, seed=SEED,
                       steps=0)
    fs = visible_faces(g)
    sx, sy, _ = SAMPLE_DIMS
    sample_cells = int(np.unique(fs.cells[:, 0].astype(np.int64) + sx * (
        fs.cells[:, 1] + sy * fs.cells[:, 2].astype(np.int64))).size)
    cases = {
        "shell": {"what": "all cells active, no faults (the paper's shell)",
                  "faces": shell_faces, "cells_drawn": shell_cells, "faulted": False},
        "faulted": {"what": f"synthetic grid, 2 faults + {INACTIVE:.0%} inactive blobs "
                            f"(faces of {SAMPLE_DIMS[0]}×{SAMPLE_DIMS[1]}×{SAMPLE_DIMS[2]} "
                            f"× {SCALE})",
                    "faces": SCALE * len(fs.face), "cells_drawn": SCALE * sample_cells,
                    "fault_faces": SCALE * int(fs.fault.sum()), "faulted": True},
    }
    rows = []
    for name, case in cases.items():
        for label, approach, store, bits in (("1", 1, "faces", 16), ("2", 2, "faces", 16),
                                             ("2", 2, "faces", 32), ("3 grid", 3, "grid", 16),
                                             ("3 grid", 3, "grid", 32),
                                             ("3 faces", 3, "faces", 16),
                                             ("3 faces", 3, "faces", 32)):
            plan = gpu_plan(approach, PAPER_DIMS, case["faces"], case["cells_drawn"], bits,
                            store)
            rows.append({"case": name, "approach": label, "bits": None if approach == 1
                         else bits, "bytes": int(sum(plan.values())), "plan": plan})
    paper = {"1": 827 * MiB, "3 grid": 1.66 * GiB, "2": 3 * GiB}
    return {"dims": list(PAPER_DIMS), "cases": cases, "rows": rows, "paper": paper}


def _sub_table(script: str, what: str, args) -> tuple[str, dict]:
    """``run(args) -> (markdown, results)`` of a sibling benchmark script; a failure is a line
    in the table, not the end of the run."""
    path = Path(__file__).resolve().parent / script
    if not path.is_file():
        return (f"*{what}: `benchmarks/{script}` is not in this checkout yet.*\n",
                {"skipped": f"benchmarks/{script} absent"})
    spec = importlib.util.spec_from_file_location(f"geoshade_{path.stem}", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    try:
        return mod.run(args)
    except Exception as exc:
        return (f"*{what} failed: {type(exc).__name__}: {exc}*\n",
                {"error": f"{type(exc).__name__}: {exc}"})


def large_table(args) -> tuple[str, dict]:
    """The 1e7/1e8-cell rows with the peers (``grid_large.py``), ``--full`` only."""
    return _sub_table("grid_large.py", "Large-grid benchmark", args)


def parse_table(args, out_dir: Path) -> tuple[str, dict]:
    return _sub_table("grid_parse.py", "Parse benchmark", args)


# --- Markdown ---------------------------------------------------------------------------------
def _ms(v):
    if v is None:
        return "—"
    return f"{v:,.0f}" if v >= 100 else f"{v:.1f}"


def _ratio(a, b):
    return "—" if not a or not b else f"{a / b:.1f}"


def markdown(result: dict) -> str:
    m = result["machine"]
    lines = [MARK_BEGIN, "## grid — corner-point grids (`geoshade bench grid`)", "",
             f"- date: {m['date']}; command: `{result['command']}`",
             f"- machine: {m['cpu']}, {m['cores']} cores usable, {m['ram_gib']:.1f} GiB RAM; "
             f"GL: {m.get('gl_renderer')} ({m.get('gl_version')})",
             f"- Python {m['python']}, numpy {m['numpy']}"
             + (f", PyVista {result['peers'].get('pyvista')}, VTK {result['peers'].get('vtk')}"
                if result["peers"].get("pyvista") else ""),
             "- noisy machine (2 shared cores, other engineers' tests run meanwhile; 1-min load "
             f"average {result['load_range'][0]:.1f}–{result['load_range'][1]:.1f} during the "
             "workers): compare the ratios, measured side by side in one run; every config "
             f"ran {result['repeats']}× (rounds interleaved), each timing is its best round", ""]
    parse_md = result["parse_md"].rstrip()
    lines += ([] if parse_md.lstrip().startswith("#") else ["### Parsing", ""]) + [parse_md, ""]
    mem = result["memory"]
    lines += ["### GPU memory for the paper's (1000, 1000, 100) grid", "",
              "From `layout.gpu_plan`, the sizes the renderer allocates (tests check "
              "`GpuCache.breakdown() == plan`); nothing is allocated here.", ""]
    for name, case in mem["cases"].items():
        lines.append(f"- **{name}**: {case['what']}: {case['faces']:,} visible faces, "
                     f"{case['cells_drawn']:,} cells with a visible face"
                     + (f", {case['fault_faces']:,} fault faces" if case.get("fault_faces")
                        else ""))
    lines += ["", "| approach | ZCORN bits | shell (paper's case) | with faults + inactive | "
              "paper | ≤ 1.0 GB with faults |", "|---|---|---|---|---|---|"]
    by = {}
    for r in mem["rows"]:
        by.setdefault((r["approach"], r["bits"]), {})[r["case"]] = r["bytes"]
    paper = {"1": "827 MB", "3 grid": "~1.66 GB (items sum to 1.61)", "2": "~3 GB (32-bit), "
             "1.5 GB (16-bit)"}
    for (label, bits), v in by.items():
        f = v.get("faulted")
        note = "n/a (conforming only; smeared)" if label == "1" else (
            "✔" if f is not None and f <= GB else "✘")
        lines.append(f"| {label} | {bits or '—'} | {v['shell'] / GiB:.3f} GiB "
                     f"({v['shell'] / GB:.2f} GB) | {f / GiB:.3f} GiB ({f / GB:.2f} GB) | "
                     f"{paper.get(label, '—') if bits in (None, 16) or label == '2' else '—'} "
                     f"| {note} |")
    lines += ["", "### Frames, property and step switches, filters vs PyVista", ""]
    lines.append("| grid | method | faces | GPU bytes | first frame ms | re-render ms | "
                 "edges ms | property switch ms | step switch ms | filter ms | peak RSS MiB | "
                 "PyVista re-render / ours | PyVista switch / ours | RSS ours / PyVista |")
    lines.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for dims in result["sizes"]:
        rows = [r for r in result["rows"] if tuple(r.get("dims") or ()) == tuple(dims)]
        peer = next((r for r in rows if r.get("kind") == "pyvista" and r.get("ok")), None)
        for r in rows:
            name = "×".join(str(d) for d in dims)
            label = r.get("label") or "?"
            if not r.get("ok"):
                lines.append(f"| {name} | {label}: {r.get('error') or r.get('skipped')} |"
                             + " |" * 12)
                continue
            ours = r.get("kind") == "geoshade"
            cells = [name, f"**{label}**" if ours and label == "3 faces" else label,
                     f"{r['faces']:,}" if ours else "—",
                     f"{r['gpu_bytes']:,}" if ours else "—",
                     _ms(r["first_frame_ms"]), _ms(r["frame_ms"]), _ms(r["edges_frame_ms"]),
                     _ms(r["property_switch_ms"]), _ms(r["step_switch_ms"]),
                     _ms(r["filter_ms"]), f"{r['peak_rss_mib']:,.0f}"]
            if not ours:
                cells += ["1", "1", "1"]
            elif peer:
                cells += [_ratio(peer["frame_ms"], r["frame_ms"]),
                          _ratio(peer["property_switch_ms"], r["property_switch_ms"]),
                          f"{r['peak_rss_mib'] / peer['peak_rss_mib']:.2f}"]
            else:
                cells += ["—"] * 3
            lines.append("| " + " | ".join(cells) + " |")
    lines += ["", "Columns: *first frame* = the first draw after construction (shader "
              "compilation included; PyVista: `add_mesh` + first `show`, its surface "
              "extraction included); *re-render* = median of the following frames; *edges* = "
              "the same with cell edges (ours: in the same pass; PyVista: `show_edges=True`); "
              "*property switch* = PORO -> PERMX until the new picture is drawn (ours: new "
              "colour indices written into the existing colour object; PyVista: new active "
              "array + render); *step switch* = SWAT of report step 1; *filter* = show only "
              "`PORO > 0.2` (ours: new visible faces from the grid in memory; PyVista: "
              "`threshold` + new actor + render). Peak RSS = VmHWM of the worker process (on "
              "llvmpipe the \"GPU\" memory is in RAM too).", ""]
    if result.get("large_md"):
        lines += [result["large_md"].rstrip(), ""]
    lines.append(MARK_END)
    return "\n".join(lines) + "\n"


machine_info = harness.machine_info


def _log(msg: str) -> None:
    print(f"[bench grid] {msg}", file=sys.stderr, flush=True)


def main(args, folder: Path) -> int:
    from geoshade.io.output import write_json
    from geoshade.styles.image import parse_size

    t_start = time.perf_counter()
    out_dir = Path(args.output) if getattr(args, "output", None) else Path(folder)
    (out_dir / "results").mkdir(parents=True, exist_ok=True)
    size = parse_size(getattr(args, "size", "1024x768"))
    mode = "quick" if args.quick else "full" if args.full else "default"
    sizes = SIZES[mode]
    peers = {}
    if not args.no_peers and importlib.util.find_spec("pyvista") is not None:
        import importlib.metadata as md

        peers = {"pyvista": md.version("pyvista"), "vtk": md.version("vtk")}
    avail = _status_kib("MemAvailable", "/proc/meminfo")
    mem_limit = MEM_FRACTION * avail * 1024 if avail else None
    _log("parse benchmark ...")
    parse_md, parse_res = parse_table(args, out_dir)
    _log("GPU memory table ...")
    mem = memory_table()
    rows = []
    for dims in sizes:
        base = {"dims": list(dims), "size": list(size), "frames": 5}
        cfgs = [{**base, "kind": "geoshade", "label": lab, "approach": a, "store": s, "bits": b}
                for lab, a, s, b in VARIANTS]
        if peers:
            cfgs.append({**base, "kind": "pyvista", "label": "PyVista ExplicitStructuredGrid"})
        runs: dict[str, list] = {c["label"]: [] for c in cfgs}
        for rnd in range(1 if mode == "quick" else REPEATS):
            for cfg in cfgs:
                _log(f"{dims} {cfg['label']} (round {rnd + 1}) ...")
                res = run_worker(cfg, WORKER_TIMEOUT_S, mem_limit)
                runs[cfg["label"]].append(res)
                _log(f"  {'ok' if res.get('ok') else 'FAILED: ' + str(res.get('error'))} in "
                     f"{res['elapsed_s']:.1f} s, load {res['load_avg_1min'][-1]:.1f}")
        rows += [merge_runs(r) for r in runs.values()]
    large_md, large = ("", None)
    if mode == "full":
        _log("large grids (1e7, 1e8 cells) with the peers ...")
        large_md, large = large_table(args)
    cmd = "geoshade bench grid" + "".join(
        f" --{f.replace('_', '-')}" for f in ("quick", "full", "no_peers") if getattr(args, f))
    loads = [v for r in rows for v in r.get("load_avg_1min") or [] if v]
    result = {"part": PART, "command": cmd, "mode": mode, "size": list(size),
              "repeats": 1 if mode == "quick" else REPEATS,
              "load_range": [min(loads, default=0.0), max(loads, default=0.0)],
              "sizes": [list(d) for d in sizes], "machine": machine_info(), "peers": peers,
              "parse_md": parse_md, "parse": parse_res, "memory": mem, "rows": rows,
              "large_md": large_md, "large": large}
    result["elapsed_s"] = time.perf_counter() - t_start
    md_text = markdown(result)
    print(md_text)
    write_json(out_dir / "results" / "grid.json", result)
    res_md = harness.write_results(out_dir, "grid", md_text, out_dir / "results" / "grid.json")
    _log(f"wrote {res_md} and {out_dir / 'results' / 'grid.json'} "
         f"({result['elapsed_s']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(harness.script_main(worker_main, "grid"))
