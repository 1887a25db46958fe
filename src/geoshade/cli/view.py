"""``geoshade view``: the interactive desktop viewer (needs the ``[viewer]`` extra)."""

from __future__ import annotations

import argparse

from geoshade.api import KINDS
from geoshade.cli.core import parse_select
from geoshade.cli.grid import read_wells
from geoshade.cli.main import add_volume_args, finite_float, volume_hints
from geoshade.cli.params import add_param_arg, param_hint
from geoshade.cli.render import (
    RENDER_VIEWS,
    add_color_args,
    add_skip_missing_arg,
    case_inputs,
    color_options,
    deprecated_flag,
    skip_missing_hint,
)
from geoshade.core.options import CoreOptions
from geoshade.errors import InputError
from geoshade.grid.options import GridOptions
from geoshade.styles.image import parse_size
from geoshade.styles.options import CameraSpec
from geoshade.viewer.app import require_qt


def register(sub) -> None:
    p = sub.add_parser(
        "view", help="interactive viewer: turn, zoom, change range/box/step/strata live",
        description="Open PATH (anything geoshade.load reads) in the interactive viewer. Mouse: "
                    "left drag orbit, right/middle drag pan, wheel zoom. Keys: 1-7 or "
                    "I/T/B/F/K/L/R named views, 0 reset, O ortho, +/- zoom, [ ] vertical "
                    "exaggeration, S or Ctrl+S screenshot, H help.")
    p.add_argument("path", nargs="?", metavar="PATH", help="file or folder to open")
    p.add_argument("--demo", nargs="?", const=True, default=False, metavar="PART",
                   help="open the built-in synthetic data of every part (PART first: "
                        f"{', '.join(KINDS)})")
    p.add_argument("--as", dest="kind", choices=KINDS,
                   help="the part to open PATH with (iso: a field over time, via load_field)")
    p.add_argument("--screenshot", metavar="OUT.png",
                   help="draw the first frame, save it as PNG and exit (no display needed)")
    p.add_argument("--size", default="900x650", metavar="WxH", help="3D view size (900x650)")
    p.add_argument("--view", default=CameraSpec().view, choices=RENDER_VIEWS,
                   help="named view (iso)")
    p.add_argument("--azimuth", type=finite_float, help="degrees, overrides the view")
    p.add_argument("--elevation", type=finite_float, help="degrees, overrides the view")
    p.add_argument("--zoom", type=finite_float, default=CameraSpec().zoom,
                   help="zoom factor (1 = whole model)")
    p.add_argument("--ortho", action="store_true", help="orthographic projection")
    add_volume_args(p)
    add_skip_missing_arg(p)
    add_param_arg(p)
    g = p.add_argument_group("part settings (each applies to its part)")
    g.add_argument("--select", nargs="+", metavar=("LO|auto", "HI"),
                   help="core: values selected (default: the darker half of the values); auto: "
                        "the values up to Otsu's threshold")
    g.add_argument("--range", dest="old_select", nargs="+", metavar=("LO|auto", "HI"),
                   help=argparse.SUPPRESS)  # the old name of --select
    g.add_argument("--roi", metavar="cylinder[:CX,CY,R]",
                   help="core: only voxels inside a cylinder along z ('cylinder': fitted to "
                        "the sample)")
    g.add_argument("--mask", metavar="FILE", help="core: only voxels where this mask volume is "
                                                  "nonzero")
    g.add_argument("--box", type=int, nargs=6, metavar=("X0", "Y0", "Z0", "NX", "NY", "NZ"),
                   help="core: sub-volume")
    g.add_argument("--method", choices=CoreOptions.choices("method"),
                   help="core: drawing method")
    g.add_argument("--porosity", choices=CoreOptions.choices("porosity"), metavar="AXIS",
                   help="core: the porosity profile's axis (z)")
    g.add_argument("--filter", metavar="EXPR",
                   help="grid: show only cells where EXPR holds ('PORO > 0.2')")
    g.add_argument("--wells", metavar="FILE", action="append",
                   help="grid: well trajectories drawn as tubes (as grid render's --wells; "
                        "default: the deck's wells)")
    g.add_argument("--wells-coords", choices=GridOptions.choices("wells_coords"),
                   help="grid: coordinates of the --wells files (grid)")
    g.add_argument("--faults", choices=GridOptions.choices("faults"),
                   help="grid: fault faces shown, highlighted or hidden")
    g.add_argument("--property", help="grid: cell property or expression ('log10(PERMX)')")
    g.add_argument("--step", help="grid, iso: report/time step: index, -1 (last, the default), "
                                  "R36 or a date YYYY-MM-DD")
    g.add_argument("--level", type=finite_float, help="iso: isosurface level S*")
    g.add_argument("--keyword", help="iso: array/variable/restart keyword to read (SWAT)")
    g.add_argument("--color-by", help="iso: colour the surface by this quantity")
    g.add_argument("--drape", metavar="IMAGE", help="stacks: image draped on the top surface")
    add_color_args(g, what="the property (grid), colour-by quantity (iso) or selection (core)")
    g.add_argument("--exaggeration", type=finite_float, help="grid, stacks: vertical exaggeration")
    g.add_argument("--distributed", action="store_true",
                   help="core, grid: draw on the --scheduler cluster (a core's bricks or a "
                        "grid's layer ranges on the workers' GPUs, composited by depth)")
    g.add_argument("--scheduler", metavar="ADDRESS",
                   help="core, grid, with --distributed: the dask.distributed scheduler "
                        "(tcp://HOST:8786) or local:N")
    p.set_defaults(func=run)


