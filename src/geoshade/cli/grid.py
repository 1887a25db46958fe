"""``geoshade grid render``: a corner-point grid coloured by a property, with the paper's
approaches, cell edges, slices, filters, a cutting plane, faults and wells."""

from __future__ import annotations

import argparse

from geoshade.cli.main import finite_float
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import (
    add_color_args,
    add_render_args,
    add_skip_missing_arg,
    color_options,
    run_render,
    skip_missing_hint,
)
from geoshade.errors import InputError


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
    r.add_argument("--edges", nargs="?", const="quad", default="none",
                   choices=("none", "quad", "paper"),
                   help="cell edges in the same pass (--edges = quad; paper = the paper's "
                        "per-triangle variant)")
    r.add_argument("--approach", type=int, choices=(1, 2, 3), default=3,
                   help="1: packed nodes (conforming grids), 2: GS from COORD/ZCORN per cell, "
                        "3: faces from the CPU (default, least GPU memory)")
    r.add_argument("--zcorn-store", choices=("faces", "grid"), default="faces",
                   help="approach 3: depths of the visible faces only (default) or the whole "
                        "ZCORN indexed per face (the paper)")
    r.add_argument("--zcorn-bits", type=int, choices=(16, 32), default=16,
                   help="ZCORN precision on the GPU (16: the paper's packing; error in stats)")
    r.add_argument("--smear-faults", dest="smear_faults", action="store_const", const=True,
                   default=None, help="approach 1 on a faulted grid: average the corners at "
                                      "each node without a warning (the default warns)")
    r.add_argument("--no-smear-faults", dest="smear_faults", action="store_const",
                   const=False, help="approach 1: refuse a faulted grid instead")
    r.add_argument("--faults", choices=("show", "highlight", "hide"), default="show",
                   help="fault faces: as the others, highlighted, or hidden")
    r.add_argument("--exaggeration", type=finite_float, default=1.0, help="vertical exaggeration")
    r.add_argument("--wells", metavar="FILE", action="append",
                   help="well trajectories drawn as tubes (repeat for several files): a "
                        "geoshade wells file ('WELL name' lines, each followed by 'x y z [md]' "
                        "rows and 'MARKER x y z [label]' lines; # comments), an RMS ASCII well "
                        "file (.rmswell/.w: version, type, 'name x y [rkb]', number of logs, "
                        "one line per log, then 'x y z logs...' rows, -999 undefined; a log "
                        "named MD gives measured depths) or a CSV (.csv: rows 'name, x, y, "
                        "z[, md]', header optional); z is depth, down positive; the format "
                        "is found from the suffix or the content")
    r.add_argument("--wells-coords", choices=("grid", "map"), default="grid",
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
    r.add_argument("--triad", choices=("enu", "ijk"), default="enu",
                   help="the axes drawn in the corner: east/north/up (enu) or the grid's I/J/K")
    add_skip_missing_arg(r)
    add_render_args(r)
    r.set_defaults(func=run_render_cmd)


def read_wells(path) -> list:
    """Well trajectories from a file, through ``geoshade.io.welltraj`` (or the reader registry)."""
    from pathlib import Path

    from geoshade.models.grid import WellPath

    if not Path(path).exists():
        raise InputError(f"{path}: no such file (--wells)")
    from geoshade.io.welltraj import read_wells as reader

    wells = reader(path)
    if isinstance(wells, WellPath):
        wells = [wells]
    if not isinstance(wells, list | tuple) or not all(isinstance(w, WellPath) for w in wells):
        raise InputError(f"{path}: not a well trajectory file (--wells)")
    return list(wells)


def run_render_cmd(args) -> int:
    from geoshade.io import load
    from geoshade.models.grid import CornerPointGrid

    options = {
        "property": args.property, "step": args.step, "filter": args.filter,
        "slice": args.slice, "plane": args.plane, "clip_plane": args.clip, "edges": args.edges,
        "approach": args.approach, "faults": args.faults, "exaggeration": args.exaggeration,
        "zcorn_bits": args.zcorn_bits, "zcorn_store": args.zcorn_store,
        "cull": not args.no_cull, "well_radius": args.well_radius,
        "smear_faults": args.smear_faults, "triad": args.triad, **color_options(args),
        "sim_wells": args.sim_wells, "well_xray": not args.no_well_xray,
    }
    if args.clip is None:
        del options["clip_plane"]
    wells_file = [w for f in args.wells for w in read_wells(f)] if args.wells else None

    def load_grid():
        with progress_bar(f"reading {args.case}", unit="bytes") as cb:
            model = load(args.case, progress=cb, **skip_missing_hint(args))
        if not isinstance(model, CornerPointGrid):
            raise InputError(f"{args.case}: not a corner-point grid (got {type(model).__name__})")
        if wells_file is not None:
            return model, {"wells": wells_file, "wells_coords": args.wells_coords}
        if not args.no_deck_wells and model.meta.get("wells"):
            return model, {"wells": list(model.meta["wells"]), "wells_coords": "grid"}
        return model

    inputs = [args.case, *(args.wells or [])]
    with progress_bar("visible faces") as cb:
        return run_render(args, "grid", load_grid, options, inputs=inputs, progress=cb)
