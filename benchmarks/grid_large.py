"""``geoshade bench grid --full``, large grids: 1e7 and 1e8 cells in memory, beside the peers.

Cases are written by :mod:`grid_cases` (streamed, independent of geoshade's writers) into the temp
folder once: ``BIG.EGRID/INIT/UNRST`` of (1000, 1000, 10) and (1000, 1000, 100) (two faults,
5 % inactive blobs, PORO/PERMX, SWAT at two report steps) and the (1000, 1000, 100) GRDECL.

Each reader runs in its own subprocess (peak RSS = VmHWM of that process; a time limit and a
memory limit of :data:`MEM_FRACTION` of the available memory — ending at one is a result too):

- **geoshade** (EGRID+INIT+UNRST, and GRDECL at 1e8): ``geoshade.load`` then a ``GridView``
  (approach 3, faces) to a first picture at 1024×768, then a property switch (PORO -> PERMX),
  a report-step switch (SWAT step 1), a filter (``PERMX > 1000``) and an IJK slice, each timed
  to its next picture;
- **xtgeo**: ``grid_from_file`` + ``gridproperty_from_file`` (PORO) — reading only;
- **resdata**: ``Grid`` + ``ResdataFile`` (PORO) — reading only;
- **PyVista**: ``ExplicitStructuredGrid`` from the corner points (as ``bench_grid`` builds it)
  with PORO, inactive cells hidden, and its first off-screen picture.

``run(args) -> (markdown, results)`` is called by ``bench_grid.main``;
``python grid_large.py --worker JSON`` runs one config.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness
from harness import peak_rss_mib

DIMS = {"1e7": (1000, 1000, 10), "1e8": (1000, 1000, 100), "1e9": (2000, 2000, 250)}
MEM_FRACTION = 0.85
TIMEOUT_S = 900
FILTER, SLICE = "PERMX > 1000", "i=200:800,j=100:900"
GiB = 2**30
TARGETS = {"first_s": 60.0, "first_grdecl_s": 240.0, "peak_gib": 6.0, "property_s": 2.0,
           "filter_s": 15.0, "store_peak_gib": 8.0}


def case_folder(label: str) -> Path:
    return Path(tempfile.gettempdir()) / "geoshade-grid-large" / label


def ensure_case(label: str, grdecl: bool = False) -> Path:
    """The EGRID case (and GRDECL) of ``label``, written once; the folder."""
    import grid_cases

    folder = case_folder(label)
    if not (folder / "BIG.UNRST").is_file():
        grid_cases.write_case(folder, *DIMS[label], steps=2)
    if grdecl and not (folder / "BIG.GRDECL").is_file():
        part = folder / "BIG.GRDECL.part"
        grid_cases.write_grdecl_case(part, *DIMS[label])
        part.rename(folder / "BIG.GRDECL")
    return folder


# --- workers -----------------------------------------------------------------------------------
def worker_geoshade(cfg: dict) -> dict:
    """A case (EGRID, GRDECL) or a grid store (drawn out of core) to a first picture and
    through the switches."""
    import warnings

    import geoshade
    from geoshade.grid import GridView
    from geoshade.render.context import get_context

    warnings.simplefilter("ignore")
    ctx = get_context()
    out: dict = {"kind": "geoshade", "label": cfg["label"], "source": cfg["source"]}
    t0 = time.perf_counter()
    g = geoshade.load(cfg["path"])
    out["load_s"] = time.perf_counter() - t0
    out["load_peak_gib"] = peak_rss_mib() / 1024
    if cfg.get("progressive"):   # the coarse level of detail first (issue 26, target 2)
        view = GridView(g, property="PORO", size=(1024, 768), ctx=ctx, progressive=True)
        _, cst = view.draw(frames=1)
        out["coarse_s"] = time.perf_counter() - t0
        out["coarse"] = {k: cst.get(k) for k in ("coarse", "level", "coarse_ratio", "faces")}
        out["coarse_peak_gib"] = peak_rss_mib() / 1024
        view.refine()
    else:
        view = GridView(g, property="PORO", size=(1024, 768), ctx=ctx)
    _, st = view.draw(frames=1)
    out["first_s"] = time.perf_counter() - t0
    out["index"] = st.get("index")
    out["faces_from"] = st.get("faces_from")
    out["first_peak_gib"] = peak_rss_mib() / 1024  # the first picture's own peak
    out["faces"] = st["faces"]
    out["gpu_bytes"] = st["gpu_bytes"]
    out["frame_ms"] = st["frame_ms"]
    out["cells"], out["active_cells"] = g.ncells, g.nactive

    def timed(change, name: str) -> float:
        """The change and its next frame; the change alone (the CPU part: faces, colours,
        upload) is kept as ``<name>_cpu_s``, the frame as ``<name>_frame_s``."""
        t = time.perf_counter()
        change()
        t1 = time.perf_counter()
        view.draw(frames=1, count=False)
        t2 = time.perf_counter()
        out[f"{name}_cpu_s"], out[f"{name}_frame_s"] = t1 - t, t2 - t1
        return t2 - t

    out["property_s"] = timed(lambda: view.update(property="PERMX"), "property")
    out["switch_peak_gib"] = peak_rss_mib() / 1024  # peak up to the switches (no filter yet)
    out["property_colours_ms"] = view.colors_ms
    if g.steps:
        out["step_s"] = timed(lambda: view.update(property="SWAT", step=1), "step")
    view.update(property="PORO")
    out["filter_s"] = timed(lambda: view.update(filter=FILTER), "filter")
    out["filter_peak_gib"] = peak_rss_mib() / 1024
    out["filter_faces"] = len(view.faces)
    fst = view.draw(frames=1, count=False)[1]
    out["filter_from"] = {k: fst.get(k) for k in ("faces_from", "chunks_skipped", "values_from")
                          if k in fst}
    out["filter_faces_ms"] = view.faces_ms
    view.update(filter=None)
    out["slice_s"] = timed(lambda: view.update(slice=cfg.get("slice", SLICE)), "slice")
    out["slice_faces"] = len(view.faces)
    view.release()
    out["peak_rss_mib"] = peak_rss_mib()
    return out


def worker_xtgeo(cfg: dict) -> dict:
    import warnings

    import xtgeo

    warnings.simplefilter("ignore")
    t0 = time.perf_counter()
    grid = xtgeo.grid_from_file(cfg["path"])
    poro = xtgeo.gridproperty_from_file(str(Path(cfg["path"]).with_suffix(".INIT")),
                                        name="PORO", grid=grid)
    return {"kind": "xtgeo", "label": cfg["label"], "read_s": time.perf_counter() - t0,
            "cells": int(grid.ntotal), "poro_mean": float(poro.values.mean()),
            "xtgeo": xtgeo.__version__, "peak_rss_mib": peak_rss_mib()}


def worker_resdata(cfg: dict) -> dict:
    import resdata
    from resdata.grid import Grid
    from resdata.resfile import ResdataFile

    t0 = time.perf_counter()
    grid = Grid(cfg["path"])
    init = ResdataFile(str(Path(cfg["path"]).with_suffix(".INIT")))
    poro = init["PORO"][0].numpy_copy()
    return {"kind": "resdata", "label": cfg["label"], "read_s": time.perf_counter() - t0,
            "cells": int(grid.get_global_size()), "poro_mean": float(poro.mean()),
            "resdata": resdata.__version__, "peak_rss_mib": peak_rss_mib()}


def worker_pyvista(cfg: dict) -> dict:
    import numpy as np
    import pyvista as pv
    from bench_grid import corner_points

    import geoshade

    pv.OFF_SCREEN = True
    t0 = time.perf_counter()
    g = geoshade.load(cfg["path"])
    nx, ny, nz = g.dims
    mesh = pv.ExplicitStructuredGrid(np.array([nx + 1, ny + 1, nz + 1]), corner_points(g))
    mesh.cell_data["PORO"] = np.asarray(g.properties["PORO"]).ravel(order="F")
    mesh = mesh.hide_cells(np.flatnonzero(~g.active.ravel(order="F")))
    build_s = time.perf_counter() - t0
    plotter = pv.Plotter(off_screen=True, window_size=[1024, 768])
    plotter.add_mesh(mesh, scalars="PORO", show_scalar_bar=False)
    plotter.view_isometric()
    plotter.show(auto_close=False)
    first_s = time.perf_counter() - t0
    plotter.close()
    return {"kind": "pyvista", "label": cfg["label"], "build_s": build_s, "first_s": first_s,
            "pyvista": pv.__version__, "peak_rss_mib": peak_rss_mib()}


WORKERS = {"geoshade": worker_geoshade, "store": worker_geoshade, "xtgeo": worker_xtgeo,
           "resdata": worker_resdata, "pyvista": worker_pyvista}


def worker_main(config_json: str) -> int:
    return harness.worker_main(config_json, lambda cfg: WORKERS[cfg["kind"]],
                               keep=("kind", "label"))


# --- parent ------------------------------------------------------------------------------------
def _log(msg: str) -> None:
    print(f"[bench grid large] {msg}", file=sys.stderr, flush=True)


def configs(labels, peers: bool) -> list[dict]:
    cfgs = []
    for label in labels:
        folder = ensure_case(label, grdecl=label == "1e8")
        egrid = str(folder / "BIG.EGRID")
        cfgs.append({"kind": "geoshade", "label": label, "source": "EGRID", "path": egrid})
        if label == "1e8":
            cfgs.append({"kind": "geoshade", "label": label, "source": "GRDECL",
                         "path": str(folder / "BIG.GRDECL")})
            store = folder / "BIG.zarr"
            if not store.is_dir():  # geoshade grid ingest (streamed; ~1 min), its index
                from geoshade.compute.grid.index_faces import store_index
                from geoshade.grid.lod import write_coarse_level
                from geoshade.io.stores.grid_store import ingest_grid

                ingest_grid(egrid, store, index=store_index)
                write_coarse_level(store, 4)
            cfgs.append({"kind": "store", "label": label, "source": "store",
                         "path": str(store), "progressive": True})
        if peers:
            cfgs += [{"kind": k, "label": label, "path": egrid}
                     for k in ("xtgeo", "resdata", "pyvista")]
    return cfgs


def run(args, labels=("1e7", "1e8")) -> tuple[str, dict]:
    """The rows of ``labels`` and, when its store is there, the 1e9-cell grid store."""
    avail = harness.status_kib("MemAvailable", "/proc/meminfo")
    mem_limit = MEM_FRACTION * avail * 1024 if avail else None
    peers = not getattr(args, "no_peers", False)
    rows = []
    for cfg in configs(labels, peers):
        _log(f"{cfg['label']} {cfg['kind']} {cfg.get('source', '')} ...")
        res = harness.run_worker(__file__, cfg, TIMEOUT_S, mem_limit, keep=("kind", "label"))
        res.setdefault("source", cfg.get("source", "EGRID"))
        _log(f"  {'ok' if res.get('ok') else 'FAILED: ' + str(res.get('error'))} in "
             f"{res['elapsed_s']:.0f} s, peak {res.get('peak_rss_mib', 0) / 1024:.2f} GiB")
        rows.append(res)
    e9 = e9_store()
    if e9 is not None:
        cfg = {"kind": "store", "label": "1e9", "source": "store", "path": str(e9),
               "slice": "i=400:1600,j=200:1800", "progressive": True}
        _log("1e9 store ...")
        res = harness.run_worker(__file__, cfg, 3 * TIMEOUT_S, mem_limit, keep=("kind", "label"))
        res.setdefault("source", "store")
        _log(f"  {'ok' if res.get('ok') else 'FAILED: ' + str(res.get('error'))} in "
             f"{res['elapsed_s']:.0f} s, peak {res.get('peak_rss_mib', 0) / 1024:.2f} GiB")
        rows.append(res)
    result = {"dims": DIMS, "filter": FILTER, "slice": SLICE, "targets": TARGETS,
              "mem_limit_gib": (mem_limit or 0) / GiB, "rows": rows}
    if "1e8" in labels:  # GRDECL -> grid store, streamed (grid_ingest_grdecl.py)
        import grid_ingest_grdecl

        result["grdecl_ingest"] = grid_ingest_grdecl.run(case_folder("1e8"), TIMEOUT_S,
                                                         mem_limit)
    return markdown(result), result


def e9_store() -> Path | None:
    """The (2000, 2000, 250) generated store (``grid_store_case.py``, ~9 min to write, 7.4 GB):
    used when it is in the temp folder or ``GEOSHADE_BENCH_1E9=1`` asks to write it."""
    import os

    store = case_folder("1e9") / "BIG.zarr"
    if store.is_dir():
        return store
    if os.environ.get("GEOSHADE_BENCH_1E9") != "1":
        _log("1e9 store skipped (set GEOSHADE_BENCH_1E9=1 to write it: ~9 min, 7.4 GB)")
        return None
    import grid_store_case

    store.parent.mkdir(parents=True, exist_ok=True)
    grid_store_case.main([str(store), "2000", "2000", "250", "--steps", "2", "--coarse", "4"])
    return store


def _s(v) -> str:
    return "—" if v is None else f"{v:,.1f}"


def _ok(v, limit) -> str:
    return "" if v is None else (" ✔" if v <= limit else " ✘")


def _coarse(r: dict) -> str:
    """A store row's coarse preview time and where its faces came from."""
    out = f" (coarse preview {_s(r['coarse_s'])})" if r.get("coarse_s") is not None else ""
    return out + (f", faces from the {r['faces_from']}" if r.get("faces_from") else "")


