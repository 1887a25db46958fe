"""``geoshade core render|porosity`` (and ``ingest``, see :mod:`geoshade.cli.ingest`)."""

from __future__ import annotations

import argparse
import math

from geoshade.cli import ingest as _big  # ingest, --scheduler, --bricks, --level
from geoshade.cli.main import add_volume_args, finite_float
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import (
    add_color_args,
    add_distributed_args,
    add_progressive_arg,
    add_render_args,
    color_options,
    deprecated_flag,
    distributed_view,
    run_render,
)
from geoshade.compute.porosity import csv_text
from geoshade.core.options import CoreOptions as C
from geoshade.errors import InputError


def _add_select(p, required: bool) -> None:
    p.add_argument("--select", nargs="+", metavar=("LO|auto", "HI"), required=False,
                   help="values selected, inclusive, in the data's units (the pore space or "
                        "the mineral skeleton); auto: the pore space, the values up to Otsu's "
                        "threshold of the box's voxels inside the ROI" + ("" if required else
                                                   "; default: the whole dtype range"))
    p.add_argument("--range", dest="old_select", nargs="+", metavar=("LO|auto", "HI"),
                   help=argparse.SUPPRESS)  # the old name of --select, still accepted


def add_roi_args(p) -> None:
    """``--roi`` and ``--mask``: the region of interest beyond the box."""
    p.add_argument("--roi", metavar="cylinder[:CX,CY,R]|sample",
                   help="only the voxels inside count and are drawn: 'cylinder' fits a "
                        "cylinder along z to the sample scanned in air (Otsu of a few slices, "
                        "footprint centroid and area), 'cylinder:CX,CY,R' in voxels, 'sample' "
                        "the sample detected in air (its footprint over the slices holding it)")
    p.add_argument("--mask", metavar="FILE",
                   help="a mask volume of the same shape: only voxels where it is nonzero count "
                        "and are drawn (a raw mask: one uint8/uint16 per voxel)")
    p.add_argument("--sample", choices=C.choices("sample"), default=C.default("sample"),
                   help="without --roi/--mask, draw and count only the sample detected in air "
                        "(auto: its footprint over the slices; none: every voxel of the box)")


def roi_options(args) -> dict:
    """``roi``/``mask`` options from ``--roi``/``--mask`` (only those given)."""
    out = {}
    if getattr(args, "roi", None):
        out["roi"] = args.roi
    if getattr(args, "mask", None):
        out["mask"] = args.mask
    if getattr(args, "sample", C.default("sample")) != C.default("sample"):
        out["sample"] = args.sample
    return out


def parse_select(values, flag: str = "--select"):
    """``--select`` words -> ``(lo, hi)``, ``"auto"`` or None.

    >>> parse_select(["0", "80"]), parse_select(["auto"]), parse_select(None)
    ((0.0, 80.0), 'auto', None)
    """

    if values is None:
        return None
    if len(values) == 1 and str(values[0]).strip().lower() in ("auto", "otsu"):
        return "auto"
    try:
        nums = tuple(float(v) for v in values)
    except ValueError:
        nums = ()
    if len(nums) != 2 or not all(math.isfinite(v) for v in nums):
        raise InputError(f"{flag}: expected two finite numbers LO HI or 'auto', got "
                         f"{' '.join(map(str, values))!r}")
    return nums


def _select(args, required: bool):
    sel = deprecated_flag(args.select, args.old_select, "--range", "--select (the values "
                          "selected)", " for the core")
    if sel is None and required:
        raise InputError("--select: give the pore values LO HI (e.g. --select 0 80) or auto "
                         "(Otsu's threshold)")
    return parse_select(sel, "--select" if args.select is not None else "--range")


