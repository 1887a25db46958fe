"""``geoshade grid render``: a corner-point grid coloured by a property, with the paper's
approaches, cell edges, slices, filters, a cutting plane, faults and wells; ``geoshade grid
export``: a sector model of the cells a filter, slice and plane select."""

from __future__ import annotations

import time
from pathlib import Path

from geoshade.cli.options import add_option_args, given_options
from geoshade.cli.params import add_param_arg, param_hint
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import (
    add_animation_args,
    add_render_args,
    add_skip_missing_arg,
    model_inputs,
    run_render,
    skip_missing_hint,
)
from geoshade.compute.grid.filters import Filter
from geoshade.compute.grid.index_faces import store_index
from geoshade.errors import InputError
from geoshade.grid.api import animate
from geoshade.grid.export import FORMATS, export_sector
from geoshade.grid.geometry import parse_slice
from geoshade.grid.lod import read_coarse_level, write_coarse_level
from geoshade.grid.options import GridOptions
from geoshade.io import load
from geoshade.io.formats import case_files
from geoshade.io.output import Outputs, json_bytes
from geoshade.io.paths import format_bytes
from geoshade.io.stores.grid_index import add_index
from geoshade.io.stores.grid_store import ingest_grid, open_grid_store
from geoshade.models.grid import CornerPointGrid
from geoshade.styles.options import Plane


def register(sub) -> None:
    p = sub.add_parser("grid", help="reservoir grids: render a corner-point grid (GRDECL, .DATA, "
                                    "EGRID) coloured by a property")
    gsub = p.add_subparsers(dest="grid_command", metavar="ACTION")
    gsub.required = True
    r = gsub.add_parser("render", help="render the grid's visible cell faces")
    r.add_argument("case", metavar="CASE",
                   help="GRDECL file (.grdecl/.grid), a .DATA deck or an EGRID (with INIT/UNRST "
                        "beside it)")
    add_skip_missing_arg(r)
    add_param_arg(r)
    add_render_args(r, "grid")
    r.set_defaults(func=run_render_cmd)

    e = gsub.add_parser("export", help="write a sector model: the cells a filter, slice and "
                                       "plane select, as GRDECL or EGRID + INIT")
    e.add_argument("case", metavar="CASE", help="the grid: GRDECL, .DATA deck or EGRID")
    e.add_argument("-o", "--output", required=True, metavar="SECTOR.GRDECL|.EGRID",
                   help="GRDECL (.grdecl/.grid/.inc: every digit) or EGRID (.egrid, with "
                        "SECTOR.INIT beside it: PORV and the static properties)")
    e.add_argument("--filter", metavar="EXPR",
                   help="keep the cells where EXPR holds, e.g. 'PORO > 0.2 and PERMX > 100'")
    e.add_argument("--slice", metavar="i=A:B,j=C:D,k=E:F",
                   help="IJK box, 0-based, B exclusive (numpy slices); 'k=3' is one layer")
    e.add_argument("--plane", metavar="NX,NY,NZ[,D]",
                   help="keep the cells whose centre has NX·x + NY·y + NZ·z >= D (map "
                        "coordinates, z up; without D through the grid's centre)")
    e.add_argument("--step", metavar="K",
                   help="report step of the filter's report-step keywords (default: the last)")
    add_skip_missing_arg(e)
    add_param_arg(e)
    e.set_defaults(func=run_export_cmd)
    add_animate_parser(gsub)
    add_ingest_parser(gsub)


