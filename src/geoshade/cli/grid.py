"""``geoshade grid render``: a corner-point grid coloured by a property, with the paper's
approaches, cell edges, slices, filters, a clipping plane, faults and wells."""

from __future__ import annotations

from geoshade.cli.main import add_render_args
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
    r.add_argument("--property", help="cell property to colour by (default: one colour)")
    r.add_argument("--step", type=int, help="report step (0-based) of UNRST properties")
    r.add_argument("--range", type=float, nargs=2, metavar=("LO", "HI"),
                   help="colour range (default: the property's range over active cells)")
    r.add_argument("--colormap", default="viridis", help="matplotlib colour map (viridis)")
    r.add_argument("--filter", metavar="EXPR",
                   help="show only cells where EXPR holds, e.g. 'PORO > 0.2 and PERMX > 100'")
    r.add_argument("--slice", metavar="i=A:B,j=C:D,k=E:F",
                   help="IJK box, 0-based, B exclusive (numpy slices); 'k=3' is one layer")
    r.add_argument("--clip", metavar="NX,NY,NZ,D", type=str,
                   help="clipping plane D metres from the grid's centre: keep the cells on "
                        "the side the normal (NX, NY, NZ) points to (x east, y north, depth "
                        "down), e.g. 1,0,0,0 keeps the eastern half (write --clip=-1,0,0,0 "
                        "when the first number is negative)")
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
    r.add_argument("--smear-faults", action="store_true",
                   help="approach 1 on a faulted grid: average the corners at each node")
    r.add_argument("--faults", choices=("show", "highlight", "hide"), default="show",
                   help="fault faces: as the others, highlighted, or hidden")
    r.add_argument("--exaggeration", type=float, default=1.0, help="vertical exaggeration")
    r.add_argument("--wells", metavar="FILE", help="well trajectory file (drawn as tubes)")
    r.add_argument("--wells-coords", choices=("grid", "map"), default="grid",
                   help="coordinates of the trajectory file: grid (before MAPAXES) or map")
    r.add_argument("--well-radius", type=float, help="tube radius in metres (default: 0.4%% of "
                                                     "the grid's diagonal)")
    r.add_argument("--no-deck-wells", action="store_true",
                   help="do not draw the wells of the deck (WELSPECS/COMPDAT)")
    r.add_argument("--no-cull", action="store_true", help="draw back faces too")
    r.add_argument("--frames", type=int, default=5, help="frames timed for frame_ms (5)")
    add_render_args(r)
    r.set_defaults(func=run_render)


def read_wells(path) -> list:
    """Well trajectories from a file, through ``geoshade.io.welltraj`` (or the reader registry)."""
    from pathlib import Path

    from geoshade.models.grid import WellPath

    if not Path(path).exists():
        raise InputError(f"{path}: no such file (--wells)")
    try:
        from geoshade.io.welltraj import read_wells as reader
    except ImportError:
        from geoshade.io import load as reader
    wells = reader(path)
    if isinstance(wells, WellPath):
        wells = [wells]
    if not isinstance(wells, list | tuple) or not all(isinstance(w, WellPath) for w in wells):
        raise InputError(f"{path}: not a well trajectory file (--wells)")
    return list(wells)


def run_render(args) -> int:
    from geoshade import grid as gridpart
    from geoshade.io import load
    from geoshade.io.output import write_json, write_png
    from geoshade.models.grid import CornerPointGrid

    model = load(args.case)
    if not isinstance(model, CornerPointGrid):
        raise InputError(f"{args.case}: not a corner-point grid (got {type(model).__name__})")
    # check the cheap arguments before any work on the grid
    gridpart.parse_slice(args.slice, model.dims)
    gridpart.parse_clip(args.clip)
    wells = [] if args.no_deck_wells else list(model.meta.get("wells") or [])
    coords = "grid"
    if args.wells:
        wells = read_wells(args.wells)
        coords = args.wells_coords
    img, stats = gridpart.render(
        model, property=args.property, step=args.step, filter=args.filter, slice=args.slice,
        edges=args.edges, approach=args.approach, wells=wells or None, clip_plane=args.clip,
        faults=args.faults, exaggeration=args.exaggeration, view=args.view,
        azimuth=args.azimuth, elevation=args.elevation, zoom=args.zoom, ortho=args.ortho,
        size=args.size, transparent=args.transparent, colormap=args.colormap,
        color_range=args.range, zcorn_bits=args.zcorn_bits, zcorn_store=args.zcorn_store,
        cull=not args.no_cull, wells_coords=coords, well_radius=args.well_radius,
        smear_faults=args.smear_faults, frames=args.frames)
    write_png(args.output, img)
    if args.stats:
        write_json(args.stats, stats)
    prop = stats["property"] or "no property"
    step = "" if stats["step"] is None else f" (step {stats['step']})"
    print(f"{args.output}: {stats['width']}x{stats['height']} {stats['method']}, {prop}{step}, "
          f"{stats['shown_cells']} of {stats['active_cells']} active cells shown, "
          f"{stats['faces_drawn']} faces, {stats['frame_ms']:.1f} ms/frame, "
          f"{stats['gpu_bytes'] / 2**20:.2f} MiB on the GPU")
    return 0