def register(sub) -> None:
    p = sub.add_parser("core", help="digital core: render a box of a micro-CT volume, porosity")
    csub = p.add_subparsers(dest="core_command", metavar="ACTION")
    csub.required = True

    r = csub.add_parser("render", help="render the voxels of a box whose values are selected")
    r.add_argument("volume", metavar="VOLUME", help="raw, TIFF (file or folder), .npy, zarr")
    add_volume_args(r)
    _add_select(r, required=False)
    add_roi_args(r)
    r.add_argument("--box", type=int, nargs=6, metavar=("X0", "Y0", "Z0", "NX", "NY", "NZ"),
                   help="sub-volume: offset and size in voxels (default: whole volume)")
    r.add_argument("--method", default=C.default("method"), choices=C.choices("method"),
                   help="auto picks the fastest for this renderer (raycast on llvmpipe)")
    add_color_args(r, what="the selected voxels", log=False)
    r.add_argument("--no-cull", action="store_true",
                   help="draw hidden voxels too (reproduces the paper's trefoil counts)")
    r.add_argument("--paper-trefoil", action="store_true",
                   help="one trefoil per frame from the view direction, Eq. (1), instead of per "
                        "voxel from the eye position")
    r.add_argument("--occlusion", dest="occlusion", action="store_const", const=True,
                   default=None, help="ambient occlusion and depth cue (default: on for one "
                                      "solid colour, e.g. a single selected value)")
    r.add_argument("--no-occlusion", dest="occlusion", action="store_const", const=False,
                   help="plain directional lighting only")
    r.add_argument("--exaggeration", type=finite_float, default=C.default("exaggeration"),
                   metavar="F", help="vertical exaggeration: z multiplied by F (1)")
    r.add_argument("--porosity", choices=C.choices("porosity"), metavar="AXIS",
                   help="also compute the porosity profile along AXIS (x, y or z): the pore "
                        "fraction in the subtitle and the stats, as the viewer shows it")
    r.add_argument("--gpu-memory", type=finite_float, metavar="GiB",
                   help="GPU memory to plan for when the driver does not say (default: unknown)")
    add_render_args(r)
    _big.add_scale_args(r, render=True)
    add_distributed_args(r, "the box's bricks")
    add_progressive_arg(r, "the box from the store's finest overview level within 256³ voxels")
    r.set_defaults(func=run_render_cmd)

    q = csub.add_parser("porosity", help="pore fraction of a box, total and as a profile")
    q.add_argument("volume", metavar="VOLUME")
    add_volume_args(q)
    _add_select(q, required=True)
    add_roi_args(q)
    q.add_argument("--box", type=int, nargs=6, metavar=("X0", "Y0", "Z0", "NX", "NY", "NZ"))
    q.add_argument("--axis", choices=C.choices("porosity"), default="z",
                   help="profile axis (z)")
    q.add_argument("-o", "--output", required=True, metavar="PLOT.png")
    q.add_argument("--csv", metavar="FILE.csv")
    q.add_argument("--json", metavar="FILE.json")
    _big.add_scale_args(q, render=False)
    q.set_defaults(func=run_porosity)
    _big.register(csub)


def run_render_cmd(args) -> int:

    options = {
        "select": _select(args, required=False), "box": args.box, "method": args.method,
        "cull": not args.no_cull, "trefoil_mode": "paper" if args.paper_trefoil else "eye",
        "gpu_memory_limit": None if args.gpu_memory is None else args.gpu_memory * 2**30,
        "occlusion": args.occlusion, "exaggeration": args.exaggeration,
        "porosity": args.porosity, **color_options(args), **_big.scale_kwargs(args),
        **roi_options(args), "progressive": args.progressive,
    }
    view_cls = distributed_view(args, "core", options)
    with progress_bar("selecting voxels") as cb:
        return run_render(args, "core", lambda: _big.load_volume(args), options,
                          inputs=[args.volume], progress=cb, view_cls=view_cls)


def run_porosity(args) -> int:
    from geoshade import core
    from geoshade.core.plots import porosity_plot
    from geoshade.io.output import Outputs, json_bytes

    select = _select(args, required=True)
    with Outputs({"-o": args.output, "--csv": args.csv, "--json": args.json},
                 inputs=[args.volume], suffixes={"-o": (".png",), "--csv": (".csv",),
                                                 "--json": (".json",)}) as out:
        vol = _big.load_volume(args)
        with progress_bar("porosity") as cb:
            res = core.porosity(vol, select, box=args.box, axis=args.axis, progress=cb,
                                **_big.scale_kwargs(args),
                                **roi_options(args))
        lo, hi = res.range
        porosity_plot(res, out.path("-o"), title=f"{vol.name or args.volume} — {res.quantity}"
                                                 f", values [{lo:g}, {hi:g}]")
        out.put("--csv", csv_text(res).encode("utf-8"))
        out.put("--json", json_bytes(res.to_dict()))
        out.commit()
    print(f"{core.porosity_line(res)}; profile along {args.axis} -> {args.output}")
    for note in res.notes():
        print(f"  {note}")
    return 0