def run_export_cmd(args) -> int:
    """The sector model: the selected cells' bounding IJK box, unselected cells inactive
    (:func:`geoshade.grid.export_sector`)."""

    suffix = Path(args.output).suffix.lower()
    if suffix not in FORMATS:
        raise InputError(f"{args.output}: -o: expected a name ending in "
                         f"{', '.join(FORMATS)} (GRDECL or EGRID)")

    Filter.parse(args.filter)  # the syntax, before reading the case
    Plane.parse(args.plane)
    parse_slice(args.slice, (1 << 62,) * 3)
    inputs = case_files(args.case)
    Outputs({"-o": args.output}, inputs)  # checked before reading the case
    with progress_bar(f"reading {args.case}", unit="bytes") as cb:
        grid = load(args.case, progress=cb, **skip_missing_hint(args), **param_hint(args))
    if not isinstance(grid, CornerPointGrid):
        raise InputError(f"{args.case}: not a corner-point grid (got {type(grid).__name__})")
    with progress_bar("pore volumes") as cb:
        out = export_sector(grid, args.output, filter=args.filter, slice=args.slice,
                            plane=args.plane, step=args.step, inputs=inputs, progress=cb)
    nx, ny, nz = out.grid.dims
    print(f"{', '.join(map(str, out.files))}: sector {out.box_text()} ({nx}×{ny}×{nz} cells, "
          f"{out.cells} active)")
    return 0


def run_render_cmd(args) -> int:
    def load_grid():
        with progress_bar(f"reading {args.case}", unit="bytes") as cb:
            model = load(args.case, progress=cb, **skip_missing_hint(args), **param_hint(args))
        if not isinstance(model, CornerPointGrid):
            raise InputError(f"{args.case}: not a corner-point grid (got {type(model).__name__})")
        return model

    with progress_bar("visible faces") as cb:
        return run_render(args, "grid", load_grid, inputs=[args.case], progress=cb)


# --- geoshade grid animate ----------------------------------------------------------------------
def add_animate_parser(gsub) -> None:
    """``geoshade grid animate CASE --property SWAT -o OUT.mp4 [--summary FOPR]``."""
    a = gsub.add_parser("animate", help="render a report-step property at every step into an "
                                        ".mp4 or .gif (the summary curves under the frames)")
    a.add_argument("case", metavar="CASE", help="an ECLIPSE/OPM case with report steps")
    add_skip_missing_arg(a)
    add_param_arg(a)
    add_option_args(a, {"grid": GridOptions}, skip=("step", "camera"),
                    defaults={"size": "1280x720"})
    add_animation_args(a)
    a.set_defaults(func=run_animate_cmd)


def run_animate_cmd(args) -> int:
    opts = {"size": "1280x720", "annotations": True, **given_options(args, GridOptions)}
    with Outputs({"-o": args.output, "--stats": args.stats}, case_files(args.case),
                 {"-o": (".mp4", ".gif"), "--stats": (".json",)}) as out:
        with progress_bar(f"reading {args.case}", unit="bytes") as cb:
            grid = load(args.case, progress=cb, **skip_missing_hint(args), **param_hint(args))
        if not isinstance(grid, CornerPointGrid):
            raise InputError(f"{args.case}: not a corner-point grid (got {type(grid).__name__})")
        out.protect(model_inputs(grid))
        with progress_bar("rendering steps", unit="steps") as cb:
            res = animate(grid, out.path("-o"), fps=args.fps, steps=args.steps,
                          progress=cb, **opts)
        res["output"] = str(args.output)
        out.put("--stats", json_bytes(res))
        out.commit()
    print(f"{args.output}: {res['frames']} steps at {res['width']}x{res['height']}, "
          f"{res['fps']:g} fps, median {res['frame_ms']:.1f} ms/frame, {res['seconds']:.1f} s "
          "in all")
    return 0