def _settings(args) -> dict:
    s = {}
    sel = deprecated_flag(args.select, args.old_select, "--range", "--select (the values "
                          "selected)", " for the core")
    if sel is not None:

        s["select"] = parse_select(sel, "--select" if args.select is not None else "--range")
    if args.roi is not None:
        s["roi"] = args.roi
    if args.mask is not None:
        s["mask"] = args.mask
    if args.box is not None:
        s["box"] = list(args.box)
    if args.method is not None:
        s["method"] = args.method
    if args.property is not None:
        s["property"] = args.property
    if args.step is not None:
        s["step"] = args.step
    if args.level is not None:
        s["level"] = args.level
    if args.color_by is not None:
        s["color_by"] = args.color_by
    for name in ("porosity", "filter", "faults", "wells_coords"):
        if getattr(args, name) is not None:
            s[name] = getattr(args, name)
    if args.wells:

        s["wells"] = [w for f in args.wells for w in read_wells(f)]
    s.update(color_options(args))
    cam = {k: getattr(args, k) for k in ("azimuth", "elevation")
           if getattr(args, k) is not None}
    if args.zoom != CameraSpec().zoom:
        cam["zoom"] = args.zoom
    s.update(cam)
    if args.drape is not None:
        s["drape"] = args.drape
    if args.exaggeration is not None:
        s["exaggeration"] = args.exaggeration
    if args.distributed or args.scheduler:
        if not (args.distributed and args.scheduler):
            raise InputError("--distributed and --scheduler ADDRESS|local:N go together (the "
                             "core or grid drawn on a dask cluster)")
        s.update(distributed=True, scheduler=args.scheduler)
    return s


def run(args) -> int:

    if not args.path and not args.demo:
        raise InputError("view: give a PATH to open, or --demo")
    if args.demo not in (True, False) and args.demo not in KINDS:
        raise InputError(f"--demo: unknown part {args.demo!r}; expected one of {', '.join(KINDS)}")
    size = parse_size(args.size)
    if args.screenshot:  # checked before any work: not an input, a writable folder, .png
        from geoshade.io.output import Outputs

        Outputs({"--screenshot": args.screenshot}, case_inputs(args.path),
                {"--screenshot": (".png",)})
    hints = {**volume_hints(args), **skip_missing_hint(args), **param_hint(args)}
    if args.keyword:
        if args.kind not in (None, "iso"):
            raise InputError("--keyword: applies to fields over time (--as iso)")
        args.kind = "iso"
        hints["keyword"] = args.keyword
    if args.skip_missing and args.kind == "iso":  # fields over time do not read INCLUDEs
        raise InputError("--skip-missing: applies to decks and GRDECL files opened as grids")
    require_qt()
    from geoshade.viewer.window import run_viewer

    sources = []
    if args.path:
        sources.append({"source": args.path, "kind": args.kind, "hints": hints,
                        "settings": _settings(args)})
    rc = run_viewer(sources, demo=args.demo, screenshot=args.screenshot, size=size,
                    view=args.view, ortho=args.ortho)
    if args.screenshot and rc == 0:
        print(f"{args.screenshot}: {size[0]}x{size[1]} first frame")
    return rc