def markdown(result: dict) -> str:
    t = result["targets"]
    lines = ["### 1e7 and 1e8 cells in memory (issue 16, target 1)", "",
             f"Generated cases (`benchmarks/grid_cases.py`: 1000 × 1000 × 10 and × 100 cells, two "
             f"faults, 5 % inactive blobs, PORO/PERMX, SWAT at 2 report steps), each reader in "
             f"its own process under a {result['mem_limit_gib']:.1f} GiB memory limit and a "
             f"{TIMEOUT_S} s time limit. Targets at 1e8: first picture ≤ {t['first_s']:.0f} s "
             f"(EGRID) / ≤ {t['first_grdecl_s']:.0f} s (GRDECL), peak RSS ≤ {t['peak_gib']:.0f} "
             f"GiB, property switch ≤ {t['property_s']:.0f} s, filter and slice ≤ "
             f"{t['filter_s']:.0f} s (✔/✘ beside each 1e8 figure); a grid store (`geoshade grid "
             f"ingest`, drawn out of core) of 1e9 cells: peak RSS ≤ {t['store_peak_gib']:.0f} "
             "GiB.", "",
             "| cells | reader | load s | first picture s | peak RSS GiB | faces | property "
             "switch s | step switch s | filter s (faces) | slice s (faces) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        label = r.get("label")
        name = r.get("kind", "?") + (f" ({r.get('source')})" if r.get("kind") == "geoshade"
                                     else "")
        if not r.get("ok"):
            lines.append(f"| {label} | {name} | {r.get('error', '?')[:140]} |" + " |" * 7)
            continue
        big = label == "1e8"
        peak = r["peak_rss_mib"] / 1024
        if r.get("source") == "store" and label == "1e9":
            first = r.get("first_peak_gib", peak)
            cells = [_s(r["load_s"]), _s(r["first_s"]) + _coarse(r),
                     f"{first:.2f}{_ok(first, t['store_peak_gib'])} (with the filter: "
                     f"{peak:.2f}{_ok(peak, t['store_peak_gib'])})", f"{r['faces']:,}",
                     _s(r["property_s"]), _s(r.get("step_s")),
                     f"{_s(r['filter_s'])} ({r['filter_faces']:,})",
                     f"{_s(r['slice_s'])} ({r['slice_faces']:,})"]
        elif r["kind"] == "geoshade":
            first_lim = t["first_grdecl_s"] if r.get("source") == "GRDECL" else t["first_s"]
            cells = [_s(r["load_s"]), _s(r["first_s"]) + (_ok(r["first_s"], first_lim)
                                                         if big else "") + _coarse(r),
                     f"{peak:.2f}" + (_ok(peak, t["peak_gib"]) if big else ""),
                     f"{r['faces']:,}",
                     _s(r["property_s"]) + (_ok(r["property_s"], t["property_s"]) if big
                                            else ""),
                     _s(r.get("step_s")),
                     f"{_s(r['filter_s'])}{_ok(r['filter_s'], t['filter_s']) if big else ''} "
                     f"({r['filter_faces']:,})",
                     f"{_s(r['slice_s'])}{_ok(r['slice_s'], t['filter_s']) if big else ''} "
                     f"({r['slice_faces']:,})"]
        elif r["kind"] == "pyvista":
            cells = [_s(r["build_s"]), _s(r["first_s"]), f"{peak:.2f}"] + ["—"] * 5
        else:
            cells = [_s(r["read_s"]), "— (no picture)", f"{peak:.2f}"] + ["—"] * 5
        lines.append(f"| {label} | {name} | " + " | ".join(cells) + " |")
    lines += ["", "*peak RSS* of a 1e9 store: the first picture's, then the whole run's (the "
              "filter shows ~9e7 faces); "
              "*load* = file to model in memory (peers: their reader, grid and PORO); "
              "*first picture* = from the start of reading to the first drawn frame; the "
              f"switches are timed to the next drawn frame; filter `{result['filter']}`, slice "
              f"`{result['slice']}`. Peers' rows that end at a limit are results: that is what "
              "the user gets on this machine."]
    import grid_ingest_grdecl

    lines += grid_ingest_grdecl.markdown(result.get("grdecl_ingest"))
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(harness.script_main(worker_main, "grid_large"))
