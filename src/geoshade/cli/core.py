"""``geoshade core render|porosity`` (and ``ingest``, see :mod:`geoshade.cli.ingest`)."""

from __future__ import annotations

import argparse

from geoshade.cli import ingest as _big  # ingest, --scheduler, --bricks, --level
from geoshade.cli.main import add_volume_args, finite_float
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import add_color_args, add_render_args, deprecated_flag, run_render
from geoshade.errors import InputError


def _add_select(p, required: bool) -> None:
    p.add_argument("--select", type=finite_float, nargs=2, metavar=("LO", "HI"), required=False,
                   help="values selected, inclusive, in the data's units (the pore space or "
                        "the mineral skeleton)" + ("" if required else
                                                   "; default: the whole dtype range"))
    p.add_argument("--range", dest="old_select", type=finite_float, nargs=2, metavar=("LO", "HI"),
                   help=argparse.SUPPRESS)  # the old name of --select, still accepted


def _select(args, required: bool):
    sel = deprecated_flag(args.select, args.old_select, "--range", "--select (the values "
                          "selected)", " for the core")
    if sel is None and required:
        raise InputError("--select: give the pore values LO HI (e.g. --select 0 80)")
    return None if sel is None else tuple(sel)


def register(sub) -> None:
    p = sub.add_parser("core", help="digital core: render a box of a micro-CT volume, porosity")
    csub = p.add_subparsers(dest="core_command", metavar="ACTION")
    csub.required = True

    r = csub.add_parser("render", help="render the voxels of a box whose values are selected")
    r.add_argument("volume", metavar="VOLUME", help="raw, TIFF (file or folder), .npy, zarr")
    add_volume_args(r)
    _add_select(r, required=False)
    r.add_argument("--box", type=int, nargs=6, metavar=("X0", "Y0", "Z0", "NX", "NY", "NZ"),
                   help="sub-volume: offset and size in voxels (default: whole volume)")
    r.add_argument("--method", default="auto",
                   choices=("auto", "raycast", "trefoil", "gs", "cubes"),
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
    r.add_argument("--exaggeration", type=finite_float, default=1.0, metavar="F",
                   help="vertical exaggeration: z multiplied by F (1)")
    r.add_argument("--gpu-memory", type=finite_float, metavar="GiB",
                   help="GPU memory to plan for when the driver does not say (default: unknown)")
    add_render_args(r)
    _big.add_scale_args(r, render=True)
    r.set_defaults(func=run_render_cmd)

    q = csub.add_parser("porosity", help="pore fraction of a box, total and as a profile")
    q.add_argument("volume", metavar="VOLUME")
    add_volume_args(q)
    _add_select(q, required=True)
    q.add_argument("--box", type=int, nargs=6, metavar=("X0", "Y0", "Z0", "NX", "NY", "NZ"))
    q.add_argument("--axis", choices=("x", "y", "z"), default="z", help="profile axis (z)")
    q.add_argument("-o", "--output", required=True, metavar="PLOT.png")
    q.add_argument("--csv", metavar="FILE.csv")
    q.add_argument("--json", metavar="FILE.json")
    _big.add_scale_args(q, render=False)
    q.set_defaults(func=run_porosity)
    _big.register(csub)


def run_render_cmd(args) -> int:
    from geoshade.cli.render import color_options

    options = {
        "select": _select(args, required=False), "box": args.box, "method": args.method,
        "cull": not args.no_cull, "trefoil_mode": "paper" if args.paper_trefoil else "eye",
        "gpu_memory_limit": None if args.gpu_memory is None else args.gpu_memory * 2**30,
        "occlusion": args.occlusion, "exaggeration": args.exaggeration,
        **color_options(args), **_big.scale_kwargs(args),
    }
    with progress_bar("selecting voxels") as cb:
        return run_render(args, "core", lambda: _big.load_volume(args), options,
                          inputs=[args.volume], progress=cb)


def run_porosity(args) -> int:
    from geoshade import core
    from geoshade.compute.porosity import csv_text
    from geoshade.core.plots import porosity_plot
    from geoshade.io.output import Outputs, json_bytes

    select = _select(args, required=True)
    with Outputs({"-o": args.output, "--csv": args.csv, "--json": args.json},
                 inputs=[args.volume], suffixes={"-o": (".png",), "--csv": (".csv",),
                                                 "--json": (".json",)}) as out:
        vol = _big.load_volume(args)
        with progress_bar("porosity") as cb:
            res = core.porosity(vol, select, box=args.box, axis=args.axis, progress=cb,
                                **_big.scale_kwargs(args))
        porosity_plot(res, out.path("-o"), title=f"{vol.name or args.volume}")
        out.put("--csv", csv_text(res).encode("utf-8"))
        out.put("--json", json_bytes(res.to_dict()))
        out.commit()
    print(f"porosity {res.porosity:.4f} ({res.count} of {res.total} voxels in "
          f"[{select[0]:g}, {select[1]:g}]); profile along {args.axis} -> {args.output}")
    return 0
