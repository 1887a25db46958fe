"""``geoshade grid render``: a corner-point grid coloured by a property, with the paper's
approaches, cell edges, slices, filters, a cutting plane, faults and wells; ``geoshade grid
export``: a sector model of the cells a filter, slice and plane select."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from geoshade.cli.main import finite_float, positive_int
from geoshade.cli.params import add_param_arg, param_hint
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import (
    add_color_args,
    add_distributed_args,
    add_progressive_arg,
    add_render_args,
    add_skip_missing_arg,
    case_inputs,
    color_options,
    distributed_view,
    run_render,
    skip_missing_hint,
)
from geoshade.compute.grid_filter import Filter
from geoshade.compute.grid_index_faces import store_index
from geoshade.errors import InputError
from geoshade.grid.export import FORMATS, export_sector
from geoshade.grid.geometry import parse_slice
from geoshade.grid.options import GridOptions as G
from geoshade.models.grid import CornerPointGrid, WellPath
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
    r.add_argument("--property", help="cell property to colour by, any case, or an expression "
                                      "with --filter's grammar such as 'log10(PERMX)' or "
                                      "'PORO * NTG' (default: one colour)")
    r.add_argument("--step", metavar="K",
                   help="report step: index (0-based), -1 for the last (default), R36 for report "
                        "36, or a date YYYY-MM-DD")
    add_color_args(r, deprecated_range=True)
    r.add_argument("--filter", metavar="EXPR",
                   help="show only cells where EXPR holds, e.g. 'PORO > 0.2 and PERMX > 100' "
                        "(names in any case)")
    r.add_argument("--slice", metavar="i=A:B,j=C:D,k=E:F",
                   help="IJK box, 0-based, B exclusive (numpy slices); 'k=3' is one layer")
    r.add_argument("--plane", metavar="NX,NY,NZ[,D]",
                   help="cutting plane in map coordinates (x east, y north, z up, metres): keep "
                        "the cells whose centre has NX·x + NY·y + NZ·z >= D; without D the plane "
                        "goes through the grid's centre (e.g. 1,0,0 keeps the eastern half; "
                        "write --plane=-1,0,0 when the first number is negative)")
    r.add_argument("--clip", metavar="NX,NY,NZ,D", help=argparse.SUPPRESS)  # deprecated
    r.add_argument("--edges", nargs="?", const="quad", default=G.default("edges"),
                   choices=G.choices("edges"),
                   help="cell edges in the same pass (--edges = quad; paper = the paper's "
                        "per-triangle variant)")
    r.add_argument("--approach", type=int, choices=G.choices("approach"),
                   default=G.default("approach"),
                   help="1: packed nodes (conforming grids), 2: GS from COORD/ZCORN per cell, "
                        "3: faces from the CPU (default, least GPU memory)")
    r.add_argument("--zcorn-store", choices=G.choices("zcorn_store"),
                   default=G.default("zcorn_store"),
                   help="approach 3: depths of the visible faces only (default) or the whole "
                        "ZCORN indexed per face (the paper)")
    r.add_argument("--zcorn-bits", type=int, choices=G.choices("zcorn_bits"),
                   default=G.default("zcorn_bits"),
                   help="ZCORN precision on the GPU (16: the paper's packing; error in stats)")
    r.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="a grid store (geoshade grid ingest): compute its visible faces chunk "
                        "by chunk on a dask cluster (local:N or tcp://HOST:8786); default "
                        "dask threads here")
    add_distributed_args(r, "the grid's layer ranges (faces computed where they are drawn)")
    r.add_argument("--parts", type=positive_int, default=None, metavar="N",
                   help="--distributed: cut the grid into N layer ranges (default two per "
                        "worker, whole k-slabs of the drawing order)")
    r.add_argument("--gpu-memory", metavar="SIZE", default=None,
                   help="GPU memory the picture may use (8G, 512M, bytes): a larger plan of the "
                        "chosen approach stops before any GPU object, naming what it needs "
                        "(`geoshade info CASE --gpu` lists every approach)")
    r.add_argument("--smear-faults", dest="smear_faults", action="store_const", const=True,
                   default=None, help="approach 1 on a faulted grid: average the corners at "
                                      "each node without a warning (the default warns)")
    r.add_argument("--no-smear-faults", dest="smear_faults", action="store_const",
                   const=False, help="approach 1: refuse a faulted grid instead")
    r.add_argument("--faults", choices=G.choices("faults"), default=G.default("faults"),
                   help="fault faces: as the others, highlighted, or hidden")
    r.add_argument("--exaggeration", type=finite_float, default=G.default("exaggeration"),
                   help="vertical exaggeration")
    r.add_argument("--wells", metavar="FILE", action="append",
                   help="well trajectories drawn as tubes (repeat for several files): a "
                        "geoshade wells file ('WELL name' lines, each followed by 'x y z [md]' "
                        "rows and 'MARKER x y z [label]' lines; # comments), an RMS ASCII well "
                        "file (.rmswell/.w: version, type, 'name x y [rkb]', number of logs, "
                        "one line per log, then 'x y z logs...' rows, -999 undefined; a log "
                        "named MD gives measured depths) or a CSV (.csv: rows 'name, x, y, "
                        "z[, md]', header optional); z is depth, down positive; the format "
                        "is found from the suffix or the content")
    r.add_argument("--wells-coords", choices=G.choices("wells_coords"),
                   default=G.default("wells_coords"),
                   help="coordinates of the trajectory file: grid (before MAPAXES) or map")
    r.add_argument("--well-radius", type=finite_float,
                   help="tube radius in metres (default: 0.4%% of the grid's diagonal)")
    r.add_argument("--no-deck-wells", action="store_true",
                   help="do not draw the wells of the deck (WELSPECS/COMPDAT)")
    r.add_argument("--sim-wells", action=argparse.BooleanOptionalAction, default=None,
                   help="the simulation wells of the restart file (IWEL/ICON/ZWEL of the shown "
                        "step) as named pipes through their completion cells, producers green, "
                        "water injectors blue, gas injectors red, shut ones grey (default: "
                        "shown when the restart file has wells)")
    r.add_argument("--no-well-xray", action="store_true",
                   help="do not draw the parts of wells hidden by cells as a half-tone on top")
    r.add_argument("--no-cull", action="store_true", help="draw back faces too")
    r.add_argument("--triad", choices=G.choices("triad"), default=G.default("triad"),
                   help="the axes drawn in the corner: east/north/up (enu) or the grid's I/J/K")
    add_skip_missing_arg(r)
    add_param_arg(r)
    add_render_args(r)
    add_progressive_arg(r, "the coarse level of detail (a grid store's, from 'grid ingest "
                           "--coarse F'; a big grid in memory merged on the fly)")
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
    add_ingest_parser(gsub)


def run_export_cmd(args) -> int:
    """The sector model: the selected cells' bounding IJK box, unselected cells inactive
    (:func:`geoshade.grid.export_sector`)."""
    from geoshade.io import load
    from geoshade.io.output import Outputs

    suffix = Path(args.output).suffix.lower()
    if suffix not in FORMATS:
        raise InputError(f"{args.output}: -o: expected a name ending in "
                         f"{', '.join(FORMATS)} (GRDECL or EGRID)")

    Filter.parse(args.filter)  # the syntax, before reading the case
    Plane.parse(args.plane)
    parse_slice(args.slice, (1 << 62,) * 3)
    inputs = case_inputs(args.case)
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


def read_wells(path) -> list:
    """Well trajectories from a file, through ``geoshade.io.grids.welltraj`` (or the reader
    registry)."""


    if not Path(path).exists():
        raise InputError(f"{path}: no such file (--wells)")
    from geoshade.io.grids.welltraj import read_wells as reader

    wells = reader(path)
    if isinstance(wells, WellPath):
        wells = [wells]
    if not isinstance(wells, list | tuple) or not all(isinstance(w, WellPath) for w in wells):
        raise InputError(f"{path}: not a well trajectory file (--wells)")
    return list(wells)


def run_render_cmd(args) -> int:
    from geoshade.io import load

    options = {
        "property": args.property, "step": args.step, "filter": args.filter,
        "slice": args.slice, "plane": args.plane, "clip_plane": args.clip, "edges": args.edges,
        "approach": args.approach, "faults": args.faults, "exaggeration": args.exaggeration,
        "zcorn_bits": args.zcorn_bits, "zcorn_store": args.zcorn_store,
        "gpu_memory": args.gpu_memory, "scheduler": getattr(args, "scheduler", None),
        "cull": not args.no_cull, "well_radius": args.well_radius,
        "smear_faults": args.smear_faults, "triad": args.triad, **color_options(args),
        "sim_wells": args.sim_wells, "well_xray": not args.no_well_xray,
        "progressive": args.progressive,
    }
    if args.clip is None:
        del options["clip_plane"]
    if args.parts is not None:
        if not args.distributed:
            raise InputError("--parts: applies to --distributed rendering")
        options["parts"] = args.parts
    view_cls = distributed_view(args, "grid", options)
    wells_file = [w for f in args.wells for w in read_wells(f)] if args.wells else None

    def load_grid():
        with progress_bar(f"reading {args.case}", unit="bytes") as cb:
            model = load(args.case, progress=cb, **skip_missing_hint(args), **param_hint(args))
        if not isinstance(model, CornerPointGrid):
            raise InputError(f"{args.case}: not a corner-point grid (got {type(model).__name__})")
        if wells_file is not None:
            return model, {"wells": wells_file, "wells_coords": args.wells_coords}
        if not args.no_deck_wells and model.meta.get("wells"):
            return model, {"wells": list(model.meta["wells"]), "wells_coords": "grid"}
        return model

    inputs = [args.case, *(args.wells or [])]
    with progress_bar("visible faces") as cb:
        return run_render(args, "grid", load_grid, options, inputs=inputs, progress=cb,
                          view_cls=view_cls)


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
                   help="blosc compressor of the chunks (default zstd)")
    g.add_argument("--overwrite", action="store_true",
                   help="replace an existing store (or restart an unfinished one)")
    g.set_defaults(func=run_ingest_cmd)


def run_ingest_cmd(args) -> int:
    """Stream the case into the store slab by slab (resumable: run it again to finish)."""
    from geoshade.io.paths import format_bytes
    from geoshade.io.stores.grid_index import add_index
    from geoshade.io.stores.grid_store import ingest_grid, open_grid_store

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
    from geoshade.grid.lod import read_coarse_level, write_coarse_level

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