# --- geoshade grid ingest (out of core: a chunked zarr grid store) ------------------------------
def add_ingest_parser(gsub) -> None:
    """``geoshade grid ingest CASE -o CASE.zarr``."""
    g = gsub.add_parser("ingest", help="stream a case (EGRID + INIT + UNRST, or GRDECL) into a "
                                       "chunked zarr grid store for grids beyond memory")
    g.add_argument("case", metavar="CASE", nargs="?",
                   help="any file of an ECLIPSE/OPM case (EGRID with INIT and restarts beside "
                        "it) or a GRDECL file / .DATA deck, streamed k-slab by k-slab "
                        "(block-centred decks are read in memory)")
    g.add_argument("-o", "--output", metavar="CASE.zarr", help="store to write")
    g.add_argument("--index-only", metavar="STORE",
                   help="add (or rebuild) the index of an existing grid store: its visible "
                        "faces, corner depths, per-chunk statistics and face-cell values, so "
                        "opening, switches, filters and slices read little (written beside, "
                        "then renamed)")
    g.add_argument("--chunks", nargs=3, type=int, metavar=("CI", "CJ", "CK"),
                   default=(128, 128, 16),
                   help="cells per chunk along i, j, k (default 128 128 16); memory is about a "
                        "slab of CK layers")
    g.add_argument("--coarse", metavar="F", choices=("2", "4", "8", "auto"),
                   help="also keep a coarse level of detail in the store (cells merged FxFxF "
                        "along pillars, faults at kept pillars kept; auto: the smallest F "
                        "leaving at most 2 M cells), drawn first by 'grid render "
                        "--progressive' and the viewer; with a store and no -o: add it to that "
                        "store")
    g.add_argument("--compressor", default="zstd", choices=("zstd", "lz4", "lz4hc", "zlib"),
                   help="blosc compressor of the chunks (default zstd, the smallest store; "
                        "lz4 for a store meant for filters and slices: its ZCORN chunks "
                        "decode in ~60 %% of zstd's time, for ~1.6x the disk)")
    g.add_argument("--overwrite", action="store_true",
                   help="replace an existing store (or restart an unfinished one)")
    g.set_defaults(func=run_ingest_cmd)


def run_ingest_cmd(args) -> int:
    """Stream the case into the store slab by slab (resumable: run it again to finish)."""

    if args.index_only is not None:
        if args.case is not None or args.output is not None:
            raise InputError("grid ingest --index-only STORE: takes the store only (no CASE, "
                             "no -o)")
        with progress_bar(f"indexing {args.index_only}", unit="steps") as cb:
            built = add_index(open_grid_store(args.index_only), store_index, progress=cb)
        print(f"{args.index_only}: index of {built.faces} faces, {built.cells} face cells, "
              f"{built.chunks} chunks, {built.seconds:.1f} s")
        return 0
    if args.coarse is not None and args.output is None and args.case is not None:
        return _write_coarse(args.case, args.coarse)   # a store's coarse level only
    if args.case is None or args.output is None:
        raise InputError("grid ingest: expected CASE -o CASE.zarr (or --index-only STORE)")
    with progress_bar(f"ingesting {args.case}", unit="slabs") as cb, \
            progress_bar("building the index", unit="steps") as icb:
        rep = ingest_grid(args.case, args.output, chunks=tuple(args.chunks), progress=cb,
                          overwrite=args.overwrite, compressor=args.compressor,
                          index=store_index, index_progress=icb)
    nx, ny, nz = rep.dims
    how = f"resumed, {rep.slabs_skipped} slabs kept" if rep.resumed else "new"
    print(f"{rep.path}: {nx}×{ny}×{nz} cells, chunks {'×'.join(map(str, rep.chunks))}, "
          f"{rep.slabs_written} of {rep.slabs} slabs written ({how}), "
          f"{len(rep.arrays)} arrays, {rep.seconds:.1f} s, about "
          f"{format_bytes(rep.memory_bytes)} in memory")
    if rep.index is not None:
        print(f"{rep.path}: index of {rep.index.faces} faces, {rep.index.cells} face cells, "
              f"{rep.index.chunks} chunks built in {rep.index.seconds:.1f} s")
    if args.coarse is not None:
        return _write_coarse(rep.path, args.coarse)
    return 0


def _write_coarse(store, f: str) -> int:
    """``grid ingest --coarse F``: the store's coarse level of detail (written beside, then
    renamed into the store)."""

    t0 = time.perf_counter()
    with progress_bar("coarse level", unit="steps") as cb:
        path = write_coarse_level(store, f, progress=cb)
    level = read_coarse_level(store)
    if level is None:   # pragma: no cover - just written
        raise InputError(f"{store}: the coarse level was not kept")
    n = level.meta["lod"]["factor"]
    print(f"{path}: coarse level, cells merged {n}×{n}×{n}: "
          f"{'×'.join(map(str, level.dims))} cells, {time.perf_counter() - t0:.1f} s")
    return 0
